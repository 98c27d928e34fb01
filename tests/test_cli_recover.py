"""The ``aarecovery recover`` command: results, maps, and one-line errors on bad input."""

import os
import subprocess
import sys

import numpy as np
import pytest
import tifffile
from PIL import Image

import aarecovery
from aarecovery import read_image, write_image
from aarecovery.cli import main


def edge_pair(height=32, width=40, dtype=np.uint16):
    """An antialiased colour edge and the same edge thresholded (its antialiasing destroyed)."""
    rows, cols = np.mgrid[0:height, 0:width] / np.float32(height)
    ramp = np.clip((cols + 0.3 * rows - 0.6) * 8, 0, 1)
    original = np.stack([ramp, 0.5 * ramp, 1 - ramp], axis=-1)
    filtered = (original > 0.5).astype(np.float32)
    full = np.iinfo(dtype).max
    return (np.rint(original * full).astype(dtype), np.rint(filtered * full).astype(dtype))


@pytest.fixture
def pair(tmp_path):
    original, filtered = edge_pair()
    write_image(tmp_path / "o.png", original)
    write_image(tmp_path / "f.png", filtered)
    return tmp_path, original, filtered


def run_cli(capsys, *args):
    status = main(["recover", *map(str, args), "--backend", "numpy"])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def assert_one_line_error(capsys, args, *words):
    status, out, err = run_cli(capsys, *args)
    assert status != 0
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("aarecovery: error: ")
    for word in words:
        assert word in lines[0], f"{word!r} not in {lines[0]!r}"
    return lines[0]


# --- success ---------------------------------------------------------------------------------------


def test_recover_writes_the_api_result_in_filtered_depth(pair, capsys):
    folder, original, filtered = pair
    status, out, err = run_cli(capsys, folder / "o.png", folder / "f.png", "-o", folder / "r.png")
    assert status == 0, err
    result = read_image(folder / "r.png")
    assert result.dtype == np.uint16 and result.shape == filtered.shape
    np.testing.assert_array_equal(result, aarecovery.recover(original, filtered, backend="numpy"))
    assert not np.array_equal(result, filtered), "the edge pair should need repair"
    assert "r.png" in out and "40x32" in out and "numpy" in out


def test_parameters_reach_the_recovery(pair, capsys):
    folder, original, filtered = pair
    status, _, err = run_cli(capsys, folder / "o.png", folder / "f.png", "-o", folder / "r.tif",
                             "--sigma-d", 0.2, "--sigma-e", 0.02, "--iterations", 5,
                             "--blend-space", "srgb", "--linear", "--tile-size", 64)
    assert status == 0, err
    expected = aarecovery.recover(original, filtered, sigma_d=0.2, sigma_e=0.02, iterations=5,
                                  blend_space="srgb", linear=True, backend="numpy")
    np.testing.assert_array_equal(read_image(folder / "r.tif"), expected)


def test_8_bit_filtered_gives_8_bit_result(tmp_path, capsys):
    original, _ = edge_pair(dtype=np.uint16)
    _, filtered = edge_pair(dtype=np.uint8)
    write_image(tmp_path / "o.png", original)
    write_image(tmp_path / "f.png", filtered)
    status, _, err = run_cli(capsys, tmp_path / "o.png", tmp_path / "f.png", "-o", tmp_path / "r.png")
    assert status == 0, err
    assert read_image(tmp_path / "r.png").dtype == np.uint8


def test_maps_are_16_bit_grey_and_scaled_as_documented(pair, capsys):
    folder, original, filtered = pair
    status, _, err = run_cli(capsys, folder / "o.png", folder / "f.png", "-o", folder / "r.png",
                             "--maps", folder / "maps" / "run1")
    assert status == 0, err
    _, maps = aarecovery.recover(original, filtered, backend="numpy", return_maps=True)
    expected = {
        "alpha": np.clip(maps.alpha, 0, 1),
        "beta": np.clip(maps.beta, 0, 1),
        "edge_strength": np.clip(np.sqrt(maps.edge_strength), 0, 1),
        "residual": np.clip(maps.residual * 10, 0, 1),
    }
    for name, values in expected.items():
        stored = read_image(folder / "maps" / "run1" / f"{name}.png")
        assert stored.dtype == np.uint16 and stored.shape == (32, 40), name
        np.testing.assert_array_equal(stored, np.rint(values * 65535).astype(np.uint16), err_msg=name)
    assert read_image(folder / "maps" / "run1" / "beta.png").max() > 0


