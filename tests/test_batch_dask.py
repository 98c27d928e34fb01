"""``aarecovery batch --dask`` on a real ``LocalCluster`` of worker processes.

Results are byte for byte those of the local batch, a pair of tiled TIFFs runs as one task
per tile, and a worker process killed in the middle of the batch loses nothing: Dask runs
its task again, and no half-written file is left.
"""

import os
import signal
import threading

import numpy as np
import pytest
import tifffile

import aarecovery
from aarecovery.cli import main
from scenes import shapes
from test_batch import no_temporary_files, threshold, write_numbered_pairs, write_pairs

distributed = pytest.importorskip("distributed", reason="pip install '.[test]' installs dask[distributed]")

NAMES = ["a.png", "sub/b.tif", "c-grey.png", "d.png", "e.png", "f.png"]


@pytest.fixture(scope="module")
def client():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  worker_class=distributed.Nanny) as cluster, distributed.Client(cluster) as client:
        yield client


def write_big_pair(folder):
    original = np.concatenate([shapes(120, seed=7, noise=0.01), shapes(120, seed=8)], axis=1)[:100]
    for sub, image in (("o", original), ("f", threshold(original))):
        tifffile.imwrite(folder / sub / "big.tif", image, tile=(32, 32), photometric="rgb", compression="zlib")


def files(folder):
    return {path.relative_to(folder).as_posix(): path.read_bytes() for path in sorted(folder.rglob("*"))
            if path.is_file()}


def test_a_batch_on_a_local_cluster_gives_the_local_batch_byte_for_byte(tmp_path, capsys, client):
    write_pairs(tmp_path, NAMES)
    write_big_pair(tmp_path)
    options = ["--backend", "numpy", "--tile-size", "48"]
    assert main(["batch", str(tmp_path / "o"), str(tmp_path / "f"), "-o", str(tmp_path / "local"), *options]) == 0
    results = aarecovery.recover_many(aarecovery.batch.find_pairs(str(tmp_path / "o"), str(tmp_path / "f"))[0],
                                      tmp_path / "dask", backend="numpy", tile_size=48, dask=client)
    assert [result.status for result in results] == ["done"] * (len(NAMES) + 1)
    assert {result.name: result.streamed for result in results}["big.tif"] is True
    local, remote = files(tmp_path / "local"), files(tmp_path / "dask")
    assert sorted(local) == sorted(NAMES + ["big.tif"]) and remote == local
    # The command line reaches the same cluster by its address; everything is up to date.
    capsys.readouterr()
    status = main(["batch", str(tmp_path / "o"), str(tmp_path / "f"), "-o", str(tmp_path / "dask"), *options,
                   "--dask", client.scheduler.address])
    assert status == 0 and f"{len(NAMES) + 1} up to date" in capsys.readouterr().out


class KillOnce(distributed.WorkerPlugin):
    """Kill this worker's process with SIGKILL a moment after its first task starts, once per cluster."""

    def __init__(self, marker, delay):
        self.marker, self.delay = marker, delay

    def setup(self, worker):
        self.worker = worker

    def transition(self, key, start, finish, **kwargs):
        if finish != "executing":
            return
        try:
            descriptor = os.open(self.marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
        except FileExistsError:
            return
        os.write(descriptor, str(os.getpid()).encode())
        os.close(descriptor)
        threading.Timer(self.delay, os.kill, (os.getpid(), signal.SIGKILL)).start()


def test_a_worker_killed_in_the_middle_of_the_batch_loses_no_result(tmp_path, client):
    pairs = write_numbered_pairs(tmp_path, 8, 160)
    names = sorted(pairs)
    marker = tmp_path / "killed"
    client.register_plugin(KillOnce(str(marker), 0.15), name="kill-once")
    try:
        results = aarecovery.recover_many([(tmp_path / "o" / n, tmp_path / "f" / n) for n in names], tmp_path / "r",
                                          backend="numpy", dask=client)
    finally:
        client.unregister_worker_plugin("kill-once")
    killed = int(marker.read_text())
    with pytest.raises(ProcessLookupError):
        os.kill(killed, 0)
    assert [result.status for result in results] == ["done"] * len(names)
    for name, pair in pairs.items():
        np.testing.assert_array_equal(aarecovery.read_image(tmp_path / "r" / name),
                                      aarecovery.recover(*pair, backend="numpy"))
    assert no_temporary_files(tmp_path) == []


def test_dask_logs_are_one_line_messages(capsys, monkeypatch):
    """A worker restarted by its nanny printed Dask's own '2026-... - distributed.nanny -
    WARNING - Restarting worker' among our lines; a record with a traceback, many lines."""
    import logging

    from aarecovery.cli.batch import dask_logs_as_lines
    logger = logging.getLogger("distributed")
    monkeypatch.setattr(logger, "handlers", list(logger.handlers))
    monkeypatch.setattr(logger, "propagate", logger.propagate)
    monkeypatch.delenv("DASK_LOGGING__DISTRIBUTED", raising=False)
    dask_logs_as_lines()
    logging.getLogger("distributed.nanny").warning("Restarting worker (status=Status.running)")
    logging.getLogger("distributed.worker").error("Compute failed\nTraceback (most recent call last):\n  File x")
    err = capsys.readouterr().err
    assert err.splitlines() == ["aarecovery: dask: warning: Restarting worker (status=Status.running)",
                                "aarecovery: dask: error: Compute failed (+2 lines)"]
