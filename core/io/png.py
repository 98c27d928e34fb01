"""A fast, standard PNG encoder for 8 and 16-bit images.

libpng (through imagecodecs) tries every row filter on every row and deflates with zlib at
level 6: 4.4 s of CPU for a noisy 4096 x 4096 RGB result, more than the whole recovery.
Here every row gets PNG's "Up" filter (one NumPy subtraction), and libdeflate (bundled with
imagecodecs) compresses the stream in one call. Measured on 4096 x 4096 8-bit RGB results
of ``aarecovery recover``, CPU seconds:

======================  ===============  ==============  ===================
result                  libpng, level 6  this, level 1   size against libpng
======================  ===============  ==============  ===================
thresholded pair        0.33 s           0.13 s          +12% (1.43 MiB)
gamma pair (noisy)      4.4 s            0.32 s          +6% (23.1 MiB)
======================  ===============  ==============  ===================

Most of a recovered image is often flat (a threshold, a posterize: the method's main use),
and its Up-filtered rows are then nearly all zero bytes; there zlib-ng (also bundled with
imagecodecs) at level 2 compresses 3-8x faster than libdeflate at level 1, to the same size
or smaller, and on noisy rows 1.2-2x slower. So the rows choose (:data:`FLAT_ZERO_SHARE`),
measured in milliseconds and megabytes of output, best of three:

=================================  ==========  ============  =============  ===============
Up-filtered rows                   zero bytes  libdeflate 1  zlib-ng 2      choice
=================================  ==========  ============  =============  ===============
thin-features result, 4096 x 4096  0.99        120 ms 0.44   15 ms 0.44     zlib-ng
photo-like result, 4096 x 4096     0.96        125 ms 1.56   30 ms 1.57     zlib-ng
noisy photo, 4096 x 4096           0.18        202 ms 23.1   399 ms 23.3    libdeflate
noise in 20 % of its rows, 2048^2  0.79        34 ms 1.22    22 ms 1.24     zlib-ng
noise in 40 % of its rows, 2048^2  0.55        38 ms 2.52    43 ms 2.56     libdeflate
bundled photos, thresholded        0.91-0.94   8-17 ms       2.5-3.3 ms     zlib-ng
=================================  ==========  ============  =============  ===============

Any PNG reader reads the files: a zlib stream in IDAT chunks, filter type 2 on every row
(the first row's prior row counts as zeros, so it is stored as it is). Images of more than
:data:`ONE_SHOT_BYTES` are filtered and compressed in bands through zlib instead, which
holds one band at a time (a 20000 x 20000 RGB image would otherwise need a second 1.2 GB).
"""

import io
import struct
import zlib

import numpy as np

from .formats import import_codec

__all__ = ["encode_png", "write_png", "COMPRESSION_LEVEL", "ONE_SHOT_BYTES", "FLAT_ZERO_SHARE", "FLAT_LEVEL"]

#: libdeflate's level: 1 was the fastest and within 6-12% of libpng's size (the table above);
#: level 3 took 1.9x the time for 2% smaller files on the noisy image. zlib's level 1 for
#: large images.
COMPRESSION_LEVEL = 1
#: Up-filtered rows with at least this share of zero bytes are compressed by zlib-ng at
#: :data:`FLAT_LEVEL` (the table above: it is the faster above about 0.6-0.7).
FLAT_ZERO_SHARE = 0.75
FLAT_LEVEL = 2
#: Images up to this many bytes of samples are compressed in one call (libdeflate or zlib-ng).
ONE_SHOT_BYTES = 1 << 28
# Rows per band of the banded encoder, and the largest IDAT chunk written.
_BAND_BYTES = 1 << 24
_MAX_CHUNK = 1 << 30
# PNG colour types by channel count: grey, grey+alpha, RGB, RGBA.
_COLOUR_TYPES = {1: 0, 2: 4, 3: 2, 4: 6}
_UP = 2


def _chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def _up_filtered(rows, previous=None):
    """Rows of big-endian samples, each prefixed by its filter type, Up-filtered.

    `previous` is the row above the first (zeros at the image's top).
    """
    height = rows.shape[0]
    samples = rows.astype(rows.dtype.newbyteorder(">"), copy=False)
    data = samples.reshape(height, -1).view(np.uint8)
    filtered = np.empty((height, data.shape[1] + 1), np.uint8)
    filtered[:, 0] = _UP
    if previous is None:
        filtered[0, 1:] = data[0]
    else:
        np.subtract(data[0], previous, out=filtered[0, 1:])
    # Bytes wrap modulo 256, as the filter is defined.
    np.subtract(data[1:], data[:-1], out=filtered[1:, 1:])
    return filtered, data[-1].copy()


def _mostly_flat(filtered):
    """Whether Up-filtered rows are mostly zero bytes, judged on every 16th row (not the
    first, which is stored as it is)."""
    sample = filtered[1::16, 1:]
    return sample.size > 0 and np.count_nonzero(sample) <= (1 - FLAT_ZERO_SHARE) * sample.size


def _compressed(pixels, level):
    """The zlib stream of the filtered rows, in pieces."""
    if pixels.nbytes <= ONE_SHOT_BYTES:
        imagecodecs = import_codec("imagecodecs", "PNG")
        filtered = _up_filtered(pixels)[0]
        if level == COMPRESSION_LEVEL and _mostly_flat(filtered) and imagecodecs.ZLIBNG.available:
            yield imagecodecs.zlibng_encode(filtered, level=FLAT_LEVEL)
        else:
            yield imagecodecs.deflate_encode(filtered, level=level)
        return
    compressor = zlib.compressobj(level)
    band = max(1, _BAND_BYTES // max(1, pixels[0].nbytes))
    previous = None
    for top in range(0, pixels.shape[0], band):
        filtered, previous = _up_filtered(pixels[top:top + band], previous)
        yield compressor.compress(filtered)
    yield compressor.flush()


def write_png(file, pixels, level=COMPRESSION_LEVEL):
    """Write an image to a binary file as PNG.

    Parameters
    ----------
    file : binary file object
    pixels : ndarray of uint8 or uint16, shape (H, W) or (H, W, C), C in 1..4
        Grey, grey+alpha, RGB or RGBA.
    level : int
        The compression level, 1 (fastest) to 9.
    """
    height, width = pixels.shape[:2]
    channels = 1 if pixels.ndim == 2 else pixels.shape[2]
    depth = 8 if pixels.dtype == np.uint8 else 16
    file.write(b"\x89PNG\r\n\x1a\n")
    file.write(_chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, depth, _COLOUR_TYPES[channels], 0, 0, 0)))
    for piece in _compressed(pixels, level):
        for start in range(0, len(piece), _MAX_CHUNK):
            file.write(_chunk(b"IDAT", piece[start:start + _MAX_CHUNK]))
    file.write(_chunk(b"IEND", b""))


def encode_png(pixels, level=COMPRESSION_LEVEL):
    """The bytes :func:`write_png` writes."""
    buffer = io.BytesIO()
    write_png(buffer, pixels, level)
    return buffer.getvalue()
