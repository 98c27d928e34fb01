"""How much memory one image may take once decoded, checked from the file's header first.

A few-megabyte PNG or GIF can declare 40000 x 40000 pixels and decode to gigabytes (a
decompression bomb). Every reader asks :func:`check_decoded_size` with the shape and dtype it
is about to decode, before it decodes anything. The limit is on what is decoded into memory
at once: a reader that decodes a large file piece by piece checks each piece, not the whole.

Why 4 GB by default: ``recover`` holds O, F and R whole (R at F's depth) and one tile's
working set beside them (about 0.5 GB on GL), so a pair of images at the limit needs about
3 x 4 + 0.5 = 12.5 GB, what a 16 GB workstation can give; measured, a 20000 x 20000 RGB pair
(1.2 GB per image) peaked at 4.6 GB. The documented large cases pass: 20000 x 20000 RGB
8-bit (1.2 GB) and even 16-bit RGBA (3.2 GB); the 40000 x 40000 RGB bomb (4.8 GB once
decoded, from a 1.5 MB PNG or a 1.2 MB GIF) is refused before decoding.
"""

import math
import os

import numpy as np

from ..errors import InputError

__all__ = ["DEFAULT_MAX_BYTES", "ENVIRONMENT_VARIABLE", "max_bytes_from", "check_decoded_size", "format_bytes"]

#: The default limit on one decoded image, in bytes (see the module's text for why).
DEFAULT_MAX_BYTES = 4 * 10**9
#: Raises the limit for every read in the process, in GB (a viewer or plug-in session).
ENVIRONMENT_VARIABLE = "AARECOVERY_MAX_IMAGE_MEMORY"
_LAYOUTS = {1: "grey", 2: "grey+alpha", 3: "RGB", 4: "RGBA"}


def format_bytes(count):
    """``"4.8 GB"``, ``"310 MB"``: decimal units, as disks and ``--max-image-memory`` count."""
    if count >= 10**9:
        return f"{count / 1e9:.1f} GB"
    return f"{count / 1e6:.0f} MB" if count >= 10**6 else f"{count / 1e3:.0f} kB"


def max_bytes_from(max_bytes=None):
    """The limit in force: `max_bytes` if given, else the environment's, else the default."""
    if max_bytes is not None:
        if isinstance(max_bytes, bool) or not isinstance(max_bytes, (int, float, np.integer, np.floating)) \
                or not max_bytes > 0:
            raise InputError(f"max_bytes must be a positive number of bytes, got {max_bytes!r}")
        return max_bytes
    text = os.environ.get(ENVIRONMENT_VARIABLE)
    if text:
        try:
            gigabytes = float(text)
        except ValueError:
            gigabytes = math.nan
        if not gigabytes > 0 or not math.isfinite(gigabytes):
            raise InputError(f"{ENVIRONMENT_VARIABLE} must be a positive number of GB, got {text!r}")
        return gigabytes * 1e9
    return DEFAULT_MAX_BYTES


def check_decoded_size(path, shape, dtype, max_bytes=None):
    """Raise :class:`InputError` if decoding `shape` at `dtype` at once would exceed the limit.

    Parameters
    ----------
    path : str
        The file, for the message.
    shape : tuple of int
        ``(H, W)`` or ``(H, W, C)`` as the reader will return it (or one piece of it).
    dtype : numpy.dtype
        The dtype it will be returned in.
    max_bytes : int or float, optional
        The limit; by default :func:`max_bytes_from`.
    """
    limit = max_bytes_from(max_bytes)
    needed = math.prod(int(side) for side in shape) * np.dtype(dtype).itemsize
    if needed <= limit:
        return
    height, width = int(shape[0]), int(shape[1])
    channels = 1 if len(shape) == 2 else int(shape[2])
    depth = f"{np.dtype(dtype).itemsize * 8}-bit" + (" float" if np.dtype(dtype).kind == "f" else "")
    raise InputError(
        f"{path} declares {width}x{height} {_LAYOUTS.get(channels, f'{channels}-channel')} {depth} pixels, "
        f"{format_bytes(needed)} once decoded, over the {format_bytes(limit)} limit for one image (a small file "
        f"that claims this much is a decompression bomb); if it is genuine, raise the limit: --max-image-memory "
        f"{math.ceil(needed / 1e8) / 10:g} on the command line, max_bytes= in read_image, or "
        f"{ENVIRONMENT_VARIABLE} (GB)")
