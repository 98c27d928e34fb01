"""Interrupted writes leave nothing behind: SIGTERM and SIGHUP like SIGINT, and after SIGKILL
the next run (or a batch, through ``remove_stale_parts``) removes the part it left."""

import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

from aarecovery import write_image
from aarecovery.io import remove_stale_parts
from aarecovery.io.parts import create_part, is_part_name

# Runs `aarecovery ARGS...` with an encoder that writes part of the file, says so, and stalls:
# the signal then arrives in the middle of a real write.
_STALLED_WRITER = textwrap.dedent("""
    import os, signal, sys, time
    from aarecovery.io import write
    from aarecovery.cli import main

    def stalled(file, pixels, format_name):
        file.write(b"\\x89PNG half of an image" * 1000)
        file.flush()
        print("writing", flush=True)
        time.sleep(60)

    write._encode = stalled
    # The dispositions a terminal gives, or nohup's, whatever this test run inherited (under
    # nohup SIGHUP arrives ignored, in a background job SIGINT).
    signal.signal(signal.SIGHUP, signal.SIG_IGN if os.environ.get("TEST_NOHUP") else signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    sys.exit(main(sys.argv[1:]))
""")


def ramp_files(folder):
    ramp = np.tile(np.linspace(0, 255, 32).astype(np.uint8), (24, 1))
    write_image(folder / "o.png", ramp)
    write_image(folder / "f.png", np.where(ramp > 127, 255, 0).astype(np.uint8))


def start_stalled_recover(folder, output="r.png", nohup=False):
    process = subprocess.Popen(
        [sys.executable, "-c", _STALLED_WRITER, "recover", str(folder / "o.png"), str(folder / "f.png"),
         "-o", str(folder / output), "--backend", "numpy"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env={**os.environ, "TEST_NOHUP": "1" if nohup else ""})
    assert process.stdout.readline() == "writing\n", process.communicate()[1]
    return process


def parts_in(folder):
    return sorted(name for name in os.listdir(folder) if ".part" in name)


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP, signal.SIGINT])
def test_terminating_signals_leave_no_part(tmp_path, signum):
    ramp_files(tmp_path)
    process = start_stalled_recover(tmp_path)
    assert len(parts_in(tmp_path)) == 1
    process.send_signal(signum)
    _, err = process.communicate(timeout=30)
    assert process.returncode == 128 + signum, err
    assert err.splitlines() == [f"aarecovery: interrupted ({signal.Signals(signum).name}); "
                                "no half-written file was left"]
    assert sorted(os.listdir(tmp_path)) == ["f.png", "o.png"]


def age(path, seconds):
    stamp = time.time() - seconds
    os.utime(path, (stamp, stamp))


def test_the_next_run_removes_what_sigkill_left(tmp_path):
    ramp_files(tmp_path)
    process = start_stalled_recover(tmp_path)
    process.kill()
    process.wait(timeout=30)
    (left,) = parts_in(tmp_path)
    assert os.path.getsize(tmp_path / left) > 0
    assert is_part_name(left, "r", ".png")

    # An empty part as fresh may be a writer's between its creation and its lock: it stays.
    descriptor, empty = create_part(str(tmp_path), "r", ".png")
    os.close(descriptor)
    done = subprocess.run([sys.executable, "-m", "aarecovery", "recover", str(tmp_path / "o.png"),
                           str(tmp_path / "f.png"), "-o", str(tmp_path / "r.png"), "--backend", "numpy"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    # The killed writer's part had bytes, so its free lock says that it is gone, at any age.
    assert sorted(os.listdir(tmp_path)) == sorted(["f.png", "o.png", "r.png", os.path.basename(empty)])
    age(empty, 120)
    assert remove_stale_parts(tmp_path, "r", ".png") == [empty]


def test_stale_parts_of_living_writers_and_other_files_stay(tmp_path):
    ramp_files(tmp_path)
    living = start_stalled_recover(tmp_path, "busy.png")
    try:
        descriptor, dead = create_part(str(tmp_path), "gone", ".tif")
        os.close(descriptor)  # its writer is gone: the lock went with the descriptor
        others = ["notes.part.png", ".gone.part.tif", ".gone.short.part.tif", "gone.abcdefgh.part.tif"]
        for name in others:
            (tmp_path / name).write_bytes(b"not ours")
        for name in os.listdir(tmp_path):
            age(tmp_path / name, 3 * 3600)
        (busy,) = [name for name in parts_in(tmp_path) if name.startswith(".busy.")]

        assert remove_stale_parts(tmp_path, "r", ".png") == []
        assert remove_stale_parts(tmp_path) == [dead]
        assert busy in os.listdir(tmp_path)
        for name in others:
            assert (tmp_path / name).read_bytes() == b"not ours"
    finally:
        living.kill()
        living.wait(timeout=30)


def test_nohup_keeps_sighup_ignored(tmp_path):
    ramp_files(tmp_path)
    process = start_stalled_recover(tmp_path, nohup=True)
    try:
        process.send_signal(signal.SIGHUP)
        with pytest.raises(subprocess.TimeoutExpired):
            process.wait(timeout=2)
    finally:
        process.kill()
        process.communicate(timeout=30)
