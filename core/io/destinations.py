"""Where a command may write: never over its own inputs, and only where every write can succeed.

Every command that writes files (``recover``, ``filter``, ``batch``, ``recover_many``) checks
all of its destinations here before it reads or computes anything, so that a run never ends
in a refusal after part of its output was written.
"""

import os

from ..errors import InputError
from .write import check_output_path, check_writable_folder

__all__ = ["check_destinations", "check_writable_folders", "same_file", "file_identity"]


def file_identity(path):
    """What names one file whatever the path: device and inode when it exists, else the real path.

    Two paths with the same identity are the same file (through links, ``..`` or hard links).
    """
    try:
        status = os.stat(path)
    except OSError:
        return os.path.realpath(path)
    return (status.st_dev, status.st_ino)


def same_file(first, second):
    """True when two paths name the same file (through links, ``..`` or hard links)."""
    return file_identity(first) == file_identity(second)


def check_destinations(outputs, inputs, *, overwrite=False, folders=()):
    """Refuse outputs that would replace an input, and destinations that cannot be written.

    Parameters
    ----------
    outputs : list of str
        The image files the command will write.
    inputs : dict
        ``{role: path}`` of the images the command reads (``"original"``, ``"filtered"``...).
    overwrite : bool
        The user's ``--overwrite``: an output may then replace an input.
    folders : iterable of str
        Folders the command creates if missing (``--maps DIR``); their nearest existing
        ancestor must be writable.

    Raises
    ------
    InputError
        Naming the output and the input it would replace (and ``--overwrite``), an unknown
        extension, a missing folder, or a folder that cannot be written.
    """
    for output in outputs:
        for role, source in inputs.items():
            if not overwrite and same_file(output, source):
                raise InputError(f"output {output} is the {role} image {source}; choose another output "
                                 "name, or pass --overwrite to replace it")
    created = [os.path.abspath(folder) for folder in folders]
    for output in outputs:
        if not any(os.path.abspath(output).startswith(folder + os.sep) for folder in created):
            check_output_path(output)
    check_writable_folders([os.path.dirname(os.path.abspath(output)) for output in outputs] + created)


def check_writable_folders(folders):
    """Raise unless a file can be created in each folder, or in its nearest existing ancestor
    (where a missing folder will be made)."""
    checked = set()
    for folder in folders:
        folder = os.path.abspath(folder)
        existing = folder
        while not os.path.exists(existing):
            existing = os.path.dirname(existing)
        if not os.path.isdir(existing):
            raise InputError(f"{existing} is a file, so the folder {folder} cannot be made; choose another folder")
        if existing not in checked:
            checked.add(existing)
            check_writable_folder(existing)
