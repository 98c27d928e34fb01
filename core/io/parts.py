"""The temporary ``.part`` files that :func:`aarecovery.write_image` writes before renaming.

A part is named ``.NAME.XXXXXXXX.part.EXT`` beside its destination ``NAME.EXT`` (``XXXXXXXX``
is :func:`tempfile.mkstemp`'s random text) and stays locked (``flock``) by its writer from
the moment it exists until it is renamed or removed. Signals that Python can catch remove
the part (the command line turns SIGTERM and SIGHUP into an interruption); SIGKILL, a power
cut or a crash cannot, so :func:`remove_stale_parts` removes the parts whose writer is gone:
the lock is free exactly then, since the kernel drops a process's locks when it dies.
"""

import os
import re
import stat
import tempfile
import time

try:
    import fcntl
except ImportError:  # Windows: no flock; only the age tells a stale part there
    fcntl = None

__all__ = ["create_part", "remove_stale_parts", "is_part_name"]

_PART = re.compile(r"^\.(?P<name>.+)\.[a-z0-9_]{8}\.part(?P<extension>\.[A-Za-z0-9]+)$")
# An empty part younger than this is left alone even when unlocked: its writer may sit
# between creating it and locking it (two system calls apart). A part with bytes in it was
# locked before its first byte, so its free lock means that its writer is gone, at any age.
_MIN_AGE_SECONDS = 60.0
# Where locks cannot be taken (Windows, some network file systems), only the age can tell:
# no single image write takes a day.
_UNLOCKED_STALE_AGE_SECONDS = 24 * 3600.0


def is_part_name(filename, name=None, extension=None):
    """True when `filename` is a part that :func:`create_part` names (for `name` and `extension`)."""
    match = _PART.match(filename)
    return bool(match) and (name is None or match["name"] == name) and (
        extension is None or match["extension"] == extension)


def create_part(folder, name, extension):
    """Create and lock the part for ``NAME.EXT`` in `folder`.

    Returns
    -------
    descriptor : int
        An open descriptor that holds the lock; close it after the part was renamed or removed.
    path : str
    """
    descriptor, path = tempfile.mkstemp(dir=folder, prefix=f".{name}.", suffix=".part" + extension)
    if fcntl is not None:
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            pass  # a file system without locks: remove_stale_parts then goes by age
    return descriptor, path


def _writer_is_gone(path, age):
    """Take the part's lock if its writer is gone; return the descriptor that holds it, or None."""
    try:
        descriptor = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    except OSError:
        return None
    if fcntl is None:
        if age >= _UNLOCKED_STALE_AGE_SECONDS:
            return descriptor
        os.close(descriptor)
        return None
    try:
        fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
        return descriptor
    except BlockingIOError:
        pass  # its writer still holds it
    except OSError:
        if age >= _UNLOCKED_STALE_AGE_SECONDS:
            return descriptor
    os.close(descriptor)
    return None


def remove_stale_parts(folder, name=None, extension=None):
    """Remove the parts in `folder` that an interrupted write left behind.

    Only files named as :func:`create_part` names them are considered, and of those only the
    ones that no living writer holds (their lock is free) and that hold bytes or are at least
    a minute old (an empty one may be between its creation and its lock); where locks are not
    available, only those older than a day.

    Parameters
    ----------
    folder : str or os.PathLike
    name, extension : str, optional
        Only the parts of ``NAME.EXT`` (``extension`` with its dot), as a command does for
        its own outputs; by default every part in the folder, as a batch run does.

    Returns
    -------
    list of str
        The paths removed.
    """
    folder = os.fspath(folder)
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    now = time.time()
    for entry in entries:
        if not is_part_name(entry.name, name, extension):
            continue
        try:
            info = entry.stat(follow_symlinks=False)
        except OSError:
            continue
        age = now - info.st_mtime
        if not stat.S_ISREG(info.st_mode) or (info.st_size == 0 and age < _MIN_AGE_SECONDS):
            continue
        descriptor = _writer_is_gone(entry.path, age)
        if descriptor is None:
            continue
        try:
            os.unlink(entry.path)
            removed.append(entry.path)
        except OSError:
            pass
        finally:
            os.close(descriptor)
    return removed
