"""``aarecovery batch`` and ``recover_many``, run for real: every result equals ``recover`` on its pair."""

import csv
import json
import os
import shutil
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import tifffile

import aarecovery
from aarecovery import read_image, write_image
from aarecovery.cli import main
from scenes import shapes


def threshold(image):
    """A thresholded copy in the image's own dtype and layout (its antialiasing destroyed)."""
    full = np.iinfo(image.dtype).max
    return np.where(image > full // 2, full, 0).astype(image.dtype)


def write_pairs(folder, names):
    """Originals and thresholded copies under folder/o and folder/f; returns {name: (O, F)}."""
    pairs = {}
    for index, name in enumerate(names):
        original = shapes(40 + 4 * index, seed=index)[:, :50]
        if name.endswith(".tif"):
            original = original.astype(np.uint16) * 257
        if "grey" in name:
            original = np.ascontiguousarray(original[..., 1])
        filtered = threshold(original)
        for sub, image in (("o", original), ("f", filtered)):
            os.makedirs(os.path.dirname(folder / sub / name), exist_ok=True)
            write_image(folder / sub / name, image)
        pairs[name] = (original, filtered)
    return pairs


def write_numbered_pairs(folder, count, size):
    """`count` noisy pairs image00.png... under folder/o and folder/f; returns {name: (O, F)}."""
    pairs = {}
    for index in range(count):
        original = shapes(size, seed=index, noise=0.02)
        pairs[f"image{index:02d}.png"] = (original, threshold(original))
        for sub, image in zip("of", pairs[f"image{index:02d}.png"]):
            os.makedirs(folder / sub, exist_ok=True)
            write_image(folder / sub / f"image{index:02d}.png", image)
    return pairs


def corrupt(path):
    """A file that starts like a PNG and stops."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as file:
        file.write(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR")


def run_batch(capsys, *args):
    status = main(["batch", *map(str, args)])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def assert_equals_recover(output, original, filtered, **options):
    expected = aarecovery.recover(original, filtered, **options)
    result = read_image(output)
    assert result.dtype == expected.dtype and result.shape == expected.shape
    np.testing.assert_array_equal(result, expected)


def no_temporary_files(folder):
    return [path for path in folder.rglob("*") if ".part" in path.name]


NAMES = ["a.png", "sub/b.tif", "c-grey.png", "d.png"]


def test_folders_are_paired_by_relative_path_and_a_corrupt_file_does_not_stop_the_batch(tmp_path, capsys, backend):
    pairs = write_pairs(tmp_path, NAMES)
    corrupt(tmp_path / "o" / "bb.png")
    shutil.copyfile(tmp_path / "o" / "bb.png", tmp_path / "f" / "bb.png")
    status, out, err = run_batch(capsys, tmp_path / "o", tmp_path / "f", "-o", tmp_path / "r", "--backend", backend,
                                 "--report", tmp_path / "report.csv")
    assert status == 1
    assert "aarecovery: failed: bb.png: could not decode" in err
    assert "4 recovered" in out and "1 failed" in out
    for name, (original, filtered) in pairs.items():
        assert_equals_recover(tmp_path / "r" / name, original, filtered, backend=backend)
    assert not (tmp_path / "r" / "bb.png").exists()
    assert no_temporary_files(tmp_path) == []
    with open(tmp_path / "report.csv") as file:
        rows = {row["name"]: row for row in csv.DictReader(file)}
    assert set(rows) == set(NAMES) | {"bb.png"}
    assert rows["bb.png"]["status"] == "failed" and "could not decode" in rows["bb.png"]["error"]
    for name in NAMES:
        assert rows[name]["status"] == "done" and rows[name]["backend"] == backend
        assert rows[name]["mode"] == "safe" and rows[name]["reason"] and float(rows[name]["strength"]) >= 0
        assert rows[name]["decision"] in {str(decision) for decision in aarecovery.Decision}


def test_globs_are_paired_by_what_their_wildcards_match(tmp_path, capsys):
    original = shapes(40, seed=1)
    write_image(tmp_path / "scan-1.png", original)
    write_image(tmp_path / "scan-1-bw.tif", threshold(original))
    write_image(tmp_path / "scan-2.png", original[::-1])
    status, out, err = run_batch(capsys, tmp_path / "scan-?.png", tmp_path / "scan-?-bw.tif", "-o", tmp_path / "r",
                                 "--backend", "numpy")
    assert status == 1 and "no filtered image matches" in err and "scan-2.png" in err
    # The result keeps the filtered image's name and format.
    assert_equals_recover(tmp_path / "r" / "scan-1-bw.tif", original, threshold(original), backend="numpy")


def test_a_builtin_filter_makes_f_and_keeps_it(tmp_path, capsys):
    original = shapes(48, seed=2)
    os.makedirs(tmp_path / "o")
    write_image(tmp_path / "o" / "x.png", original)
    status, out, err = run_batch(capsys, tmp_path / "o", "-o", tmp_path / "r", "--backend", "numpy", "--paper",
                                 "--keep-filtered", tmp_path / "kept", "--filter", "threshold", "level=0.4")
    assert status == 0, err
    filtered = aarecovery.filters.apply("threshold", original, level=0.4)
    np.testing.assert_array_equal(read_image(tmp_path / "kept" / "x.png"), filtered)
    assert_equals_recover(tmp_path / "r" / "x.png", original, filtered, backend="numpy", mode="paper")


def require_tool(name):
    path = shutil.which(name)
    if path is None or (name == "convert" and not os.path.exists("/usr/bin/convert") and not shutil.which("magick")):
        message = f"{name} is not installed; apt-get install imagemagick gmic (packaging/test.sh does)"
        if os.environ.get("CI"):
            pytest.fail(message)
        pytest.skip("FILTER COMMAND TEST NOT RUN: " + message)
    return path


def imagemagick():
    """ImageMagick 7's 'magick' where installed, else ImageMagick 6's 'convert' (Debian 12)."""
    return "magick" if shutil.which("magick") else require_tool("convert") and "convert"


@pytest.mark.parametrize("tool", ["imagemagick", "gmic"])
def test_a_command_line_tool_makes_f_and_its_failure_is_reported(tmp_path, capsys, tool):
    template = {"imagemagick": lambda: f"{imagemagick()} {{in}} -threshold 50% {{out}}",
                "gmic": lambda: require_tool("gmic") and "gmic {in} -quantize 3 -o {out}"}[tool]()
    originals = {"a.png": shapes(44, seed=3), "sub/b.png": shapes(40, seed=4)}
    for name, image in originals.items():
        os.makedirs(os.path.dirname(tmp_path / "o" / name), exist_ok=True)
        write_image(tmp_path / "o" / name, image)
    corrupt(tmp_path / "o" / "aa.png")
    before = {path: path.read_bytes() for path in (tmp_path / "o").rglob("*.png")}
    status, out, err = run_batch(capsys, tmp_path / "o", "-o", tmp_path / "r", "--backend", "numpy",
                                 "--filter-cmd", template, "--keep-filtered", tmp_path / "kept",
                                 "--report", tmp_path / "report.json")
    assert status == 1
    line = next(line for line in err.splitlines() if "aa.png" in line)
    assert "the filter command exited with status" in line or "could not decode" in line, line
    for name, original in originals.items():
        filtered = read_image(tmp_path / "kept" / name)
        assert not np.array_equal(filtered, original)
        assert_equals_recover(tmp_path / "r" / name, original, filtered, backend="numpy")
    # The tool ran on copies: the originals are as they were.
    assert {path: path.read_bytes() for path in (tmp_path / "o").rglob("*.png")} == before
    report = {row["name"]: row for row in json.loads((tmp_path / "report.json").read_text())}
    assert report["aa.png"]["status"] == "failed" and report["a.png"]["status"] == "done"
    assert no_temporary_files(tmp_path) == []


def test_a_filter_command_that_does_not_exist_is_one_line(tmp_path, capsys):
    write_pairs(tmp_path, ["a.png"])
    status, out, err = run_batch(capsys, tmp_path / "o", "-o", tmp_path / "r", "--filter-cmd",
                                 "no-such-tool-here {in} {out}")
    assert status == 1 and err.startswith("aarecovery: error: --filter-cmd: the program 'no-such-tool-here'")
    assert len(err.splitlines()) == 1


def results(folder):
    """The result files in `folder` (not the hidden temporary files of writes in progress)."""
    return sorted(path.name for path in folder.glob("*.png") if not path.name.startswith("."))


def default_signal_dispositions():
    """In a child, before exec: the dispositions a terminal gives, whatever this test run
    inherited (under nohup SIGHUP is ignored, in a background job SIGINT)."""
    for number in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(number, signal.SIG_DFL)


def _batch_command(tmp_path, *extra):
    return [sys.executable, "-m", "aarecovery", "batch", str(tmp_path / "o"), str(tmp_path / "f"), "-o",
            str(tmp_path / "r"), "--backend", "numpy", "--workers", "1", *extra]


def _interrupt_after_first_results(tmp_path, signal_number):
    # A session of its own, so that SIGINT reaches the whole process group, as Ctrl+C does.
    process = subprocess.Popen(_batch_command(tmp_path), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               start_new_session=True, preexec_fn=default_signal_dispositions)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and process.poll() is None:
        if len(results(tmp_path / "r")) >= 2:
            break
        time.sleep(0.02)
    if signal_number == signal.SIGINT:
        os.killpg(process.pid, signal.SIGINT)
    else:
        process.send_signal(signal_number)
    out, err = process.communicate(timeout=120)
    return process.returncode, out.decode(), err.decode()


@pytest.mark.parametrize("signal_number", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGKILL])
def test_an_interrupted_batch_leaves_only_complete_results_and_resumes(tmp_path, signal_number):
    pairs = write_numbered_pairs(tmp_path, 8, 96)
    names = sorted(pairs)
    status, out, err = _interrupt_after_first_results(tmp_path, signal_number)
    written = results(tmp_path / "r")
    assert 2 <= len(written) < len(names), (status, out, err)
    if signal_number != signal.SIGKILL:
        assert status == 128 + signal_number, err
        assert f"interrupted ({signal.Signals(signal_number).name}) after" in err, err
        assert "run the same command again" in err and "Traceback" not in err
        assert no_temporary_files(tmp_path) == []
    else:
        # Its analysis processes find the batch gone and end quietly (communicate() read
        # their stderr to its end: they have exited).
        assert "Traceback" not in err and "BrokenPipeError" not in err, err
        # A killed process cannot tidy up: leave a temporary file as it would (its write
        # was cut short), older than the next run.
        stale = tmp_path / "r" / f".{names[-1][:-4]}.x1y2.part.png"
        stale.write_bytes(b"\x89PNG half")
        os.utime(stale, (time.time() - 60, time.time() - 60))
    for name in written:
        np.testing.assert_array_equal(read_image(tmp_path / "r" / name),
                                      aarecovery.recover(*pairs[name], backend="numpy"))
    stamps = {name: os.stat(tmp_path / "r" / name).st_mtime_ns for name in written}
    resumed = subprocess.run(_batch_command(tmp_path), capture_output=True, text=True)
    assert resumed.returncode == 0, resumed.stderr
    assert f"{len(written)} up to date" in resumed.stdout
    assert {name: os.stat(tmp_path / "r" / name).st_mtime_ns for name in written} == stamps
    for name, pair in pairs.items():
        np.testing.assert_array_equal(read_image(tmp_path / "r" / name), aarecovery.recover(*pair, backend="numpy"))
    assert no_temporary_files(tmp_path) == []
    if signal_number == signal.SIGINT:
        forced = subprocess.run(_batch_command(tmp_path, "--force"), capture_output=True, text=True)
        assert forced.returncode == 0 and f"{len(names)} recovered" in forced.stdout


def write_tiled(path, image, tile):
    tifffile.imwrite(path, image, tile=(tile, tile), compression="zlib",
                     photometric="rgb" if image.ndim == 3 and image.shape[2] >= 3 else "minisblack",
                     extrasamples=("unassalpha",) if image.ndim == 3 and image.shape[2] in (2, 4) else None)


@pytest.mark.parametrize("layout", ["rgb8", "rgba16"])
def test_a_tiled_tiff_larger_than_the_tile_streams_to_the_result_of_recover(tmp_path, capsys, backend, layout):
    original = np.concatenate([shapes(150, seed=7, noise=0.01), shapes(150, seed=8)], axis=1)[:140, :290]
    if layout == "rgba16":
        alpha = np.full(original.shape[:2] + (1,), 255, np.uint8)
        alpha[40:60, 100:200] = 128
        original = np.concatenate([original, alpha], axis=-1).astype(np.uint16) * 257
    filtered = threshold(original)
    if layout == "rgba16":
        filtered[..., 3] = original[..., 3]
    for sub in ("o", "f"):
        os.makedirs(tmp_path / sub)
    write_tiled(tmp_path / "o" / "big.tif", original, 32)
    write_tiled(tmp_path / "f" / "big.tif", filtered, 48)
    for mode in ("safe", "paper"):
        extra = ["--paper"] if mode == "paper" else []
        expected = aarecovery.recover(original, filtered, backend=backend, mode=mode)
        status, out, err = run_batch(capsys, tmp_path / "o", tmp_path / "f", "-o", tmp_path / mode, "--backend",
                                     backend, "--tile-size", "64", "--report", tmp_path / f"{mode}.json", *extra)
        assert status == 0, err
        assert json.loads((tmp_path / f"{mode}.json").read_text())[0]["streamed"] is True
        with tifffile.TiffFile(tmp_path / mode / "big.tif") as tif:
            assert tif.pages.first.is_tiled
        np.testing.assert_array_equal(read_image(tmp_path / mode / "big.tif"), expected)
        status = main(["recover", str(tmp_path / "o" / "big.tif"), str(tmp_path / "f" / "big.tif"), "-o",
                       str(tmp_path / f"{mode}.png"), "--backend", backend, "--tile-size", "64", *extra])
        assert status == 0 and "streamed in tiles" in capsys.readouterr().out
        np.testing.assert_array_equal(read_image(tmp_path / f"{mode}.png"), expected)
    assert no_temporary_files(tmp_path) == []


def test_recover_many_returns_arrays_and_calls_progress(tmp_path):
    pairs = write_pairs(tmp_path, ["a.png", "b.png"])
    calls = []
    arrays = [(original, filtered) for original, filtered in pairs.values()]
    results = aarecovery.recover_many(arrays + [(tmp_path / "o" / "a.png", tmp_path / "f" / "a.png", "again")],
                                      backend="numpy", progress=lambda *call: calls.append(call))
    assert [result.status for result in results] == ["done"] * 3
    assert sorted(call[1] for call in calls) == [1, 2, 3] and {call[2] for call in calls} == {3}
    for result, (original, filtered) in zip(results, arrays + [pairs["a.png"]]):
        np.testing.assert_array_equal(result.image, aarecovery.recover(original, filtered, backend="numpy"))
        assert result.output is None and result.backend == "numpy"


def test_recover_many_shows_which_images_were_left_alone_and_why(tmp_path):
    original = shapes(64, seed=5, noise=0.01)
    blurred = aarecovery.filters.apply("blur", original)
    results = aarecovery.recover_many([(original, blurred, "blurred.png"), (original, threshold(original), "t.png")],
                                      tmp_path, backend="numpy")
    kept, repaired = results
    assert kept.status == "done" and kept.strength == 0 and kept.decision == "lowpass-kept"
    np.testing.assert_array_equal(read_image(tmp_path / "blurred.png"), blurred)
    assert repaired.strength > 0


def test_a_result_that_would_replace_its_input_is_refused(tmp_path, capsys):
    write_pairs(tmp_path, ["a.png"])
    before = (tmp_path / "f" / "a.png").read_bytes()
    status, out, err = run_batch(capsys, tmp_path / "o", tmp_path / "f", "-o", tmp_path / "f", "--backend", "numpy")
    assert status == 1 and "would replace the filtered image" in err
    assert (tmp_path / "f" / "a.png").read_bytes() == before


def test_names_that_collide_are_refused():
    image = np.zeros((8, 8), np.uint8)
    with pytest.raises(aarecovery.InputError, match="both named 'x.png'"):
        aarecovery.recover_many([(image, image, "x.png"), (image, image, "x.png")], backend="numpy")


def test_fsspec_urls_for_inputs_and_results(tmp_path, capsys):
    pytest.importorskip("fsspec", reason="pip install '.[test]' installs fsspec")
    pairs = write_pairs(tmp_path, ["a.png", "sub/b.tif"])
    url = f"file://{tmp_path.as_posix()}"
    status, out, err = run_batch(capsys, f"{url}/o", f"{url}/f", "-o", f"{url}/r", "--backend", "numpy")
    assert status == 0, err
    for name, (original, filtered) in pairs.items():
        assert_equals_recover(tmp_path / "r" / name, original, filtered, backend="numpy")
    assert no_temporary_files(tmp_path) == []
    status, out, err = run_batch(capsys, f"{url}/o/*.png", f"{url}/f/*.png", "-o", f"{url}/r", "--backend", "numpy")
    assert status == 0 and "1 up to date" in out, err


def test_a_filter_command_that_runs_too_long_is_stopped_and_reported(tmp_path, capsys):
    write_pairs(tmp_path, ["a.png"])
    status, out, err = run_batch(capsys, tmp_path / "o", "-o", tmp_path / "r", "--backend", "numpy",
                                 "--filter-cmd", "sh -c 'sleep 30' {in} {out}", "--filter-timeout", "0.5")
    assert status == 1 and "did not finish within 0.5 s" in err
    assert not (tmp_path / "r" / "a.png").exists() and no_temporary_files(tmp_path) == []


def test_a_filter_command_printing_a_10_mb_line_is_reported_in_a_short_line(tmp_path, capsys):
    write_pairs(tmp_path, ["a.png"])
    status, out, err = run_batch(capsys, tmp_path / "o", "-o", tmp_path / "r", "--backend", "numpy", "--filter-cmd",
                                 "python3 -c 'import sys; sys.stderr.write(\"x\" * 10**7); sys.exit(3)' {in} {out}")
    assert status == 1 and "exited with status 3" in err and "more characters" in err
    assert len(err) < 1000, len(err)


def test_max_image_memory_is_the_limit_of_each_image_read(tmp_path, capsys):
    """A file declaring more than the limit fails alone, with the option that raises it."""
    write_pairs(tmp_path, ["small.png"])
    big = shapes(400, seed=3)
    for sub, image in (("o", big), ("f", threshold(big))):
        write_image(tmp_path / sub / "big.png", image)
    # Above the small pair's peak (its images and a tile's working set, 160 bytes a pixel:
    # 0.34 MB), below the big image decoded (0.48 MB).
    limit_gb = 0.0004
    status, out, err = run_batch(capsys, tmp_path / "o", tmp_path / "f", "-o", tmp_path / "r", "--backend", "numpy",
                                 "--max-image-memory", f"{limit_gb:.9f}")
    assert status == 1 and "1 recovered" in out and "1 failed" in out
    assert "big.png" in err and "--max-image-memory" in err and "decompression bomb" in err
    assert (tmp_path / "r" / "small.png").exists() and not (tmp_path / "r" / "big.png").exists()
    status, out, err = run_batch(capsys, tmp_path / "o", tmp_path / "f", "-o", tmp_path / "r", "--backend", "numpy",
                                 "--max-image-memory", "1")
    assert status == 0 and (tmp_path / "r" / "big.png").exists(), err
    results = aarecovery.recover_many([(tmp_path / "o" / "big.png", tmp_path / "f" / "big.png")], backend="numpy",
                                      max_bytes=1000)
    assert results[0].status == "failed" and "limit for one image" in results[0].error, results[0].error


def test_a_filter_command_past_its_time_is_stopped_with_the_processes_it_started(tmp_path, capsys):
    """A wrapper script's children are stopped too: left running, they would hold the batch
    (they keep the command's stderr open) and go on writing after it reported the image."""
    write_pairs(tmp_path, ["a.png"])
    marker = tmp_path / "still-running"
    started = time.monotonic()
    status, out, err = run_batch(capsys, tmp_path / "o", "-o", tmp_path / "r", "--backend", "numpy",
                                 "--filter-cmd", f"sh -c 'sleep 4 && touch {marker} & wait' {{in}} {{out}}",
                                 "--filter-timeout", "0.5")
    assert time.monotonic() - started < 3.5, "the batch waited for the command's children"
    assert status == 1 and "did not finish within 0.5 s" in err
    time.sleep(4.5)
    assert not marker.exists(), "a child of the filter command went on running after the time-out"


def test_ctrl_c_stops_a_running_filter_command_and_its_children(tmp_path):
    """The filter runs in a process group of its own (see the time-out test), out of reach of
    the terminal's Ctrl+C: the interrupted batch must stop it, not wait for it."""
    write_pairs(tmp_path, ["a.png"])
    marker, started = tmp_path / "still-running", tmp_path / "started"
    command = [sys.executable, "-m", "aarecovery", "batch", str(tmp_path / "o"), "-o", str(tmp_path / "r"),
               "--backend", "numpy", "--filter-cmd",
               f"sh -c 'touch {started}; sleep 6 && touch {marker} & wait' {{in}} {{out}}"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True,
                               preexec_fn=default_signal_dispositions)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not started.exists():
        time.sleep(0.05)
    time.sleep(0.3)
    os.killpg(process.pid, signal.SIGINT)
    interrupted = time.monotonic()
    out, err = process.communicate(timeout=60)
    assert process.returncode == 130, err.decode()
    assert time.monotonic() - interrupted < 4, "the batch waited for the filter command"
    time.sleep(6.5 - (time.monotonic() - interrupted))
    assert not marker.exists(), "a child of the filter command went on running after Ctrl+C"
    assert no_temporary_files(tmp_path) == []


def test_relative_paths_with_a_dask_scheduler_address_are_refused_saying_where_they_resolve(tmp_path, capsys,
                                                                                          monkeypatch):
    write_pairs(tmp_path, ["a.png"])
    monkeypatch.chdir(tmp_path)
    status, _, err = run_batch(capsys, "o", "f", "-o", tmp_path / "r", "--dask", "tcp://127.0.0.1:9")
    assert status == 1 and err.count("\n") == 1, err
    assert "'o' is a relative path" in err and "resolve paths on their side" in err and str(tmp_path / "o") in err


def test_file_names_that_are_not_utf8_or_hold_control_characters_are_reported_escaped(tmp_path, capsys):
    """A name with an invalid UTF-8 byte ended the batch in a traceback while writing the
    report; escape sequences and newlines in names reached the terminal raw."""
    folder = tmp_path / "o"
    folder.mkdir()
    image = shapes(40, seed=1)
    write_image(folder / "plain.png", image)
    (folder / "plain.png").rename(os.fsdecode(os.fsencode(str(folder)) + b"/bad\xff.png"))
    broken = "esc\x1b[31mred\nline.png"
    (folder / broken).write_bytes(b"not an image")
    status, out, err = run_batch(capsys, folder, "-o", tmp_path / "r", "--filter", "threshold", "--backend",
                                 "numpy", "--report", tmp_path / "report.csv")
    assert status == 1 and "Traceback" not in err, err
    assert "\x1b" not in out + err and "\\x1b[31mred\\nline.png" in err
    assert err.count("\n") == 1 and out.count("\n") == 1
    report = (tmp_path / "report.csv").read_text(encoding="utf-8")
    assert "bad\\udcff.png,done" in report