def test_unrelated_existing_output_is_replaced(pair, capsys):
    folder, _, _ = pair
    (folder / "r.png").write_bytes(b"old result")
    status, _, err = run_cli(capsys, folder / "o.png", folder / "f.png", "-o", folder / "r.png")
    assert status == 0, err
    assert read_image(folder / "r.png").shape == (32, 40, 3)


# --- bad input: one line on stderr, non-zero status ---------------------------------------------------


def test_different_sizes_name_both(tmp_path, capsys):
    write_image(tmp_path / "o.png", edge_pair(32, 40)[0])
    write_image(tmp_path / "f.png", edge_pair(16, 20)[1])
    assert_one_line_error(capsys, [tmp_path / "o.png", tmp_path / "f.png", "-o", tmp_path / "r.png"],
                          "40x32", "20x16")
    assert not (tmp_path / "r.png").exists()


def test_missing_input(pair, capsys):
    folder, _, _ = pair
    assert_one_line_error(capsys, [folder / "o.png", folder / "absent.png", "-o", folder / "r.png"],
                          "absent.png", "does not exist")


def test_unreadable_input(pair, capsys):
    folder, _, _ = pair
    (folder / "notes.png").write_text("this is text, not pixels")
    assert_one_line_error(capsys, [folder / "notes.png", folder / "f.png", "-o", folder / "r.png"],
                          "notes.png", "supported")


