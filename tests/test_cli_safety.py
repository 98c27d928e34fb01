"""Nothing is lost: inputs are never replaced, destinations are checked before anything is
written, and a full or read-only disk is reported in one line that names the folder."""

import os
import subprocess

import numpy as np
import pytest

import aarecovery
from aarecovery import InputError, read_image, write_image
from aarecovery.cli import main
from aarecovery.io import DiskError


def ramp_pair(height=24, width=32):
    ramp = np.tile(np.linspace(0, 255, width).astype(np.uint8), (height, 1))
    return ramp, np.where(ramp > 127, 255, 0).astype(np.uint8)


def run_main(capsys, *args):
    status = main([str(arg) for arg in args])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def one_line_error(err):
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("aarecovery: error: "), err
    assert "Traceback" not in err
    return lines[0]


def _mount(*args):
    done = subprocess.run(["mount", *map(str, args)], capture_output=True, text=True)
    if done.returncode != 0:
        message = f"cannot mount ({done.stderr.strip()})"
        if os.environ.get("CI"):
            pytest.fail(message)
        pytest.skip("DISK TESTS NOT RUN: " + message)


@pytest.fixture
def read_only_folder(tmp_path):
    """A folder nobody can write, root included: a read-only bind mount (or, not root, mode 0500)."""
    folder = tmp_path / "read-only"
    folder.mkdir()
    if os.geteuid() != 0:
        folder.chmod(0o500)
        yield folder
        folder.chmod(0o700)
        return
    _mount("--bind", folder, folder)
    try:
        _mount("-o", "remount,ro,bind", folder)
        yield folder
    finally:
        subprocess.run(["umount", str(folder)], check=True)


@pytest.fixture
def full_folder(tmp_path):
    """A folder on a 1 MB file system (tmpfs; needs root)."""
    if os.geteuid() != 0:
        pytest.skip("DISK-FULL TESTS NOT RUN: mounting a small tmpfs needs root (CI runs as root)")
    folder = tmp_path / "small"
    folder.mkdir()
    _mount("-t", "tmpfs", "-o", "size=1m", "tmpfs", folder)
    try:
        yield folder
    finally:
        subprocess.run(["umount", str(folder)], check=True)


# --- A: filter never replaces its input --------------------------------------------------------------


@pytest.mark.parametrize("extra", [[], ["--recover", "--backend", "numpy"]])
def test_filter_refuses_to_replace_its_input(tmp_path, capsys, extra):
    write_image(tmp_path / "x.png", ramp_pair()[0])
    before = (tmp_path / "x.png").read_bytes()
    status, _, err = run_main(capsys, "filter", "threshold", tmp_path / "x.png", "-o", tmp_path / "x.png", *extra)
    assert status == 1
    line = one_line_error(err)
    assert "input" in line and "--overwrite" in line
    assert (tmp_path / "x.png").read_bytes() == before


def test_filter_replaces_its_input_with_overwrite(tmp_path, capsys):
    original, _ = ramp_pair()
    write_image(tmp_path / "x.png", original)
    status, _, err = run_main(capsys, "filter", "threshold", tmp_path / "x.png", "-o", tmp_path / "x.png",
                              "--overwrite")
    assert status == 0, err
    assert set(np.unique(read_image(tmp_path / "x.png"))) == {0, 255}


# --- E: every destination before anything is written -----------------------------------------------


def test_maps_folder_that_cannot_be_written_stops_the_run_before_anything(tmp_path, capsys, read_only_folder):
    original, filtered = ramp_pair()
    write_image(tmp_path / "o.png", original)
    write_image(tmp_path / "f.png", filtered)
    status, out, err = run_main(capsys, "recover", tmp_path / "o.png", tmp_path / "f.png", "-o", tmp_path / "r.png",
                                "--maps", read_only_folder / "maps", "--backend", "numpy")
    assert status == 1
    line = one_line_error(err)
    assert str(read_only_folder) in line and ".part" not in line
    assert out == ""
    assert not (tmp_path / "r.png").exists()
    assert sorted(os.listdir(tmp_path)) == ["f.png", "o.png", "read-only"]


