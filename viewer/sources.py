"""Where the image pair comes from: two files, one file and a built-in filter, or the sample.

Everything here is NumPy and files; the app hands the arrays to the engine.
"""

import os
from dataclasses import dataclass, field
from importlib import resources

import numpy as np

import aarecovery

__all__ = ["PairSource", "LoadedPair", "load_pair", "sample_path", "sample_source", "filter_names",
           "filter_parameters", "SAMPLE_FILTER"]

#: The filter applied to the bundled sample when no FILTERED file is given.
SAMPLE_FILTER = "posterize"


def _filters():
    """The built-in filters module, or None in an install that lacks it."""
    try:
        from aarecovery import filters
    except ImportError:
        return None
    return filters


def filter_names():
    """Names of the built-in filters, in registry order (empty when there are none)."""
    filters = _filters()
    return list(filters.FILTERS) if filters is not None else []


def filter_parameters(name):
    """The numeric parameters of filter `name` that the viewer offers as widgets.

    Returns
    -------
    list of tuple
        ``(parameter name, default, help, is_int)``; parameters whose defaults are not plain
        numbers (a colour ramp, a precomputed curve) keep their defaults and are not listed.
    """
    filters = _filters()
    spec = filters.get_filter(name)
    return [(p.name, p.default, p.help, isinstance(p.default, int))
            for p in spec.parameters
            if isinstance(p.default, (int, float)) and not isinstance(p.default, bool)]


def sample_path():
    """Path of the bundled sample image (package data of ``aarecovery``), or None.

    ``data/sample.png`` is the demo's sample; installs without it fall back on the first
    bundled photo.
    """
    data = resources.files("aarecovery").joinpath("data")
    candidates = [data.joinpath("sample.png")]
    if data.is_dir():
        candidates += sorted((entry for entry in data.iterdir() if entry.name.startswith("photo_")),
                             key=lambda entry: entry.name)
    for candidate in candidates:
        if candidate.is_file():
            return os.fspath(candidate)
    return None


def sample_source():
    """The bundled sample and the sample filter, or None when the install has neither."""
    path = sample_path()
    if path is None or SAMPLE_FILTER not in filter_names():
        return None
    return PairSource(path, None, SAMPLE_FILTER, {})


@dataclass
class PairSource:
    """What to load: ORIGINAL plus either a FILTERED file or a built-in filter.

    Attributes
    ----------
    original : str
        Path of O.
    filtered : str or None
        Path of F, or None to make F with `filter_name`.
    filter_name : str or None
        A built-in filter (``aarecovery.filters``) applied to O when `filtered` is None.
    filter_params : dict
        That filter's parameters (defaults for the ones not given).
    """

    original: str
    filtered: str = None
    filter_name: str = None
    filter_params: dict = field(default_factory=dict)

    @property
    def input_paths(self):
        """The files this pair was read from."""
        return [path for path in (self.original, self.filtered) if path]

    def describe_filtered(self):
        """How F was obtained, for the status line."""
        if self.filtered:
            return os.path.basename(self.filtered)
        values = {name: default for name, default, _, _ in filter_parameters(self.filter_name)}
        values.update(self.filter_params)
        details = ", ".join(f"{key}={value:g}" if isinstance(value, float) else f"{key}={value}"
                            for key, value in values.items())
        return f"{self.filter_name} filter ({details})" if details else f"{self.filter_name} filter"


@dataclass
class LoadedPair:
    """An image pair read and checked, ready for ``Engine.set_images``.

    Attributes
    ----------
    source : PairSource
    original, filtered : ndarray
        As read (or as the filter returned): any layout and dtype the core accepts.
    quantization : list of list of int or None
        The quantization tables of O's file when it is a JPEG (``aarecovery.read_quantization``),
        so that the viewer's plan reads O's compression noise as ``aarecovery recover`` does
        for the same files, and shows the same R.
    """

    source: PairSource
    original: np.ndarray
    filtered: np.ndarray
    quantization: object = None

    @property
    def size(self):
        """``(width, height)``."""
        return self.filtered.shape[1], self.filtered.shape[0]


def load_pair(source):
    """Read the files of `source` (and run its filter) into a :class:`LoadedPair`.

    Raises
    ------
    aarecovery.InputError
        On an unreadable file, mismatched sizes, an unknown filter or a bad filter
        parameter; the message is meant for the user as it is.
    """
    original = aarecovery.read_image(source.original)
    if source.filtered:
        filtered = aarecovery.read_image(source.filtered)
        if filtered.shape[:2] != original.shape[:2]:
            raise aarecovery.InputError(
                f"{os.path.basename(source.original)} is {original.shape[1]}x{original.shape[0]} but "
                f"{os.path.basename(source.filtered)} is {filtered.shape[1]}x{filtered.shape[0]}; "
                "recovery needs the two images pixel for pixel, so give a filtered image of the same size")
    else:
        filters = _filters()
        if filters is None:
            raise aarecovery.InputError("this install has no built-in filters (aarecovery.filters); "
                                        "give a FILTERED image as well")
        filtered = filters.apply(source.filter_name, original, **source.filter_params)
    return LoadedPair(source, original, filtered, aarecovery.read_quantization(source.original))
