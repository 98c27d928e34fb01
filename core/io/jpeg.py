"""What a JPEG file says about its own compression: its quantization tables.

The safe default reads the compression noise of O from them
(``aarecovery.plan.compression``); an image given as an array has no file, and the plan
searches its pixels for the block grid instead. Pillow parses the tables with the header,
without decoding the pixels.
"""

__all__ = ["read_quantization"]

# Every JPEG file starts with a start-of-image marker followed by another marker.
_JPEG_SIGNATURE = b"\xff\xd8\xff"


def read_quantization(path):
    """The quantization tables of a JPEG file, or None for any other file.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    list of list of int or None
        64 steps per table, luma first, as Pillow gives them (the noise bound does not
        depend on the order of the steps); None when the file is not a JPEG (a PNG, a TIFF:
        no compression noise) or cannot be opened as an image (``read_image`` reports that).
    """
    try:
        with open(path, "rb") as handle:
            if handle.read(len(_JPEG_SIGNATURE)) != _JPEG_SIGNATURE:
                return None
    except OSError:
        return None
    # Pillow only for a JPEG, as in ``read.py``: the GIMP plug-in's bundle has no Pillow, and
    # an .npy pair read under a tight memory limit should not pay for importing it.
    from PIL import Image, UnidentifiedImageError
    try:
        with Image.open(path) as image:
            if image.format != "JPEG":
                return None
            tables = getattr(image, "quantization", None)
    except (OSError, UnidentifiedImageError, ValueError, Image.DecompressionBombError):
        # read_image reports these with its own limit; the tables are only evidence.
        return None
    if not tables:
        return None
    return [list(tables[key]) for key in sorted(tables)]
