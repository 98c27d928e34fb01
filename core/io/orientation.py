"""The orientation a file declares, and turning stored pixels upright the way viewers show them.

Cameras store the sensor's rows and say in a tag how to turn them (EXIF Orientation in JPEG,
WebP and PNG's ``eXIf`` chunk; the TIFF Orientation tag, the same numbers). Pillow applies
it for JPEG and WebP; PNG (read by imagecodecs) and TIFF (tifffile) are turned here, so that
every format gives the same upright pixels. Otherwise a rotated PNG original is refused
against an upright filtered image, and a square pair is silently recovered misaligned.
"""

import struct
from collections import namedtuple

import numpy as np

from ..errors import InputError

__all__ = ["apply_orientation", "exif_orientation", "png_header", "tiff_orientation", "PngHeader",
           "ORIENTATION_NAMES"]

#: What each orientation value asks a viewer to do with the stored pixels.
ORIENTATION_NAMES = {
    1: "upright", 2: "mirrored left-right", 3: "turned 180 degrees", 4: "mirrored top-bottom",
    5: "transposed", 6: "turned 90 degrees clockwise", 7: "transversed", 8: "turned 90 degrees anticlockwise",
}
_ORIENTATION_TAG = 0x0112


def apply_orientation(image, orientation):
    """The stored `image` turned upright by EXIF/TIFF `orientation` (1 to 8; others as 1).

    The same transforms as Pillow's ``ImageOps.exif_transpose``; a view, not a copy.
    """
    if orientation == 2:
        return image[:, ::-1]
    if orientation == 3:
        return image[::-1, ::-1]
    if orientation == 4:
        return image[::-1]
    if orientation == 5:
        return image.swapaxes(0, 1)
    if orientation == 6:
        return np.rot90(image, -1)
    if orientation == 7:
        return image[::-1, ::-1].swapaxes(0, 1)
    if orientation == 8:
        return np.rot90(image, 1)
    return image


def exif_orientation(data):
    """The Orientation value in EXIF `data` (a TIFF structure, optionally after ``Exif\\0\\0``); 1 if none."""
    if data.startswith(b"Exif\x00\x00"):
        data = data[6:]
    order = {b"II": "<", b"MM": ">"}.get(data[:2])
    if order is None:
        return 1
    try:
        (offset,) = struct.unpack_from(order + "I", data, 4)
        (count,) = struct.unpack_from(order + "H", data, offset)
        for index in range(count):
            entry = offset + 2 + 12 * index
            tag, kind = struct.unpack_from(order + "HH", data, entry)
            if tag == _ORIENTATION_TAG and kind == 3:  # SHORT
                (value,) = struct.unpack_from(order + "H", data, entry + 8)
                return value if value in ORIENTATION_NAMES else 1
    except struct.error:
        pass
    return 1


def tiff_orientation(page):
    """The Orientation tag of a tifffile page; 1 if none or invalid."""
    tag = page.tags.get(274)
    try:
        value = int(tag.value) if tag is not None else 1
    except (TypeError, ValueError):
        return 1
    return value if value in ORIENTATION_NAMES else 1


#: What a PNG declares before it is decoded: ``shape`` and ``dtype`` as libpng expands them.
PngHeader = namedtuple("PngHeader", "shape dtype orientation")
# Channels per IHDR colour type before tRNS: grey, RGB, palette (expanded to RGB), grey+alpha, RGBA.
_PNG_CHANNELS = {0: 1, 2: 3, 3: 3, 4: 2, 6: 4}


def png_header(path):
    """Read a PNG's IHDR and walk its chunk headers (no pixel data is read or decoded).

    Raises
    ------
    InputError
        When the IHDR chunk is missing or malformed.
    """
    with open(path, "rb") as file:
        file.seek(8)
        head = file.read(8 + 13)
        if len(head) < 21 or head[4:8] != b"IHDR":
            raise InputError(f"could not decode {path} as PNG: no IHDR chunk; is the file complete?")
        width, height, depth, colour = struct.unpack(">IIBB", head[8:18])
        if colour not in _PNG_CHANNELS or width == 0 or height == 0:
            raise InputError(f"could not decode {path} as PNG: IHDR declares {width}x{height} with colour "
                             f"type {colour}; is the file complete?")
        file.seek(4, 1)  # IHDR's CRC
        transparency, orientation = False, 1
        while True:
            chunk = file.read(8)
            if len(chunk) < 8:
                break
            length, kind = struct.unpack(">I4s", chunk)
            if kind == b"IEND":
                break
            if kind == b"eXIf":
                orientation = exif_orientation(file.read(length))
                file.seek(4, 1)
                continue
            transparency |= kind == b"tRNS"
            file.seek(length + 4, 1)
    # libpng expands a tRNS chunk into an alpha channel (palette, grey and RGB alike).
    channels = _PNG_CHANNELS[colour] + int(transparency and colour in (0, 2, 3))
    shape = (height, width) if channels == 1 else (height, width, channels)
    return PngHeader(shape, np.dtype(np.uint16 if depth == 16 else np.uint8), orientation)
