"""How much memory one image may take once decoded, checked from the file's header first.

A few-megabyte PNG or GIF can declare 40000 x 40000 pixels and decode to gigabytes (a
decompression bomb). Every reader asks :func:`check_decoded_size` with the shape and dtype it
is about to decode, before it decodes anything. The limit is on what is decoded into memory
at once: a reader that decodes a large file piece by piece checks each piece, not the whole.

Why 4 GB by default: what a 16 GB workstation gives a recovery with room to spare. The
commands hold more than the decoded images to it: ``recover`` holds O, F and R whole (R at
F's depth) and one tile's working set in RGBA float beside them, and that peak is counted
against the same limit before decoding (``aarecovery.memory.check_pair_files``; a 1.6 GB
40000 x 40000 grey pair peaked at 5 GB). A 20000 x 20000 RGB 8-bit pair (1.2 GB per image,
3.8 GB at its peak) passes; the 40000 x 40000 RGB bomb (4.8 GB once decoded, from a 1.5 MB
PNG or a 1.2 MB GIF) is refused before decoding. A pair of tiled TIFFs that streams holds
only tiles, but each image's declared size is held to the limit all the same, so that a
small file cannot claim days of work (``aarecovery.stream.open_pair``).
"""

import math
import os

import numpy as np

from ..errors import InputError

__all__ = ["DEFAULT_MAX_BYTES", "ENVIRONMENT_VARIABLE", "max_bytes_from", "check_decoded_size", "format_bytes",
           "DECLARED_ONLY", "Declared", "raise_the_limit"]

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


#: A `max_bytes` that makes :func:`check_decoded_size` raise :class:`Declared` with what the
#: file declares: every reader calls it from the header, before decoding, so that
#: ``aarecovery.io.read.declared_image`` learns a file's size without a second header parser.
DECLARED_ONLY = object()


class Declared(BaseException):
    """What a file declares (``shape``, ``dtype``), raised past every reader's error handling.

    A BaseException: the readers turn any ``Exception`` met while decoding into their
    "could not decode" message.
    """

    def __init__(self, shape, dtype):
        super().__init__(shape, dtype)
        self.shape, self.dtype = tuple(int(side) for side in shape), np.dtype(dtype)


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
    if max_bytes is DECLARED_ONLY:
        raise Declared(shape, dtype)
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
        f"that claims this much is a decompression bomb); {raise_the_limit(needed)}")


def raise_the_limit(needed):
    """The end of a refusal by the limit: how to raise it to `needed` bytes."""
    return (f"if it is genuine, raise the limit: --max-image-memory {math.ceil(needed / 1e8) / 10:g} on the "
            f"command line, max_bytes= in read_image and recover_many, or {ENVIRONMENT_VARIABLE} (GB)")
