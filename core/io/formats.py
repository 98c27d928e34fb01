"""What the reader and writer share: the formats, how to import a codec, layout names."""

import importlib

import numpy as np

from ..errors import InputError

__all__ = ["WRITE_FORMATS", "READ_FORMATS", "NPY_DTYPES", "LOSSLESS_EXTENSIONS", "lossless_extension", "import_codec",
           "layout_name"]

#: Output extensions and the format each one writes.
WRITE_FORMATS = {
    ".png": "PNG", ".tif": "TIFF", ".tiff": "TIFF", ".npy": "NPY",
    ".jpg": "JPEG", ".jpeg": "JPEG", ".webp": "WEBP", ".bmp": "BMP",
}
#: Extensions whose files keep every value written (8 and 16-bit PNG; TIFF and .npy up to
#: float; 8-bit BMP).
LOSSLESS_EXTENSIONS = (".png", ".tif", ".tiff", ".npy", ".bmp")


def lossless_extension(extension):
    """`extension` when its format is lossless, else ``".png"``: the lossy and palette formats
    (JPEG, WebP, GIF...) hold at most 8 bits per channel, which PNG keeps exactly."""
    return extension if extension.lower() in LOSSLESS_EXTENSIONS else ".png"


#: What :func:`aarecovery.read_image` reads, for messages.
READ_FORMATS = ("PNG (8/16-bit), TIFF (8/16-bit, 32-bit float), NumPy .npy (uint8, uint16, float32, "
                "float64), and as 8-bit JPEG, WebP, BMP, GIF and the other formats Pillow reads")
#: The dtypes a ``.npy`` image may hold.
NPY_DTYPES = (np.uint8, np.uint16, np.float32, np.float64)

_LAYOUT_NAMES = {1: "grey", 2: "grey+alpha", 3: "RGB", 4: "RGBA"}


def layout_name(shape):
    """``"grey"``, ``"grey+alpha"``, ``"RGB"`` or ``"RGBA"`` for an image shape."""
    return _LAYOUT_NAMES[1 if len(shape) == 2 else shape[2]]


def import_codec(module, format_name):
    try:
        return importlib.import_module(module)
    except ImportError:
        raise InputError(f"{format_name} files need the {module} package, which is not installed here; "
                         f"install it with 'pip install {module}', or use another format") from None
