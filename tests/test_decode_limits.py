"""Decompression bombs: every reader checks the size a file declares before it decodes.

The bombs are complete, valid files of the issue's size (40000 x 40000 RGB, 4.8 GB once
decoded) made cheaply: a PNG whose deflate stream repeats one flushed block of zeros, sparse
TIFF and ``.npy`` files, and GIF and JPEG files whose headers declare the size of their
frame. Each read is timed and runs under a 2 GB address-space limit: a reader that decoded
first would run out of memory, or take minutes, instead of refusing in a moment.
"""

import io
import os
import struct
import subprocess
import sys
import time
import zlib

import numpy as np
import pytest
import tifffile
from PIL import Image

import aarecovery
from aarecovery import InputError, read_image, write_image
from aarecovery.cli import main
from aarecovery.io import DEFAULT_MAX_BYTES, check_decoded_size
from test_cli_safety import full_folder  # noqa: F401 (a fixture)

BOMB = (40000, 40000)  # height, width


def _chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def png_of_zeros(height, width, channels=3):
    """A complete, valid RGB 8-bit PNG of zeros, built without holding its pixels."""
    total = height * (1 + width * channels)  # each row: filter byte 0, then the samples
    block = 1 << 20
    compressor = zlib.compressobj(9, zlib.DEFLATED, -15)
    # After a full flush deflate keeps no history, so this piece encodes any 1 MiB of zeros.
    piece = compressor.compress(bytes(block)) + compressor.flush(zlib.Z_FULL_FLUSH)
    tail = compressor.compress(bytes(total % block)) + compressor.flush(zlib.Z_FINISH)
    adler = ((total % 65521) << 16) | 1  # Adler-32 of `total` zero bytes
    stream = b"\x78\xda" + piece * (total // block) + tail + struct.pack(">I", adler)
    colour = {1: 0, 3: 2, 4: 6}[channels]
    return (b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, colour, 0, 0, 0))
            + _chunk(b"IDAT", stream) + _chunk(b"IEND", b""))


def header_patched(image, format_name, patch):
    buffer = io.BytesIO()
    image.save(buffer, format_name)
    data = bytearray(buffer.getvalue())
    patch(data)
    return bytes(data)


def gif_declaring(height, width):
    def patch(data):
        data[6:10] = struct.pack("<HH", width, height)        # logical screen
        start = data.index(b"\x2c")                         # image descriptor
        data[start + 5:start + 9] = struct.pack("<HH", width, height)
    return header_patched(Image.new("P", (8, 8)), "GIF", patch)


def jpeg_declaring(height, width):
    def patch(data):
        start = data.index(b"\xff\xc0")                     # SOF0: length, precision, height, width
        data[start + 5:start + 9] = struct.pack(">HH", height, width)
    return header_patched(Image.new("RGB", (8, 8)), "JPEG", patch)


def make_bomb(folder, kind):
    path = folder / f"bomb.{kind}"
    height, width = BOMB
    if kind == "png":
        path.write_bytes(png_of_zeros(height, width))
    elif kind == "tif":
        tifffile.imwrite(path, shape=(height, width, 3), dtype=np.uint8, photometric="rgb")  # sparse
    elif kind == "npy":
        np.lib.format.open_memmap(path, mode="w+", dtype=np.uint8, shape=(height, width, 3)).flush()  # sparse
    elif kind == "gif":
        path.write_bytes(gif_declaring(height, width))
    else:
        path.write_bytes(jpeg_declaring(height, width))
    return path


def test_the_png_bomb_builder_makes_valid_pngs(tmp_path):
    (tmp_path / "small.png").write_bytes(png_of_zeros(700, 500))
    image = read_image(tmp_path / "small.png")
    assert image.shape == (700, 500, 3) and not image.any()


