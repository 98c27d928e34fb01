"""Reading and writing image files: round trips, conversions, bad files, atomic writes."""

import io
import os
import stat
import struct
import subprocess
import sys

import numpy as np
import pytest
import tifffile
from PIL import Image

import aarecovery
from aarecovery import InputError, read_image, write_image
from aarecovery.io import write as _io

LAYOUTS = {"grey": (5, 7), "grey+alpha": (5, 7, 2), "rgb": (5, 7, 3), "rgba": (5, 7, 4)}


def random_image(shape, dtype, seed=0):
    rng = np.random.default_rng(seed)
    if np.dtype(dtype).kind == "f":
        return rng.random(shape).astype(dtype)
    return rng.integers(0, np.iinfo(dtype).max, shape, dtype=dtype, endpoint=True)


def folder_listing(folder):
    return sorted(os.listdir(folder))


# --- round trips --------------------------------------------------------------------------


@pytest.mark.parametrize("extension", [".png", ".tif", ".tiff", ".npy"])
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
@pytest.mark.parametrize("layout", LAYOUTS)
def test_integer_round_trip_is_exact(tmp_path, extension, dtype, layout):
    image = random_image(LAYOUTS[layout], dtype)
    path = tmp_path / f"image{extension}"
    write_image(path, image)
    back = read_image(path)
    assert back.dtype == dtype
    assert back.shape == image.shape
    np.testing.assert_array_equal(back, image)


@pytest.mark.parametrize("layout", LAYOUTS)
def test_float32_tiff_round_trip_is_exact(tmp_path, layout):
    image = random_image(LAYOUTS[layout], np.float32)
    write_image(tmp_path / "image.tif", image)
    back = read_image(tmp_path / "image.tif")
    assert back.dtype == np.float32
    np.testing.assert_array_equal(back, image)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_npy_keeps_float_dtype(tmp_path, dtype):
    image = random_image((4, 6, 3), dtype)
    write_image(tmp_path / "image.npy", image)
    back = read_image(tmp_path / "image.npy")
    assert back.dtype == dtype
    np.testing.assert_array_equal(back, image)


def test_float64_tiff_is_stored_as_float32(tmp_path):
    image = random_image((4, 6), np.float64)
    write_image(tmp_path / "image.tif", image)
    back = read_image(tmp_path / "image.tif")
    assert back.dtype == np.float32
    np.testing.assert_array_equal(back, image.astype(np.float32))


def test_single_channel_axis_is_written_as_grey(tmp_path):
    image = random_image((4, 6, 1), np.uint16)
    write_image(tmp_path / "image.png", image)
    np.testing.assert_array_equal(read_image(tmp_path / "image.png"), image[..., 0])


def test_format_is_found_from_content_not_name(tmp_path):
    image = random_image((4, 6, 3), np.uint16)
    write_image(tmp_path / "image.png", image)
    os.rename(tmp_path / "image.png", tmp_path / "misnamed.jpg")
    np.testing.assert_array_equal(read_image(tmp_path / "misnamed.jpg"), image)


def test_big_endian_npy_is_read_in_native_order(tmp_path):
    image = random_image((4, 6), np.uint16)
    np.save(tmp_path / "image.npy", image.astype(">u2"))
    back = read_image(tmp_path / "image.npy")
    assert back.dtype == np.uint16
    np.testing.assert_array_equal(back, image)


# --- conversions by declared bit depth ------------------------------------------------------


def test_float_to_png_is_16_bit_rounded(tmp_path):
    image = np.array([[0.0, 0.5, 1.0, 1 / 3]], np.float32)
    write_image(tmp_path / "image.png", image)
    back = read_image(tmp_path / "image.png")
    assert back.dtype == np.uint16
    np.testing.assert_array_equal(back, [[0, 32768, 65535, 21845]])


