"""``aarecovery.recover_many``: the batch from Python, with the command line's progress callback."""

import os
import time

import numpy as np

from ..errors import InputError
from ..params import (DEFAULT_MODE, ITERATIONS, SIGMA_D, SIGMA_E, STRENGTH, Parameters, check_backend,
                      check_blend_space, check_gl_path, check_mode)
from ..tiling import check_tile_size
from . import storage
from .destinations import check_batch_destinations
from .filtering import BuiltinFilter, FilterCommand
from .jobs import Job, output_name
from .local import run_local
from .work import Settings

__all__ = ["recover_many", "run_jobs", "make_jobs", "make_settings"]


def _name_of(index, original, filtered):
    for item in (filtered, original):
        if isinstance(item, (str, os.PathLike)):
            return os.path.basename(os.fspath(item))
    return f"{index:05d}.png"


def make_jobs(pairs, makes_filtered):
    """Jobs from ``(original, filtered[, name])`` tuples, or from originals when the batch filters.

    Raises
    ------
    InputError
        On an item of the wrong shape, or two images with the same name (one result would
        replace the other).
    """
    jobs, seen = [], {}
    for index, item in enumerate(pairs):
        if isinstance(item, Job):
            job = item
        else:
            if makes_filtered and (isinstance(item, (str, os.PathLike, np.ndarray))):
                item = (item, None)
            if not isinstance(item, (tuple, list)) or len(item) not in (2, 3):
                raise InputError(f"item {index} of pairs is {type(item).__name__}; give (original, filtered) or "
                                 "(original, filtered, name) tuples of paths or arrays"
                                 + (", or originals alone with a filter" if makes_filtered else ""))
            original, filtered = (os.fspath(x) if isinstance(x, os.PathLike) else x for x in item[:2])
            if filtered is None and not makes_filtered:
                raise InputError(f"item {index} of pairs has no filtered image; give one, or a filter or "
                                 "filter_command that makes it")
            name = item[2] if len(item) == 3 else _name_of(index, original, filtered)
            job = Job(str(name).replace(os.sep, "/"), original, filtered)
        if job.name in seen:
            raise InputError(f"two images of the batch are both named {job.name!r} (items {seen[job.name]} and "
                             f"{index}); their results would overwrite each other: give each a name")
        seen[job.name] = index
        jobs.append(job)
    return jobs


def make_settings(*, output=None, filter=None, filter_params=None, filter_command=None, filter_timeout=None,
                  keep_filtered=None, maps=None, format=None, force=False, overwrite=False, sigma_d=SIGMA_D.default,
                  sigma_e=SIGMA_E.default, iterations=ITERATIONS.default, backend="auto", linear=False,
                  blend_space=None, tile_size=None, mode=DEFAULT_MODE, strength=STRENGTH.default, gl_path="auto",
                  max_bytes=None):
    """Check the options of a batch and return its :class:`Settings` (see :func:`recover_many`)."""
    parameters = Parameters(sigma_d, sigma_e, iterations, strength)
    check_mode(mode)
    check_backend(backend)
    check_gl_path(gl_path)
    if blend_space is not None:
        check_blend_space(blend_space)
    if tile_size is not None:
        tile_size = check_tile_size(tile_size, parameters.iterations)
    if filter is not None and filter_command is not None:
        raise InputError("give a built-in filter or a filter command, not both")
    maker = None
    if filter is not None:
        maker = BuiltinFilter(filter, dict(filter_params or {}))
    elif filter_command is not None:
        maker = FilterCommand(filter_command, filter_timeout)
    elif filter_params:
        raise InputError("filter_params were given without a filter")
    if format is not None:
        format = "." + format.lower().lstrip(".")
        output_name("x" + format)
    for role, folder in (("output", output), ("keep_filtered", keep_filtered), ("maps", maps)):
        if folder is not None and os.path.exists(folder) and not os.path.isdir(folder):
            raise InputError(f"{role} {folder} is a file; give a folder")
    for role, folder in (("keep_filtered", keep_filtered), ("maps", maps)):
        if storage.is_url(folder):
            raise InputError(f"{role} {folder} is a URL; {role} must be a local folder (only the images and the "
                             "results may be URLs)")
    if output is None and (keep_filtered is not None or maps is not None):
        raise InputError("keep_filtered and maps need an output folder; give output=")
    if max_bytes is not None and not max_bytes > 0:
        raise InputError(f"max_bytes must be a positive number of bytes, got {max_bytes!r}")
    return Settings(parameters=parameters, mode=mode, linear=bool(linear), blend_space=blend_space, backend=backend,
                    gl_path=gl_path, tile_size=tile_size, output=None if output is None else os.fspath(output), format=format,
                    filter=maker, keep_filtered=keep_filtered, maps=maps, force=bool(force),
                    overwrite=bool(overwrite), max_bytes=max_bytes)