@pytest.mark.parametrize("kind", ["png", "tif", "npy", "gif", "jpg"])
def test_bombs_are_refused_before_decoding(tmp_path, kind):
    path = make_bomb(tmp_path, kind)
    assert path.stat().st_size < 8 * 10**6 or kind in ("tif", "npy")  # sparse files hold no pixels
    code = ("import resource, sys, time\n"
            "resource.setrlimit(resource.RLIMIT_AS, (2 * 10**9, 2 * 10**9))\n"
            "from aarecovery import read_image, InputError\n"
            "start = time.perf_counter()\n"
            "try:\n    read_image(sys.argv[1])\n    print('READ')\n"
            "except InputError as error:\n    print(time.perf_counter() - start)\n    print(error)\n")
    done = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    seconds, message = done.stdout.split("\n", 1)
    assert float(seconds) < 5
    assert "40000x40000 RGB 8-bit" in message and "4.8 GB once decoded" in message
    assert "decompression bomb" in message and "--max-image-memory 4.8" in message


def test_the_limit_can_be_raised_and_lowered(tmp_path, monkeypatch):
    image = np.zeros((200, 300, 3), np.uint8)  # 180 kB decoded
    for extension in (".png", ".tif", ".npy", ".webp", ".bmp", ".jpg"):
        path = tmp_path / f"image{extension}"
        write_image(path, image)
        with pytest.raises(InputError, match="100 kB limit"):
            read_image(path, max_bytes=100_000)
        assert read_image(path, max_bytes=10**6).shape == (200, 300, 3)
        monkeypatch.setenv("AARECOVERY_MAX_IMAGE_MEMORY", "0.0001")
        with pytest.raises(InputError, match="100 kB limit"):
            read_image(path)
        monkeypatch.delenv("AARECOVERY_MAX_IMAGE_MEMORY")
        assert read_image(path).shape == (200, 300, 3)


