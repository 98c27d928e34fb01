"""How commands read images: the memory limit option, and what a size mismatch may mean."""

import argparse

from ..contract import check_same_size, layout_of
from ..errors import InputError
from ..io import DEFAULT_MAX_BYTES, describe_orientations, read_image, warn_if_orientations_differ

__all__ = ["add_image_memory_option", "memory_limit", "read_input", "check_pair_size"]


def _gigabytes(text):
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not value > 0 or value == float("inf"):
        # argparse shows an ArgumentTypeError's own words; any other error as "invalid _gigabytes value".
        raise argparse.ArgumentTypeError(f"a positive number of GB is needed, such as 8; got {text!r}")
    return value


def add_image_memory_option(parser):
    """``--max-image-memory GB``: raise (or lower) the decompression-bomb limit of every read."""
    parser.add_argument("--max-image-memory", type=_gigabytes, metavar="GB",
                        help="largest decoded size of one image, and of a recovery's peak (O, F, R and a "
                             "tile), checked from the files' headers before decoding (default "
                             f"{DEFAULT_MAX_BYTES / 1e9:g} GB; larger files are refused as possible decompression "
                             "bombs)")


def memory_limit(args):
    """The command's ``--max-image-memory`` in bytes, or None for the default."""
    limit = getattr(args, "max_image_memory", None)
    return None if limit is None else limit * 1e9


def read_input(path, args):
    """:func:`aarecovery.read_image` with the command's ``--max-image-memory``."""
    return read_image(path, max_bytes=memory_limit(args))


def check_pair_size(original, filtered, paths):
    """Refuse a pair of different sizes, saying so when the files declare different
    orientations; warn when the sizes match but the orientations differ.

    Every reader turns pixels upright by the orientation the file declares; a program that
    dropped the tag without turning the pixels leaves a pair that no longer matches.
    """
    try:
        check_same_size(layout_of(original, "original"), layout_of(filtered, "filtered"))
    except InputError as error:
        described = describe_orientations(paths)
        if described is None:
            raise
        raise InputError(f"{error}. The files' orientation tags differ: {described}; each is shown upright "
                         "as tagged, so the program that wrote one of them may have dropped or changed the "
                         "tag without turning its pixels") from None
    warn_if_orientations_differ(*paths)
