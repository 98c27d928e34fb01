"""Orientation is applied the same way in every format: EXIF in JPEG, WebP and PNG's eXIf
chunk, and the TIFF Orientation tag; a size mismatch says when the tags differ."""

import numpy as np
import pytest
import tifffile
from PIL import Image, ImageOps

import aarecovery
from aarecovery import read_image
from aarecovery.cli import main

ORIENTATIONS = range(1, 9)


def stored_image(height=5, width=7, seed=0):
    return np.random.default_rng(seed).integers(0, 256, (height, width, 3), dtype=np.uint8)


def exif_with(orientation):
    exif = Image.Exif()
    exif[0x0112] = orientation
    return exif


def save_tagged(path, pixels, orientation):
    """Save `pixels` as stored, tagged with `orientation` (PNG eXIf, TIFF tag, JPEG/WebP EXIF)."""
    if path.suffix == ".tif":
        tifffile.imwrite(path, pixels, photometric="rgb", extratags=[(274, "H", 1, orientation, True)])
    else:
        options = {".webp": {"lossless": True}, ".jpg": {"quality": 100, "subsampling": 0}}.get(path.suffix, {})
        Image.fromarray(pixels).save(path, exif=exif_with(orientation), **options)


@pytest.mark.parametrize("orientation", ORIENTATIONS)
def test_every_format_turns_the_same_way_as_pillow(tmp_path, orientation):
    pixels = stored_image()
    expected = np.asarray(ImageOps.exif_transpose(_tagged_pillow_image(pixels, orientation)))
    for extension in (".png", ".tif", ".webp"):
        path = tmp_path / f"image{extension}"
        save_tagged(path, pixels, orientation)
        np.testing.assert_array_equal(read_image(path), expected, err_msg=extension)
        assert aarecovery.io.orientation_tag(path) == orientation


def _tagged_pillow_image(pixels, orientation):
    image = Image.fromarray(pixels)
    image.getexif()[0x0112] = orientation
    image.info["exif"] = exif_with(orientation).tobytes()
    return image


def edge_scene(size):
    rows, cols = np.mgrid[0:size[0], 0:size[1]]
    ramp = np.clip((cols + 0.6 * rows - 0.4 * size[1]) / 3, 0, 1)
    original = np.stack([ramp, 0.4 * ramp, 1 - ramp], -1)
    return np.rint(original * 255).astype(np.uint8), np.where(original > 0.5, 255, 0).astype(np.uint8)


def run_recover(capsys, *args):
    status = main(["recover", *map(str, args), "--backend", "numpy"])
    return status, capsys.readouterr().err


def test_rotated_png_original_against_an_upright_filtered(tmp_path, capsys):
    upright_o, upright_f = edge_scene((40, 28))
    save_tagged(tmp_path / "o.png", np.rot90(upright_o, 1).copy(), 6)  # stored as the camera held it
    aarecovery.write_image(tmp_path / "f.png", upright_f)                # a tool that turned the pixels
    status, err = run_recover(capsys, tmp_path / "o.png", tmp_path / "f.png", "-o", tmp_path / "r.png")
    assert status == 0, err
    np.testing.assert_array_equal(read_image(tmp_path / "r.png"),
                                  aarecovery.recover(upright_o, upright_f, backend="numpy"))


@pytest.mark.parametrize("o_extension", [".jpg", ".png", ".tif"])
def test_square_pair_both_tagged_is_recovered_aligned(tmp_path, capsys, o_extension):
    upright_o, upright_f = edge_scene((36, 36))
    stored_o, stored_f = (np.rot90(image, 1).copy() for image in (upright_o, upright_f))
    save_tagged(tmp_path / f"o{o_extension}", stored_o, 6)
    save_tagged(tmp_path / "f.png", stored_f, 6)
    status, err = run_recover(capsys, tmp_path / f"o{o_extension}", tmp_path / "f.png", "-o", tmp_path / "r.png",
                              "--paper")
    assert status == 0, err
    original = read_image(tmp_path / f"o{o_extension}")   # a JPEG is lossy: compare with what it decodes to
    expected = aarecovery.recover(original, upright_f, backend="numpy", mode="paper")
    np.testing.assert_array_equal(read_image(tmp_path / "r.png"), expected)
    assert np.abs(original.astype(int) - upright_o).max() <= (12 if o_extension == ".jpg" else 0)