def test_uint16_to_8_bit_format_rounds(tmp_path):
    # 25828 / 257 = 100.498 and 25829 / 257 = 100.502: the rounding decides.
    image = np.array([[0, 25828, 25829, 65535]], np.uint16)
    write_image(tmp_path / "image.bmp", image)
    back = read_image(tmp_path / "image.bmp")
    assert back.dtype == np.uint8
    np.testing.assert_array_equal(back, [[0, 100, 101, 255]])


def test_float_to_8_bit_format_rounds(tmp_path):
    image = np.array([[0.0, 0.5, 1.0, 0.2]], np.float32)
    write_image(tmp_path / "image.bmp", image)
    np.testing.assert_array_equal(read_image(tmp_path / "image.bmp"), [[0, 128, 255, 51]])


def test_jpeg_is_8_bit_and_close(tmp_path):
    image = np.full((16, 16, 3), 40000, np.uint16)
    write_image(tmp_path / "image.jpg", image)
    back = read_image(tmp_path / "image.jpg")
    assert back.dtype == np.uint8 and back.shape == image.shape
    assert np.abs(back.astype(int) - round(40000 / 257)).max() <= 1


def test_webp_is_lossless_and_stores_grey_alpha_as_rgba(tmp_path):
    image = random_image((6, 5, 2), np.uint8)
    write_image(tmp_path / "image.webp", image)
    back = read_image(tmp_path / "image.webp")
    assert back.shape == (6, 5, 4)
    np.testing.assert_array_equal(back[..., :3], np.repeat(image[..., :1], 3, axis=-1))
    np.testing.assert_array_equal(back[..., 3], image[..., 1])


# --- modes converted on reading ---------------------------------------------------------------


def palette_image():
    image = Image.new("P", (4, 3))
    image.putpalette([255, 0, 0, 0, 255, 0] * 128)
    image.putpixel((1, 0), 1)
    return image


def test_palette_becomes_rgb(tmp_path):
    palette_image().save(tmp_path / "image.gif")
    back = read_image(tmp_path / "image.gif")
    assert back.shape == (3, 4, 3) and back.dtype == np.uint8
    np.testing.assert_array_equal(back[0, :2], [[255, 0, 0], [0, 255, 0]])


def test_palette_with_transparency_becomes_rgba(tmp_path):
    palette_image().save(tmp_path / "image.gif", transparency=0)
    back = read_image(tmp_path / "image.gif")
    assert back.shape == (3, 4, 4)
    np.testing.assert_array_equal(back[0, :2, 3], [0, 255])


def test_palette_tiff_becomes_8_bit_rgb(tmp_path):
    palette_image().save(tmp_path / "image.tif")
    back = read_image(tmp_path / "image.tif")
    assert back.dtype == np.uint8
    np.testing.assert_array_equal(back[0, :2], [[255, 0, 0], [0, 255, 0]])


@pytest.mark.parametrize("extension", [".bmp", ".tif", ".png"])
def test_one_bit_becomes_grey_0_or_255(tmp_path, extension):
    image = Image.new("1", (4, 3), 0)
    image.putpixel((2, 1), 1)
    image.save(tmp_path / f"image{extension}")
    back = read_image(tmp_path / f"image{extension}")
    assert back.dtype == np.uint8 and back.shape == (3, 4)
    expected = np.zeros((3, 4), np.uint8)
    expected[1, 2] = 255
    np.testing.assert_array_equal(back, expected)


@pytest.mark.parametrize("extension", [".jpg", ".tif"])
def test_cmyk_becomes_rgb(tmp_path, extension):
    Image.new("CMYK", (8, 8), (0, 255, 0, 0)).save(tmp_path / f"image{extension}")
    back = read_image(tmp_path / f"image{extension}")
    assert back.shape == (8, 8, 3)
    assert np.abs(back.astype(int) - [255, 0, 255]).max() <= 2


def test_16_bit_grey_pillow_mode_stays_16_bit(tmp_path):
    Image.fromarray(np.full((3, 4), 40000, np.uint16)).save(tmp_path / "image.pgm")
    back = read_image(tmp_path / "image.pgm")
    assert back.dtype == np.uint16
    np.testing.assert_array_equal(back, 40000)


