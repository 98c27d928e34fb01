"""The fast PNG encoder: standard files, every layout and depth, lossless, in one piece or in bands."""

import io

import imagecodecs
import numpy as np
import pytest
from PIL import Image

from aarecovery.io import png, read_image, write_image

LAYOUTS = [((5, 7), np.uint8), ((5, 7, 2), np.uint8), ((6, 9, 3), np.uint8), ((4, 3, 4), np.uint8),
           ((5, 7), np.uint16), ((5, 7, 2), np.uint16), ((6, 9, 3), np.uint16), ((64, 80, 4), np.uint16),
           ((1, 1, 3), np.uint8)]


@pytest.mark.parametrize("shape, dtype", LAYOUTS)
@pytest.mark.parametrize("banded", [False, True])
def test_round_trip_through_other_readers(monkeypatch, shape, dtype, banded):
    if banded:  # the zlib bands of large images, with tiny bands and IDAT chunks
        monkeypatch.setattr(png, "ONE_SHOT_BYTES", 0)
        monkeypatch.setattr(png, "_BAND_BYTES", 40)
        monkeypatch.setattr(png, "_MAX_CHUNK", 17)
    pixels = np.random.default_rng(sum(shape)).integers(0, np.iinfo(dtype).max + 1, shape).astype(dtype)
    encoded = png.encode_png(pixels)
    decoded = imagecodecs.png_decode(encoded)  # libpng
    assert decoded.dtype == dtype and decoded.shape == pixels.shape
    np.testing.assert_array_equal(decoded, pixels)
    if dtype == np.uint8:  # Pillow's own decoder
        np.testing.assert_array_equal(np.asarray(Image.open(io.BytesIO(encoded))).reshape(shape), pixels)


@pytest.mark.parametrize("shape, dtype", LAYOUTS)
def test_mostly_flat_rows_go_through_zlib_ng_and_noisy_ones_through_libdeflate(monkeypatch, shape, dtype):
    calls = []
    for name in ("zlibng_encode", "deflate_encode"):
        encode = getattr(imagecodecs, name)
        monkeypatch.setattr(imagecodecs, name, lambda data, level, _name=name, _encode=encode: (
            calls.append(_name), _encode(data, level=level))[1])
    rng = np.random.default_rng(sum(shape))
    noisy = rng.integers(0, np.iinfo(dtype).max + 1, shape).astype(dtype)
    flat = np.full(shape, 7, dtype)
    flat.flat[rng.integers(0, flat.size, max(1, flat.size // 50))] = 200  # a few marks
    # One row is stored as it is, with nothing below it to judge: libdeflate.
    flat_codec = "zlibng_encode" if shape[0] > 1 else "deflate_encode"
    for pixels, codec in ((flat, flat_codec), (noisy, "deflate_encode")):
        calls.clear()
        encoded = png.encode_png(pixels)
        assert calls == [codec]
        np.testing.assert_array_equal(imagecodecs.png_decode(encoded), pixels)
        if dtype == np.uint8:
            np.testing.assert_array_equal(np.asarray(Image.open(io.BytesIO(encoded))).reshape(shape), pixels)


def test_write_image_uses_it_and_stays_small(tmp_path):
    # A smooth image: the Up filter and deflate keep it far below its raw size.
    rows = np.linspace(0, 255, 300)[:, None, None]
    smooth = np.broadcast_to(rows, (300, 400, 3)).astype(np.uint8)
    write_image(tmp_path / "smooth.png", smooth)
    np.testing.assert_array_equal(read_image(tmp_path / "smooth.png"), smooth)
    assert (tmp_path / "smooth.png").stat().st_size < smooth.nbytes / 50