def test_size_mismatch_names_differing_orientation_tags(tmp_path, capsys):
    upright_o, _ = edge_scene((40, 28))
    stored = np.rot90(upright_o, 1).copy()
    save_tagged(tmp_path / "o.png", stored, 6)
    # A program that dropped the tag but kept the stored pixels:
    aarecovery.write_image(tmp_path / "f.png", np.where(stored > 127, 255, 0).astype(np.uint8))
    status, err = run_recover(capsys, tmp_path / "o.png", tmp_path / "f.png", "-o", tmp_path / "r.png")
    assert status == 1
    (line,) = err.splitlines()
    assert "28x40" in line and "40x28" in line
    assert "ORIGINAL is tagged orientation 6 (turned 90 degrees clockwise" in line
    assert "FILTERED is tagged orientation 1" in line and "dropped" in line


def test_size_mismatch_without_tags_says_nothing_of_orientation(tmp_path, capsys):
    aarecovery.write_image(tmp_path / "o.png", edge_scene((40, 28))[0])
    aarecovery.write_image(tmp_path / "f.png", edge_scene((28, 40))[1])
    status, err = run_recover(capsys, tmp_path / "o.png", tmp_path / "f.png", "-o", tmp_path / "r.png")
    assert status == 1 and "orientation" not in err


def _square_pair_with_o_tagged(tmp_path, extension=".png"):
    """O tagged orientation 6 and F untagged, F made from O's stored (unturned) pixels: a square
    pair whose sizes match while F is misaligned with O as read."""
    original, filtered = edge_scene((32, 32))
    save_tagged(tmp_path / f"o{extension}", original, 6)
    save_tagged(tmp_path / f"f{extension}", filtered, 1)
    return tmp_path / f"o{extension}", tmp_path / f"f{extension}"


@pytest.mark.parametrize("extension", [".png", ".tif"])
def test_recover_warns_in_one_line_when_the_orientation_tags_differ(tmp_path, capsys, extension, backend):
    original, filtered = _square_pair_with_o_tagged(tmp_path, extension)
    status = main(["recover", str(original), str(filtered), "-o", str(tmp_path / "r.png"), "--backend", backend])
    err = capsys.readouterr().err
    assert status == 0, err
    warnings = [line for line in err.splitlines() if "orientation" in line]
    assert len(warnings) == 1 and warnings[0].startswith("aarecovery: warning: "), err
    assert "orientation 6" in warnings[0] and "orientation 1" in warnings[0]


def test_batch_warns_for_each_pair_whose_orientation_tags_differ(tmp_path, capsys):
    for sub in ("o", "f"):
        (tmp_path / sub).mkdir()
    original, filtered = edge_scene((32, 32))
    save_tagged(tmp_path / "o" / "a.png", original, 6)
    save_tagged(tmp_path / "f" / "a.png", filtered, 1)
    save_tagged(tmp_path / "o" / "b.png", original, 1)
    save_tagged(tmp_path / "f" / "b.png", filtered, 1)
    status = main(["batch", str(tmp_path / "o"), str(tmp_path / "f"), "-o", str(tmp_path / "r"), "--backend",
                   "numpy"])
    err = capsys.readouterr().err
    assert status == 0, err
    warnings = [line for line in err.splitlines() if "orientation" in line]
    assert len(warnings) == 1 and warnings[0].startswith("aarecovery: warning: a.png: "), err


def test_the_library_warns_with_orientation_warning(tmp_path):
    original, filtered = _square_pair_with_o_tagged(tmp_path)
    with pytest.warns(aarecovery.OrientationWarning, match="orientation 6"):
        aarecovery.recover_many([(original, filtered)], tmp_path / "r", backend="numpy")