def recover_many(pairs, output=None, *, filter=None, filter_params=None, filter_command=None, filter_timeout=None,
                 keep_filtered=None, maps=None, format=None, force=False, overwrite=False, workers=None,
                 progress=None, dask=None, sigma_d=SIGMA_D.default, sigma_e=SIGMA_E.default,
                 iterations=ITERATIONS.default, backend="auto", linear=False, blend_space=None, tile_size=None,
                 mode=DEFAULT_MODE, strength=STRENGTH.default, gl_path="auto", max_bytes=None, engine=None):
    """Recover many image pairs with one engine, or on a Dask cluster.

    A failing image (a bad file, a failing filter command) does not stop the others: its
    result says why. Written results keep the images' relative names and formats, are
    written atomically, and a re-run skips those that are complete and newer than their
    inputs (``force=True`` redoes them).

    Parameters
    ----------
    pairs : iterable
        ``(original, filtered)`` or ``(original, filtered, name)`` tuples, each image a path
        or an array (as :func:`aarecovery.recover` takes); with `filter` or
        `filter_command`, originals alone. `name` is the result's path relative to
        `output` (default: the filtered file's name, else the original's, else
        ``NNNNN.png``).
    output : str or os.PathLike, optional
        The folder to write results into (created as needed). Without it the results are
        returned as arrays (``ImageResult.image``), and nothing is written.
    filter : str, optional
        A built-in filter (``aarecovery.filters.FILTERS``) that makes F from O, with
        `filter_params`.
    filter_command : str, optional
        A command-line tool that makes F from O, a template with ``{in}`` and ``{out}``:
        ``"convert {in} -threshold 50% {out}"``. It runs on a temporary copy of O;
        `filter_timeout` seconds stop it.
    keep_filtered : str, optional
        A folder to keep each F in (when the batch makes F).
    maps : str, optional
        A folder for each image's maps (``aarecovery recover --maps``); pairs are then read
        whole, not streamed.
    format : str, optional
        ``"png"``, ``"tif"``...: every result in this format instead of F's own.
    force, overwrite : bool
        Redo up-to-date results; allow a result to replace one of its inputs.
    workers : int, optional
        Processes for the safe analysis, and one more thread for reading, filtering and
        writing (default: a measured rule, ``aarecovery.batch.default_workers``).
    progress : callable, optional
        ``progress(result, done, total)`` after each image (the command line's bar).
    dask : str or distributed.Client, optional
        Run on a Dask cluster instead: a scheduler address (``"tcp://host:8786"``),
        ``"local"`` for a ``LocalCluster`` on this machine, or a ``Client``. Paths must then
        be on storage every worker sees (local paths or fsspec URLs), and `output` given.
    sigma_d, sigma_e, iterations, backend, linear, blend_space, tile_size, mode, strength, gl_path
        As for :func:`aarecovery.recover`, for every image.
    max_bytes : int or float, optional
        The largest decoded size of one image, as for :func:`aarecovery.read_image` (default
        4 GB, or ``AARECOVERY_MAX_IMAGE_MEMORY``), and of a recovery's peak for a pair read
        whole; a streamed TIFF pair holds only tiles, but each image's declared size is
        bound by it too.
    engine : Engine, optional
        An engine to use (not with `dask`).

    Returns
    -------
    list of ImageResult
        One per pair, in order: ``status`` (``"done"``, ``"skipped"``, ``"failed"``),
        ``error``, ``output``, the plan (``mode``, ``blend_space``, ``strength``,
        ``decision``, ``reason``), ``backend``, ``seconds``, and ``image`` without `output`.

    Examples
    --------
    >>> results = aarecovery.recover_many([("o.png", "f.png")], "repaired/")   # doctest: +SKIP
    >>> [r.status for r in results]                                            # doctest: +SKIP
    ['done']
    """
    settings = make_settings(output=output, filter=filter, filter_params=filter_params, filter_command=filter_command,
                             filter_timeout=filter_timeout, keep_filtered=keep_filtered, maps=maps, format=format,
                             force=force, overwrite=overwrite, sigma_d=sigma_d, sigma_e=sigma_e,
                             iterations=iterations, backend=backend, linear=linear, blend_space=blend_space,
                             tile_size=tile_size, mode=mode, strength=strength, gl_path=gl_path,
                             max_bytes=max_bytes)
    jobs = make_jobs(pairs, settings.filter is not None)
    check_batch_destinations(jobs, settings)
    return run_jobs(jobs, settings, workers=workers, progress=progress, dask=dask, engine=engine)


def run_jobs(jobs, settings, *, workers=None, progress=None, dask=None, engine=None):
    """Run checked jobs locally or on Dask; ``progress(result, done, total)`` after each."""
    total, done = len(jobs), [0]

    def report(result):
        done[0] += 1
        if progress is not None:
            progress(result, done[0], total)

    started = time.time()
    if dask is not None:
        if engine is not None:
            raise InputError("an engine cannot be sent to a Dask cluster; each worker makes its own")
        if settings.output is None:
            raise InputError("a batch on Dask writes its results: give an output folder (or URL)")
        from .distributed import run_dask
        return run_dask(jobs, settings, dask, progress=report, started=started)
    if not jobs:
        return []
    own_engine = engine is None
    if own_engine:
        from ..engine import Engine
        engine = Engine(settings.backend, gl_path=settings.gl_path)
    try:
        return run_local(jobs, settings, engine, workers=workers, progress=report, started=started)
    finally:
        if own_engine:
            engine.release()