@pytest.mark.parametrize("command", [
    ["recover", "{path}", "{path}", "-o", "{out}"],
    ["filter", "threshold", "{path}", "-o", "{out}"],
    ["demo", "{path}", "-o", "{folder}/demo"],
])
def test_every_command_that_reads_has_the_option(tmp_path, capsys, command):
    path = tmp_path / "image.png"
    write_image(path, np.zeros((100, 200, 3), np.uint8))
    args = [part.format(path=path, out=tmp_path / "r.png", folder=tmp_path) for part in command]
    assert main(args + ["--max-image-memory", "0.00001", "--backend", "numpy"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "decompression bomb" in err and "10 kB limit" in err
    assert main(args + ["--max-image-memory", "0.1", "--backend", "numpy"]) == 0, capsys.readouterr().err


def test_view_has_the_option():
    from aarecovery.cli import build_parser
    args = build_parser().parse_args(["view", "o.png", "f.png", "--max-image-memory", "12"])
    assert args.max_image_memory == 12


def test_the_default_lets_the_documented_large_images_through():
    assert DEFAULT_MAX_BYTES == 4 * 10**9
    check_decoded_size("scan.tif", (20000, 20000, 3), np.uint8)
    check_decoded_size("scan.tif", (20000, 20000, 4), np.uint16)
    with pytest.raises(InputError, match="decompression bomb"):
        check_decoded_size("bomb.png", (40000, 40000, 3), np.uint8)


def test_palette_and_transparency_are_counted_as_decoded(tmp_path):
    palette = Image.new("P", (300, 200))
    palette.save(tmp_path / "palette.png", transparency=0)
    # libpng expands it to RGBA: 240 kB, not the 60 kB of its indices.
    with pytest.raises(InputError, match="300x200 RGBA 8-bit pixels, 240 kB"):
        read_image(tmp_path / "palette.png", max_bytes=200_000)
    assert read_image(tmp_path / "palette.png", max_bytes=240_000).shape == (200, 300, 4)


def test_refusal_is_quick_in_process(tmp_path):
    path = make_bomb(tmp_path, "png")
    start = time.perf_counter()
    with pytest.raises(InputError):
        read_image(path)
    assert time.perf_counter() - start < 2


@pytest.mark.parametrize("value", ["0", "-2", "eight", "inf"])
def test_a_limit_that_is_not_a_positive_number_says_so(capsys, value):
    with pytest.raises(SystemExit):
        main(["recover", "o.png", "f.png", "-o", "r.png", "--max-image-memory", value])
    err = capsys.readouterr().err
    assert "a positive number of GB is needed" in err and repr(value) in err and "_gigabytes" not in err


# --- streamed pairs and the peak of a recovery count against the limit (issue 20, item 7) -----------------

def _tiled_pair(folder, size, *, noisy=False):
    """A tiled BigTIFF pair of `size` x `size` RGB that streams; flat (tiny files) unless `noisy`."""
    import tifffile

    rng = np.random.default_rng(0)
    original = rng.integers(0, 256, (size, size, 3), dtype=np.uint8) if noisy else np.full((size, size, 3), 90,
                                                                                           np.uint8)
    filtered = np.where(original > 127, 255, 0).astype(np.uint8) if not noisy else original[::-1].copy()
    paths = []
    for name, image in (("o.tif", original), ("f.tif", filtered)):
        tifffile.imwrite(folder / name, image, tile=(256, 256), bigtiff=True, photometric="rgb",
                         compression=None if noisy else "zlib")
        paths.append(folder / name)
    return paths


def test_a_streamed_pair_that_declares_more_than_the_limit_is_refused(tmp_path, capsys, backend):
    original, filtered = _tiled_pair(tmp_path, 2048)
    assert os.path.getsize(filtered) < 200_000   # 12.6 MB declared
    status = main(["recover", str(original), str(filtered), "-o", str(tmp_path / "r.tif"), "--backend", backend,
                   "--max-image-memory", "0.005"])
    err = capsys.readouterr().err
    assert status == 1 and err.startswith("aarecovery: error: ") and len(err.splitlines()) == 1, err
    assert "2048x2048" in err and "--max-image-memory" in err
    assert not (tmp_path / "r.tif").exists()
    status = main(["batch", str(tmp_path / "o.ti[f]"), str(tmp_path / "f.ti[f]"), "-o", str(tmp_path / "r"),
                   "--backend", backend, "--max-image-memory", "0.005"])
    err = capsys.readouterr().err
    assert status == 1 and "failed: f.tif" in err and "--max-image-memory" in err
    assert not (tmp_path / "r" / "f.tif").exists()


def _grey_png_pair(folder, size):
    ramp = np.tile(np.linspace(0, 255, size).astype(np.uint8), (size, 1))
    aarecovery.write_image(folder / "o.png", ramp)
    aarecovery.write_image(folder / "f.png", np.where(ramp > 127, 255, 0).astype(np.uint8))
    return folder / "o.png", folder / "f.png"


def test_the_peak_of_a_recovery_counts_against_the_limit_not_only_the_decoded_images(tmp_path, capsys, backend):
    original, filtered = _grey_png_pair(tmp_path, 600)     # 0.36 MB decoded each
    status = main(["recover", str(original), str(filtered), "-o", str(tmp_path / "r.png"), "--backend", backend,
                   "--max-image-memory", "0.002"])
    err = capsys.readouterr().err
    assert status == 1 and err.startswith("aarecovery: error: ") and len(err.splitlines()) == 1, err
    assert "600x600" in err and "peak" in err and "--max-image-memory" in err
    assert not (tmp_path / "r.png").exists()
    results = aarecovery.recover_many([(original, filtered)], tmp_path / "r", backend=backend, max_bytes=2e6)
    assert results[0].status == "failed" and "peak" in results[0].error
    status = main(["recover", str(original), str(filtered), "-o", str(tmp_path / "r.png"), "--backend", backend,
                   "--max-image-memory", "0.5"])
    assert status == 0, capsys.readouterr().err


def test_a_streamed_result_larger_than_the_free_disk_space_is_refused(tmp_path, capsys, full_folder):
    original, filtered = _tiled_pair(tmp_path, 1280, noisy=True)   # 4.9 MB files; the disk has 1 MB
    status = main(["recover", str(original), str(filtered), "-o", str(full_folder / "r.tif"), "--backend",
                   "numpy", "--paper"])
    err = capsys.readouterr().err
    assert status == 1 and err.startswith("aarecovery: error: ") and len(err.splitlines()) == 1, err
    assert str(full_folder) in err and "free" in err and "as much as" in err
    assert os.listdir(full_folder) == []
