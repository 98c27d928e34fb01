"""Saving R: where by default, and when to ask before replacing a file."""

import os

import aarecovery

__all__ = ["default_output_path", "overwrite_question", "save_result"]


def default_output_path(source):
    """``<filtered>-recovered.png`` next to F (or next to O when F came from a filter)."""
    if source.filtered:
        stem = os.path.splitext(source.filtered)[0]
    else:
        stem = f"{os.path.splitext(source.original)[0]}-{source.filter_name}"
    return f"{stem}-recovered.png"


def _same_file(a, b):
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.abspath(a) == os.path.abspath(b)


def overwrite_question(path, source):
    """The question to ask before writing `path`, or None when nothing would be replaced.

    Parameters
    ----------
    path : str
        Where R would be written.
    source : PairSource or None
        The shown pair; replacing one of its inputs gets a sterner question.
    """
    if not os.path.lexists(path):
        return None
    inputs = source.input_paths if source is not None else []
    for role, input_path in zip(("ORIGINAL", "FILTERED"), inputs):
        if _same_file(path, input_path):
            return (f"{path} is the {role} input image. Replace it with the result? "
                    "The input is lost.")
    return f"{path} exists. Replace it?"


def save_result(engine, path, overwrite=False):
    """Write the engine's R to `path` atomically, in F's layout and bit depth.

    Raises
    ------
    aarecovery.InputError
        Where `path` exists and `overwrite` is False, or the format cannot hold R.
    OSError
        When the disk refuses the write.
    """
    aarecovery.write_image(path, engine.result(), overwrite=overwrite)