def test_planar_tiff_puts_samples_last(tmp_path):
    planes = random_image((3, 4, 5), np.uint16)
    tifffile.imwrite(tmp_path / "image.tif", planes, photometric="rgb", planarconfig="separate")
    np.testing.assert_array_equal(read_image(tmp_path / "image.tif"), np.moveaxis(planes, 0, -1))


def test_min_is_white_tiff_is_inverted(tmp_path):
    tifffile.imwrite(tmp_path / "image.tif", np.array([[0, 200]], np.uint8), photometric="miniswhite")
    np.testing.assert_array_equal(read_image(tmp_path / "image.tif"), [[255, 55]])


def test_premultiplied_tiff_alpha_is_made_straight(tmp_path):
    tifffile.imwrite(tmp_path / "image.tif", np.array([[[64, 32, 0, 128]]], np.uint8),
                     photometric="rgb", extrasamples=["assocalpha"])
    np.testing.assert_array_equal(read_image(tmp_path / "image.tif"), [[[128, 64, 0, 128]]])


# --- bad files --------------------------------------------------------------------------------


def assert_input_error(call, *words):
    with pytest.raises(InputError) as caught:
        call()
    message = str(caught.value)
    for word in words:
        assert word in message, f"{word!r} not in {message!r}"
    return message


def test_missing_file(tmp_path):
    assert_input_error(lambda: read_image(tmp_path / "nothing.png"), "nothing.png", "does not exist")


def test_folder_instead_of_file(tmp_path):
    assert_input_error(lambda: read_image(tmp_path), str(tmp_path), "is a folder")


def test_empty_file(tmp_path):
    (tmp_path / "empty.png").write_bytes(b"")
    assert_input_error(lambda: read_image(tmp_path / "empty.png"), "empty.png", "0 bytes")


def test_unknown_format_lists_supported_ones(tmp_path):
    (tmp_path / "notes.png").write_text("not an image at all, just some text")
    assert_input_error(lambda: read_image(tmp_path / "notes.png"), "notes.png", "supported", "PNG", "TIFF")


