"""``aarecovery batch`` and ``recover_many`` never lose a file: every destination (results,
kept filtered images, maps, the report) is checked against the inputs and against each other,
and every folder for writability, before any image is read or written."""

import os
import shutil
import sys

import numpy as np
import pytest

import aarecovery
from aarecovery import read_image, write_image
from aarecovery.cli import main
from scenes import shapes
from test_cli_safety import one_line_error, read_only_folder  # noqa: F401 (a fixture)


def run_batch(capsys, *args):
    status = main(["batch", *map(str, args)])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def write_originals(folder, names=("a.png", "b.png"), size=40):
    os.makedirs(folder, exist_ok=True)
    for index, name in enumerate(names):
        write_image(folder / name, shapes(size, seed=index))


def snapshot(folder):
    """Every file under `folder`, with its bytes."""
    return {path.relative_to(folder): path.read_bytes() for path in sorted(folder.rglob("*")) if path.is_file()}


def copy_command():
    return f"{shutil.which('cp')} {{in}} {{out}}"


# --- item 1: a destination that would write over an input or over another destination ---------------------

@pytest.mark.parametrize("maker", ["--filter", "--filter-cmd"])
def test_keeping_filtered_images_in_the_originals_folder_is_refused(tmp_path, capsys, backend, maker):
    write_originals(tmp_path / "o")
    before = snapshot(tmp_path / "o")
    making = ["--filter", "threshold"] if maker == "--filter" else ["--filter-cmd", copy_command()]
    status, out, err = run_batch(capsys, tmp_path / "o", "-o", tmp_path / "r", "--backend", backend,
                                 "--keep-filtered", tmp_path / "o", *making)
    line = one_line_error(err)
    assert status == 1 and "keep-filtered" in line and str(tmp_path / "o") in line
    assert snapshot(tmp_path / "o") == before
    assert not (tmp_path / "r").exists()


def test_keeping_filtered_images_in_the_output_folder_is_refused(tmp_path, capsys):
    write_originals(tmp_path / "o")
    status, out, err = run_batch(capsys, tmp_path / "o", "-o", tmp_path / "r", "--backend", "numpy",
                                 "--keep-filtered", tmp_path / "r", "--filter", "threshold")
    line = one_line_error(err)
    assert status == 1 and "output folder" in line
    assert not (tmp_path / "r").exists()


def test_keeping_filtered_images_under_a_glob_of_originals_is_refused(tmp_path, capsys):
    write_originals(tmp_path / "scans")
    before = snapshot(tmp_path / "scans")
    status, out, err = run_batch(capsys, tmp_path / "scans" / "*.png", "-o", tmp_path / "r", "--backend", "numpy",
                                 "--keep-filtered", tmp_path / "scans", "--filter-cmd", copy_command())
    assert status == 1 and "keep-filtered" in one_line_error(err)
    assert snapshot(tmp_path / "scans") == before


@pytest.mark.parametrize("where", ["o", "f", "r"])
def test_maps_over_an_input_folder_or_the_output_folder_are_refused(tmp_path, capsys, backend, where):
    write_originals(tmp_path / "o")
    write_originals(tmp_path / "f")
    before = snapshot(tmp_path)
    status, out, err = run_batch(capsys, tmp_path / "o", tmp_path / "f", "-o", tmp_path / "r", "--backend", backend,
                                 "--maps", tmp_path / where)
    assert status == 1 and "maps" in one_line_error(err)
    assert snapshot(tmp_path) == before


def test_results_over_the_originals_of_a_folder_pair_are_refused_before_any_work(tmp_path, capsys):
    write_originals(tmp_path / "o")
    write_originals(tmp_path / "f", names=("a.png", "b.png"))
    before = snapshot(tmp_path)
    status, out, err = run_batch(capsys, tmp_path / "o", tmp_path / "f", "-o", tmp_path / "o", "--backend", "numpy")
    line = one_line_error(err)
    assert status == 1 and "would replace the original image" in line and "--overwrite" in line
    assert snapshot(tmp_path) == before


def test_two_results_with_one_name_are_refused(tmp_path, capsys):
    write_originals(tmp_path / "o", names=("a.png", "a.tif"))
    status, out, err = run_batch(capsys, tmp_path / "o", "-o", tmp_path / "r", "--backend", "numpy", "--filter",
                                 "threshold", "--format", "png")
    line = one_line_error(err)
    assert status == 1 and "a.png" in line and "both" in line
    assert not (tmp_path / "r").exists()


def test_recover_many_refuses_kept_filtered_images_over_the_originals(tmp_path, backend):
    write_originals(tmp_path / "o")
    before = snapshot(tmp_path / "o")
    originals = [str(tmp_path / "o" / name) for name in ("a.png", "b.png")]
    for keep in (tmp_path / "o", tmp_path / "r"):
        with pytest.raises(aarecovery.InputError, match="keep-filtered"):
            aarecovery.recover_many(originals, tmp_path / "r", filter="threshold", keep_filtered=keep,
                                    backend=backend)
    with pytest.raises(aarecovery.InputError, match="maps"):
        aarecovery.recover_many([(originals[0], originals[1])], tmp_path / "r", maps=tmp_path / "o",
                                backend=backend)
    assert snapshot(tmp_path / "o") == before
    assert not (tmp_path / "r").exists()


# --- item 4: every output written or the image is not done; interruptions and resumes reported -----------