def test_output_folder_that_cannot_be_written_is_refused_before_reading(tmp_path, capsys, read_only_folder):
    status, _, err = run_main(capsys, "recover", tmp_path / "absent-o.png", tmp_path / "absent-f.png",
                              "-o", read_only_folder / "r.png", "--backend", "numpy")
    assert status == 1
    line = one_line_error(err)
    assert str(read_only_folder) in line and "absent" not in line


def test_a_map_that_fails_to_write_leaves_the_result_unwritten(tmp_path, monkeypatch):
    from aarecovery.io import write as write_module

    original, filtered = ramp_pair()
    real_encode = write_module._encode
    calls = []

    def fail_on_the_third(file, pixels, format_name):
        calls.append(format_name)
        if len(calls) == 3:
            raise OSError(28, "No space left on device")
        real_encode(file, pixels, format_name)

    monkeypatch.setattr(write_module, "_encode", fail_on_the_third)
    with pytest.raises(DiskError, match="full"):
        write_module.write_images({tmp_path / "r.png": filtered, tmp_path / "a.png": original,
                                   tmp_path / "b.png": original})
    assert os.listdir(tmp_path) == []


# --- 11: a full or read-only disk, in one line naming the folder -----------------------------------------


@pytest.mark.parametrize("extension", [".png", ".tif", ".npy", ".bmp"])
def test_full_disk_names_the_folder_and_leaves_nothing(full_folder, extension):
    noise = np.random.default_rng(0).integers(0, 256, (700, 600, 3), dtype=np.uint8)  # 1.26 MB raw
    with pytest.raises(DiskError) as caught:
        write_image(full_folder / f"big{extension}", noise)
    message = str(caught.value)
    assert "full" in message and str(full_folder) in message and ".part" not in message
    assert "requested" not in message and "Errno" not in message
    assert os.listdir(full_folder) == []


def test_full_disk_on_the_command_line(tmp_path, capsys, full_folder):
    noise = np.random.default_rng(1).integers(0, 256, (700, 600, 3), dtype=np.uint8)
    write_image(tmp_path / "noise.png", noise)
    status, _, err = run_main(capsys, "filter", "gamma", tmp_path / "noise.png", "-o", full_folder / "out.tif")
    assert status == 1
    line = one_line_error(err)
    assert "full" in line and str(full_folder) in line
    assert os.listdir(full_folder) == []


def test_read_only_folder_names_the_folder(read_only_folder):
    with pytest.raises(DiskError) as caught:
        write_image(read_only_folder / "out.png", ramp_pair()[0])
    message = str(caught.value)
    assert str(read_only_folder) in message and ".part" not in message
    assert ("read-only" in message) if os.geteuid() == 0 else ("permission" in message)


def test_disk_errors_are_os_errors_and_input_errors_are_not():
    assert issubclass(DiskError, OSError) and not issubclass(DiskError, InputError)
    assert aarecovery.write_image is write_image


def test_batch_destinations_on_a_read_only_disk_are_one_line_without_errno(tmp_path, capsys, read_only_folder):
    originals = tmp_path / "originals"
    originals.mkdir()
    write_image(originals / "a.png", ramp_pair()[0])
    for destination in (["-o", read_only_folder / "new"], ["-o", tmp_path / "r1", "--report", read_only_folder / "r.csv"],
                        ["-o", tmp_path / "r2", "--keep-filtered", read_only_folder / "kept"]):
        status, _, err = run_main(capsys, "batch", originals, "--filter", "threshold", "--backend", "numpy",
                                  *destination)
        assert status == 1, err
        assert "Errno" not in err and "Traceback" not in err, err
        assert str(read_only_folder) in err