def test_truncated_png(tmp_path):
    write_image(tmp_path / "whole.png", random_image((40, 50, 3), np.uint16))
    data = (tmp_path / "whole.png").read_bytes()
    (tmp_path / "half.png").write_bytes(data[:len(data) // 2])
    assert_input_error(lambda: read_image(tmp_path / "half.png"),
                       "could not decode", "half.png", "as PNG", "is the file complete?")


@pytest.mark.parametrize("extension, format_name", [(".tif", "TIFF"), (".jpg", "JPEG"), (".npy", "NumPy")])
def test_truncated_files_of_other_formats(tmp_path, extension, format_name):
    write_image(tmp_path / f"whole{extension}", random_image((40, 50, 3), np.uint8))
    data = (tmp_path / f"whole{extension}").read_bytes()
    (tmp_path / f"half{extension}").write_bytes(data[:len(data) // 2])
    assert_input_error(lambda: read_image(tmp_path / f"half{extension}"),
                       "could not decode", format_name, "is the file complete?")


def test_unsupported_tiff_colour_space(tmp_path):
    Image.new("LAB", (4, 3), (50, 0, 0)).save(tmp_path / "lab.tif")
    assert_input_error(lambda: read_image(tmp_path / "lab.tif"), "lab.tif", "CIELAB", "grey, RGB")


def test_unsupported_tiff_sample_type(tmp_path):
    tifffile.imwrite(tmp_path / "signed.tif", np.zeros((3, 4), np.int32))
    assert_input_error(lambda: read_image(tmp_path / "signed.tif"), "int32", "unsigned")


def test_tiff_stack_is_refused(tmp_path):
    tifffile.imwrite(tmp_path / "stack.tif", np.zeros((3, 4, 6), np.uint8), photometric="minisblack",
                     planarconfig="contig")
    assert_input_error(lambda: read_image(tmp_path / "stack.tif"), "stack.tif", "6 samples")


def test_zero_size_npy(tmp_path):
    np.save(tmp_path / "empty.npy", np.zeros((0, 4, 3), np.uint8))
    assert_input_error(lambda: read_image(tmp_path / "empty.npy"), "empty.npy", "(0, 4, 3)", "empty")


@pytest.mark.parametrize("array, word", [(np.zeros((3, 4), np.int16), "int16"),
                                         (np.zeros((3, 4), np.complex64), "complex64"),
                                         (np.zeros((3, 4, 5), np.uint8), "(3, 4, 5)"),
                                         (np.zeros(7, np.uint8), "(7,)")])
def test_npy_of_wrong_dtype_or_shape(tmp_path, array, word):
    np.save(tmp_path / "bad.npy", array)
    assert_input_error(lambda: read_image(tmp_path / "bad.npy"), "bad.npy", word)


def test_npy_of_objects_is_refused_without_unpickling(tmp_path):
    np.save(tmp_path / "objects.npy", np.array([[{}]], dtype=object), allow_pickle=True)
    message = assert_input_error(lambda: read_image(tmp_path / "objects.npy"), "objects.npy", "pickled")
    assert "complete" not in message


def _npy_header_only(path, shape, dtype="|u1"):
    with open(path, "wb") as file:
        np.lib.format.write_array_header_1_0(file, {"descr": dtype, "fortran_order": False, "shape": shape})


@pytest.mark.parametrize("shape", [(10 ** 10,), (50000, 50000, 4, 1)])
def test_npy_shape_is_refused_from_its_header_before_anything_is_allocated(tmp_path, shape):
    # A 1-D or 4-D array claiming gigabytes: refused by its shape, not "Unable to allocate".
    _npy_header_only(tmp_path / "array.npy", shape)
    message = assert_input_error(lambda: read_image(tmp_path / "array.npy"), str(shape), "(H, W)")
    assert "\n" not in message and "complete" not in message


def test_npy_with_a_huge_header_is_one_line(tmp_path):
    with open(tmp_path / "header.npy", "wb") as file:
        file.write(b"\x93NUMPY\x02\x00" + (50_000_000).to_bytes(4, "little") + b"{" + b" " * 1000)
    message = assert_input_error(lambda: read_image(tmp_path / "header.npy"), "header.npy", "50000000 bytes")
    assert "\n" not in message


def test_read_image_of_none_is_an_input_error():
    assert_input_error(lambda: read_image(None), "NoneType")


def test_big_endian_arrays_are_recovered_as_native(backend):
    image = random_image((16, 20, 3), np.uint16)
    filtered = np.where(image > 30000, 65535, 0).astype(np.uint16)
    expected = aarecovery.recover(image, filtered, backend=backend)
    swapped = aarecovery.recover(image.astype(">u2"), filtered.astype(">u2"), backend=backend)
    assert swapped.dtype == np.uint16
    np.testing.assert_array_equal(swapped, expected)


def bmp_claiming_size(path, width, height):
    buffer = io.BytesIO()
    Image.new("L", (4, 3)).save(buffer, "BMP")
    header = bytearray(buffer.getvalue())
    header[18:26] = struct.pack("<ii", width, height)
    path.write_bytes(bytes(header))


def test_pillow_bomb_limit_does_not_stop_a_20000_square_image(tmp_path):
    # The header claims 20000 x 20000 (above Pillow's default limit) with no pixel data:
    # the read must get as far as decoding, and fail there as truncated.
    limit_before = Image.MAX_IMAGE_PIXELS
    bmp_claiming_size(tmp_path / "huge.bmp", 20000, 20000)
    message = assert_input_error(lambda: read_image(tmp_path / "huge.bmp"), "is the file complete?")
    assert "truncated" in message and "decompression" not in message.lower()
    assert Image.MAX_IMAGE_PIXELS == limit_before


def test_absurd_claimed_size_is_refused_before_decoding(tmp_path):
    bmp_claiming_size(tmp_path / "absurd.bmp", 65535, 65535)
    assert_input_error(lambda: read_image(tmp_path / "absurd.bmp"), "65535x65535", "decompression bomb")


# --- writing: refusals --------------------------------------------------------------------------


def test_unknown_output_extension_lists_supported_ones(tmp_path):
    assert_input_error(lambda: write_image(tmp_path / "out.xyz", random_image((3, 4), np.uint8)),
                       "'.xyz'", ".png", ".tif", ".npy")
    assert_input_error(lambda: write_image(tmp_path / "out", random_image((3, 4), np.uint8)),
                       "no extension", ".png")
    assert folder_listing(tmp_path) == []


def test_missing_output_folder_is_not_created(tmp_path):
    target = tmp_path / "missing" / "out.png"
    assert_input_error(lambda: write_image(target, random_image((3, 4), np.uint8)),
                       str(tmp_path / "missing"), "does not exist", "create it first")
    assert not (tmp_path / "missing").exists()


def test_folder_as_output_path(tmp_path):
    (tmp_path / "taken.png").mkdir()
    assert_input_error(lambda: write_image(tmp_path / "taken.png", random_image((3, 4), np.uint8)),
                       "is a folder")


@pytest.mark.parametrize("extension", [".jpg", ".bmp"])
def test_alpha_to_format_without_alpha_is_refused(tmp_path, extension):
    assert_input_error(lambda: write_image(tmp_path / f"out{extension}", random_image((3, 4, 4), np.uint8)),
                       "alpha", ".png")
    assert folder_listing(tmp_path) == []


@pytest.mark.parametrize("bad", [np.nan, np.inf, 2.0])
def test_float_that_has_no_integer_value_is_refused(tmp_path, bad):
    image = np.full((3, 4), 0.5, np.float32)
    image[1, 2] = bad
    assert_input_error(lambda: write_image(tmp_path / "out.png", image), "image")
    assert folder_listing(tmp_path) == []


def test_wrong_array_shape_is_refused(tmp_path):
    assert_input_error(lambda: write_image(tmp_path / "out.png", np.zeros((3, 4, 5), np.uint8)), "(3, 4, 5)")


def test_no_overwrite_keeps_existing_file(tmp_path):
    target = tmp_path / "out.png"
    target.write_bytes(b"precious")
    assert_input_error(lambda: write_image(target, random_image((3, 4), np.uint8), overwrite=False),
                       "already exists")
    assert target.read_bytes() == b"precious"
    assert folder_listing(tmp_path) == ["out.png"]


# --- writing: atomicity and permissions -----------------------------------------------------------


@pytest.mark.parametrize("failure", [KeyboardInterrupt, OSError, RuntimeError])
def test_failed_write_leaves_destination_and_no_temporary_file(tmp_path, monkeypatch, failure):
    target = tmp_path / "out.png"
    write_image(target, random_image((3, 4), np.uint8, seed=1))
    old_bytes = target.read_bytes()

    def fail_halfway(file, pixels, format_name):
        file.write(b"\x89PNG half of a file")
        raise failure("encoder stopped")

    monkeypatch.setattr(_io, "_encode", fail_halfway)
    with pytest.raises((failure, InputError)):
        write_image(target, random_image((3, 4), np.uint8, seed=2))
    assert target.read_bytes() == old_bytes
    assert folder_listing(tmp_path) == ["out.png"]


def test_interrupted_png_encoder_leaves_no_trace(tmp_path, monkeypatch):
    import imagecodecs

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(imagecodecs, "deflate_encode", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_image(tmp_path / "new.png", random_image((3, 4), np.uint8))
    assert folder_listing(tmp_path) == []


def test_new_file_gets_umask_permissions(tmp_path):
    previous = os.umask(0o027)
    try:
        write_image(tmp_path / "new.tif", random_image((3, 4), np.uint8))
    finally:
        os.umask(previous)
    assert stat.S_IMODE(os.stat(tmp_path / "new.tif").st_mode) == 0o640


def test_replaced_file_keeps_its_permissions(tmp_path):
    target = tmp_path / "out.png"
    write_image(target, random_image((3, 4), np.uint8))
    os.chmod(target, 0o604)
    write_image(target, random_image((3, 4), np.uint8, seed=3))
    assert stat.S_IMODE(os.stat(target).st_mode) == 0o604


# --- recover() with bad inputs -------------------------------------------------------------------


def test_recover_refuses_different_sizes_naming_both():
    assert_input_error(lambda: aarecovery.recover(np.zeros((16, 20)), np.zeros((10, 12)), backend="numpy"),
                       "20x16", "12x10")


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_recover_refuses_non_finite_values(bad):
    filtered = np.full((6, 6), 0.5, np.float32)
    filtered[2, 3] = bad
    assert_input_error(lambda: aarecovery.recover(np.zeros((6, 6), np.float32), filtered, backend="numpy"),
                       "filtered", "NaN or infinite", "row 2, column 3")


def test_recover_refuses_zero_size():
    assert_input_error(lambda: aarecovery.recover(np.zeros((0, 5)), np.zeros((0, 5)), backend="numpy"),
                       "(0, 5)", "empty")


def test_recover_of_read_images_keeps_filtered_depth(tmp_path):
    original = random_image((12, 10, 3), np.uint16)
    filtered = (original > 32767).astype(np.uint8) * np.uint8(255)
    write_image(tmp_path / "o.png", original)
    write_image(tmp_path / "f.png", filtered)
    result = aarecovery.recover(read_image(tmp_path / "o.png"), read_image(tmp_path / "f.png"), backend="numpy")
    assert result.dtype == np.uint8 and result.shape == filtered.shape


def test_import_stays_light():
    code = "import sys, aarecovery; print(sorted({'PIL', 'imagecodecs', 'tifffile'} & set(sys.modules)))"
    output = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert output.strip() == "[]"


def test_jpeg_exif_orientation_is_applied(tmp_path):
    image = Image.new("RGB", (8, 4), (200, 10, 10))
    exif = Image.Exif()
    exif[0x0112] = 6  # Orientation: the camera was turned; viewers rotate 90 degrees clockwise.
    image.save(tmp_path / "turned.jpg", exif=exif)
    assert read_image(tmp_path / "turned.jpg").shape == (8, 4, 3)


def test_a_flipped_or_strided_view_is_written(tmp_path):
    image = np.arange(6 * 8 * 3, dtype=np.uint8).reshape(6, 8, 3)
    for name, view in (("flipped.png", image[:, ::-1]), ("channel.png", image[..., 1]), ("every-other.tif", image[::2])):
        write_image(tmp_path / name, view)
        np.testing.assert_array_equal(read_image(tmp_path / name), view)


def test_a_codec_that_cannot_load_for_lack_of_memory_is_not_called_a_broken_file(tmp_path):
    # A process at its memory limit cannot map imagecodecs' PNG library; imagecodecs reports
    # that as "could not import name 'png_decode'", which read as a corrupt file before.
    write_image(tmp_path / "small.png", np.zeros((8, 8, 3), np.uint8))
    script = (
        "import resource, sys\n"
        "import imagecodecs\n"
        "from aarecovery import read_image\n"
        "size = int(open('/proc/self/statm').read().split()[0]) * resource.getpagesize()\n"
        "resource.setrlimit(resource.RLIMIT_AS, (size, resource.RLIM_INFINITY))\n"
        "try:\n"
        "    read_image(sys.argv[1])\n"
        "except BaseException as error:\n"
        "    print(type(error).__name__, error)\n")
    result = subprocess.run([sys.executable, "-c", script, str(tmp_path / "small.png")], capture_output=True,
                            text=True, timeout=60)
    assert result.stdout.startswith("NotEnoughMemory could not load the PNG decoder"), result
    assert "complete?" not in result.stdout and "out of memory" in result.stdout