def test_truncated_png(pair, capsys):
    folder, _, _ = pair
    data = (folder / "f.png").read_bytes()
    (folder / "cut.png").write_bytes(data[:len(data) // 2])
    assert_one_line_error(capsys, [folder / "o.png", folder / "cut.png", "-o", folder / "r.png"],
                          "cut.png", "PNG", "is the file complete?")


def test_unsupported_mode(pair, capsys):
    folder, _, _ = pair
    Image.new("LAB", (40, 32), (50, 0, 0)).save(folder / "lab.tif")
    assert_one_line_error(capsys, [folder / "o.png", folder / "lab.tif", "-o", folder / "r.png"],
                          "lab.tif", "CIELAB")


def test_unsupported_sample_type(pair, capsys):
    folder, _, _ = pair
    tifffile.imwrite(folder / "signed.tif", np.zeros((32, 40), np.int16))
    assert_one_line_error(capsys, [folder / "signed.tif", folder / "f.png", "-o", folder / "r.png"],
                          "signed.tif", "int16")


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_non_finite_npy(tmp_path, capsys, bad):
    original, filtered = (image.astype(np.float32) / 65535 for image in edge_pair())
    filtered[3, 4, 1] = bad
    np.save(tmp_path / "o.npy", original)
    np.save(tmp_path / "f.npy", filtered)
    assert_one_line_error(capsys, [tmp_path / "o.npy", tmp_path / "f.npy", "-o", tmp_path / "r.npy"],
                          "filtered", "NaN or infinite", "row 3, column 4")
    assert not (tmp_path / "r.npy").exists()


def test_zero_size_npy(pair, capsys):
    folder, _, _ = pair
    np.save(folder / "empty.npy", np.zeros((0, 40, 3), np.uint16))
    assert_one_line_error(capsys, [folder / "o.png", folder / "empty.npy", "-o", folder / "r.png"],
                          "empty.npy", "empty")


@pytest.mark.parametrize("role", ["o.png", "f.png"])
def test_output_equal_to_an_input_is_refused(pair, capsys, role):
    folder, _, _ = pair
    before = (folder / role).read_bytes()
    assert_one_line_error(capsys, [folder / "o.png", folder / "f.png", "-o", folder / role],
                          role, "--overwrite")
    assert (folder / role).read_bytes() == before


def test_output_reaching_an_input_by_another_path_is_refused(pair, capsys):
    folder, _, _ = pair
    (folder / "sub").mkdir()
    os.link(folder / "f.png", folder / "sub" / "hard.png")
    before = (folder / "f.png").read_bytes()
    indirect = folder / "sub" / ".." / "f.png"
    assert_one_line_error(capsys, [folder / "o.png", folder / "f.png", "-o", indirect], "filtered")
    assert_one_line_error(capsys, [folder / "o.png", folder / "sub" / "hard.png", "-o", folder / "f.png"],
                          "filtered")
    assert (folder / "f.png").read_bytes() == before


def test_output_equal_to_filtered_is_replaced_with_overwrite(pair, capsys):
    folder, original, filtered = pair
    status, _, err = run_cli(capsys, folder / "o.png", folder / "f.png", "-o", folder / "f.png", "--overwrite")
    assert status == 0, err
    np.testing.assert_array_equal(read_image(folder / "f.png"),
                                  aarecovery.recover(original, filtered, backend="numpy"))


def test_maps_folder_may_not_hold_an_input(pair, capsys):
    folder, _, _ = pair
    write_image(folder / "alpha.png", edge_pair()[1])
    before = (folder / "alpha.png").read_bytes()
    assert_one_line_error(capsys, [folder / "o.png", folder / "alpha.png", "-o", folder / "r.png",
                                   "--maps", folder], "alpha.png", "--overwrite")
    assert (folder / "alpha.png").read_bytes() == before


def test_missing_output_folder(pair, capsys):
    folder, _, _ = pair
    assert_one_line_error(capsys, [folder / "o.png", folder / "f.png", "-o", folder / "nowhere" / "r.png"],
                          "nowhere", "does not exist", "create it first")
    assert not (folder / "nowhere").exists()


def test_unknown_output_extension(pair, capsys):
    folder, _, _ = pair
    assert_one_line_error(capsys, [folder / "o.png", folder / "f.png", "-o", folder / "r.gif"],
                          "'.gif'", ".png", ".tif")
    assert sorted(os.listdir(folder)) == ["f.png", "o.png"]


def test_alpha_result_to_jpeg_is_refused_before_recovery(tmp_path, capsys):
    original, filtered = edge_pair()
    alpha = np.full(original.shape[:2] + (1,), 65535, np.uint16)
    write_image(tmp_path / "o.png", np.concatenate([original, alpha], axis=-1))
    write_image(tmp_path / "f.png", np.concatenate([filtered, alpha], axis=-1))
    assert_one_line_error(capsys, [tmp_path / "o.png", tmp_path / "f.png", "-o", tmp_path / "r.jpg"],
                          "JPEG", "alpha", ".png")
    assert not (tmp_path / "r.jpg").exists()


@pytest.mark.parametrize("option, value, words", [
    ("--sigma-e", "0", ("sigma_e", "from 0.0001 to 1")),
    ("--sigma-d", "nan", ("sigma_d", "nan")),
    ("--iterations", "65", ("iterations", "65")),
    ("--tile-size", "5", ("--tile-size 5", "at least 9")),
    ("--tile-size", "9", ("--tile-size 9", "below 64", "at least 64")),
    ("--tile-size", "63", ("--tile-size 63", "below 64")),
])
def test_bad_parameters(pair, capsys, option, value, words):
    folder, _, _ = pair
    assert_one_line_error(capsys, [folder / "o.png", folder / "f.png", "-o", folder / "r.png", option, value],
                          *words)


# --- the installed command -------------------------------------------------------------------------


def run_module(*args):
    return subprocess.run([sys.executable, "-m", "aarecovery", *map(str, args)],
                          capture_output=True, text=True, timeout=120)


def test_installed_command_succeeds_and_fails_in_one_line(pair):
    folder, original, filtered = pair
    done = run_module("recover", folder / "o.png", folder / "f.png", "-o", folder / "r.tif", "--backend", "numpy")
    assert done.returncode == 0, done.stderr
    assert "r.tif" in done.stdout
    np.testing.assert_array_equal(read_image(folder / "r.tif"),
                                  aarecovery.recover(original, filtered, backend="numpy"))

    before = (folder / "f.png").read_bytes()
    refused = run_module("recover", folder / "o.png", folder / "f.png", "-o", folder / "f.png",
                         "--backend", "numpy")
    assert refused.returncode == 1
    assert refused.stderr.count("\n") == 1 and refused.stderr.startswith("aarecovery: error: ")
    assert (folder / "f.png").read_bytes() == before


def test_help_has_examples_and_map_scales():
    done = run_module("recover", "--help")
    assert done.returncode == 0
    assert "examples:" in done.stdout and "aarecovery recover" in done.stdout
    assert "sqrt(edge strength)" in done.stdout and "10 x distance" in done.stdout
