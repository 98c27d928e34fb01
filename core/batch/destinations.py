"""Where a batch writes, checked before any image is read: nothing over an input, nothing twice.

A batch writes results under the output folder, and, when asked, each filtered image it
makes (keep-filtered) and each image's maps in folders of their own, and a report. Each of
these files is compared with every input of the batch and with every other destination, by
:func:`aarecovery.io.destinations.file_identity` (the check ``recover`` makes for one pair),
and every folder is tried for writability, so that a batch never replaces an original and
never fails after its first write for a folder it could have checked.
"""

import os

from ..errors import InputError
from ..io.destinations import check_writable_folders, file_identity
from . import storage
from .work import destinations

__all__ = ["check_batch_destinations"]

_FOLDER_ROLES = {"keep_filtered": "the keep-filtered folder", "maps": "the maps folder"}


def _is_local(path):
    return isinstance(path, (str, os.PathLike)) and not storage.is_url(os.fspath(path))


def _real(folder):
    return os.path.realpath(os.fspath(folder))


def _inside(path, folder):
    """True when the real `path` is `folder` or below it (both real paths)."""
    return path == folder or path.startswith(folder.rstrip(os.sep) + os.sep)


def check_batch_destinations(jobs, settings, *, report=None, sources=()):
    """Refuse a batch whose destinations would replace an input or each other, or cannot be written.

    Parameters
    ----------
    jobs : list of Job
    settings : Settings
    report : str, optional
        The report file.
    sources : iterable of str
        The folders the batch's images were found in (a folder, or a glob's fixed part): a
        keep-filtered or maps folder inside one would be read as input by the next run.

    Raises
    ------
    InputError
        Naming the destination and what it would replace; results may replace their
        inputs with ``overwrite`` (as ``recover --overwrite``), nothing else may.
    """
    inputs = {}
    for job in jobs:
        for role, path in (("original", job.original), ("filtered", job.filtered)):
            if _is_local(path):
                inputs.setdefault(file_identity(path), (role, os.fspath(path)))
    _check_folders(settings, [_real(path) for _, path in inputs.values()], [_real(source) for source in sources])
    written = {}
    for job in jobs:
        for role, path in destinations(job, settings):
            if not _is_local(path):
                continue
            _check_one(role, path, inputs, written, settings.overwrite)
    if report is not None:
        _check_one("report", report, inputs, written, False)
    folders = [settings.keep_filtered, settings.maps, settings.output, report and os.path.dirname(
        os.path.abspath(report))]
    check_writable_folders([folder for folder in folders if folder is not None and _is_local(folder)])


def _check_one(role, path, inputs, written, overwrite):
    identity = file_identity(path)
    if identity in inputs and not (role == "result" and overwrite):
        input_role, source = inputs[identity]
        advice = "choose another output folder, or pass --overwrite" if role == "result" else \
            "choose a folder of its own"
        raise InputError(f"the {role} {path} would replace the {input_role} image {source}; {advice}")
    if identity in written:
        other_role, other = written[identity]
        raise InputError(f"the {role} {path} and the {other_role} {other} are both the same file; one would "
                         "replace the other: choose separate folders (or no --format that gives two images one "
                         "name)")
    written[identity] = (role, path)


def _check_folders(settings, inputs, sources):
    """A keep-filtered or maps folder is a folder of its own: not the output folder, not one
    holding the batch's inputs, not one inside a folder the batch reads."""
    output = _real(settings.output) if _is_local(settings.output) else None
    seen = {}
    for name, role in _FOLDER_ROLES.items():
        folder = getattr(settings, name)
        if folder is None:
            continue
        real = _real(folder)
        if real == output:
            raise InputError(f"{role} {folder} is the output folder; its files would mix with (or replace) "
                             "the results: choose a folder of its own")
        if real in seen:
            raise InputError(f"{role} {folder} is also {seen[real]}; choose a folder of its own for each")
        seen[real] = role
        holding = next((path for path in inputs if _inside(path, real)), None)
        if holding is not None:
            raise InputError(f"{role} {folder} holds images the batch reads ({holding}); writing there could "
                             "replace them: choose a folder of its own")
        source = next((source for source in sources if _inside(real, source)), None)
        if source is not None:
            raise InputError(f"{role} {folder} is inside {source}, which the batch reads its images from: the "
                             "next run would take its files as inputs; choose a folder outside it")