def write_pairs(folder, count=3, size=40):
    for sub in ("o", "f"):
        os.makedirs(folder / sub, exist_ok=True)
    for index in range(count):
        original = shapes(size, seed=index)
        write_image(folder / "o" / f"p{index}.png", original)
        write_image(folder / "f" / f"p{index}.png", np.where(original > 127, 255, 0).astype(np.uint8))


def test_a_maps_folder_that_cannot_be_written_stops_the_batch_before_any_work(tmp_path, capsys, backend,
                                                                               read_only_folder):
    write_pairs(tmp_path)
    status, out, err = run_batch(capsys, tmp_path / "o", tmp_path / "f", "-o", tmp_path / "r", "--backend", backend,
                                 "--maps", read_only_folder / "maps")
    line = one_line_error(err)
    assert status == 1 and str(read_only_folder) in line
    assert not (tmp_path / "r").exists()


def test_an_image_whose_maps_fail_is_not_written_and_is_redone_by_the_next_run(tmp_path, capsys, backend):
    write_pairs(tmp_path)
    os.makedirs(tmp_path / "maps")
    (tmp_path / "maps" / "p1").write_text("a file where p1's maps folder goes")
    args = [tmp_path / "o", tmp_path / "f", "-o", tmp_path / "r", "--backend", backend, "--maps", tmp_path / "maps"]
    status, out, err = run_batch(capsys, *args)
    assert status == 1 and "failed: p1.png" in err
    assert sorted(os.listdir(tmp_path / "r")) == ["p0.png", "p2.png"]
    os.unlink(tmp_path / "maps" / "p1")
    status, out, err = run_batch(capsys, *args)
    assert status == 0 and "1 recovered" in out and "2 up to date" in out
    assert sorted(os.listdir(tmp_path / "maps" / "p1")) == ["alpha.png", "beta.png", "edge_strength.png",
                                                            "residual.png", "strength.png"]
    # A map removed since: the image is not up to date.
    os.unlink(tmp_path / "maps" / "p0" / "beta.png")
    status, out, err = run_batch(capsys, *args)
    assert status == 0 and "1 recovered" in out and (tmp_path / "maps" / "p0" / "beta.png").exists()


def test_an_interrupted_batch_reports_every_image_it_wrote(tmp_path):
    write_pairs(tmp_path, count=6, size=160)
    reported = []

    def progress(result, done, total):
        reported.append(result)
        if len(reported) == 1:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        aarecovery.recover_many([(tmp_path / "o" / f"p{i}.png", tmp_path / "f" / f"p{i}.png") for i in range(6)],
                                tmp_path / "r", backend="numpy", workers=1, progress=progress)
    written = sorted(name for name in os.listdir(tmp_path / "r") if not name.startswith("."))
    assert sorted(result.name for result in reported if result.status == "done") == written


@pytest.mark.parametrize("extension", [".csv", ".json"])
def test_a_resumed_batch_reports_the_plan_of_the_images_it_skipped(tmp_path, capsys, extension):
    write_pairs(tmp_path)
    report = tmp_path / f"report{extension}"
    args = [tmp_path / "o", tmp_path / "f", "-o", tmp_path / "r", "--backend", "numpy", "--report", report]
    assert run_batch(capsys, *args)[0] == 0
    first = aarecovery.batch.read_report(report)
    os.unlink(tmp_path / "r" / "p1.png")
    assert run_batch(capsys, *args)[0] == 0
    second = aarecovery.batch.read_report(report)
    assert [row["status"] for row in second] == ["skipped", "done", "skipped"]
    for before, after in zip(first, second):
        for name in ("width", "height", "dtype", "mode", "blend_space", "strength", "reason", "backend", "streamed"):
            assert after[name] == before[name] and after[name] not in ("", None), name


# --- item 6: the filtered images a batch makes are lossless ---------------------------------------------------

THRESHOLD_SCRIPT = ("import sys; from PIL import Image; "
                    "Image.open(sys.argv[1]).convert('L').point(lambda v: 255 if v > 127 else 0).save(sys.argv[2])")


@pytest.mark.parametrize("maker", ["--filter", "--filter-cmd"])
def test_filtered_images_of_a_jpeg_original_are_made_and_kept_lossless(tmp_path, capsys, backend, maker):
    os.makedirs(tmp_path / "o")
    original = shapes(64, seed=3)
    write_image(tmp_path / "o" / "x.jpg", original)
    making = (["--filter", "threshold"] if maker == "--filter" else
              ["--filter-cmd", f"{sys.executable} -c \"{THRESHOLD_SCRIPT}\" {{in}} {{out}}"])
    status, out, err = run_batch(capsys, tmp_path / "o", "-o", tmp_path / "r", "--backend", backend,
                                 "--keep-filtered", tmp_path / "kept", "--format", "png", *making)
    assert status == 0, err
    assert sorted(os.listdir(tmp_path / "kept")) == ["x.png"]
    kept = read_image(tmp_path / "kept" / "x.png")
    assert set(np.unique(kept)) <= {0, 255}
    # The batch recovered with that lossless F.
    np.testing.assert_array_equal(read_image(tmp_path / "r" / "x.png"),
                                  aarecovery.recover(read_image(tmp_path / "o" / "x.jpg"), kept, backend=backend))


def test_filter_command_help_says_the_filtered_image_is_lossless(capsys):
    with pytest.raises(SystemExit):
        main(["batch", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "lossless" in text and "PNG" in text
