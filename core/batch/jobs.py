"""What a batch does, image by image: which files pair up, and where each result goes.

Pairs are matched by relative path (two folders) or by what the wildcards of two globs
match (``'scans/*.png' 'bw/*-bw.png'`` pairs ``scans/a.png`` with ``bw/a-bw.png``). A result
keeps the relative path and the format of the filtered image (of the original where the
batch makes F itself), unless a format is asked for.
"""

import glob
import os
import re
from dataclasses import dataclass

from ..errors import InputError
from ..io.formats import WRITE_FORMATS
from . import storage

__all__ = ["Job", "IMAGE_EXTENSIONS", "find_pairs", "find_images", "output_name", "source_folder"]

#: Files a folder contributes to a batch, by extension (what ``read_image`` reads).
IMAGE_EXTENSIONS = (".png", ".tif", ".tiff", ".jpg", ".jpeg", ".webp", ".bmp", ".gif", ".npy")


@dataclass(frozen=True)
class Job:
    """One image of a batch.

    Attributes
    ----------
    name : str
        Its relative path (``/``-separated): where the result goes under the output folder,
        and how reports and messages name it.
    original : str or ndarray
        O, a file or an array.
    filtered : str or ndarray or None
        F, a file or an array; None when the batch's filter makes it from O.
    """

    name: str
    original: object
    filtered: object = None


def _is_glob(text):
    return glob.has_magic(text)


def _relative(path, root):
    return os.path.relpath(path, root).replace(os.sep, "/")


def _is_image(name):
    return not name.rsplit("/", 1)[-1].startswith(".") and os.path.splitext(name)[1].lower() in IMAGE_EXTENSIONS


def _folder_images(folder):
    if storage.is_url(folder):
        return {name: url for name, url in sorted(storage.listing(folder).items()) if _is_image(name)}
    found = {}
    for directory, subfolders, files in os.walk(folder):
        subfolders[:] = sorted(name for name in subfolders if not name.startswith("."))
        for name in sorted(files):
            # Hidden files include the temporary files of interrupted writes (".name.XXXX.part.png").
            if _is_image(name):
                path = os.path.join(directory, name)
                found[_relative(path, folder)] = path
    return found


def _glob_root(pattern):
    parts = pattern.replace(os.sep, "/").split("/")
    fixed = []
    for part in parts[:-1]:
        if _is_glob(part):
            break
        fixed.append(part)
    return "/".join(fixed) or "."


def _wildcard_regex(pattern):
    """A regex for `pattern` (glob syntax, ``/``-separated) with one group per wildcard."""
    parts, index = [], 0
    while index < len(pattern):
        char = pattern[index]
        if pattern.startswith("**/", index):
            parts.append("((?:.*/)?)")
            index += 3
            continue
        if char == "*":
            parts.append("(.*)" if pattern.startswith("**", index) else "([^/]*)")
            index += 2 if pattern.startswith("**", index) else 1
            continue
        if char == "?":
            parts.append("([^/])")
        elif char == "[" and "]" in pattern[index + 2:]:
            end = pattern.index("]", index + 2)
            members = pattern[index + 1:end]
            parts.append("([" + ("^" + members[1:] if members.startswith("!") else members).replace("\\", "\\\\")
                         + "])")
            index = end + 1
            continue
        else:
            parts.append(re.escape(char))
        index += 1
    return re.compile("".join(parts) + r"\Z", re.S)


def _glob_images(pattern):
    """``{key: (relative name, path)}``: the key is what the wildcards matched."""
    root = _glob_root(pattern)
    regex = _wildcard_regex(pattern.replace(os.sep, "/"))
    if storage.is_url(pattern):
        paths = sorted(storage.listing(pattern).values())
    else:
        paths = [path for path in sorted(glob.glob(pattern, recursive=True)) if os.path.isfile(path)]
    found = {}
    for path in paths:
        if _is_image(path.replace(os.sep, "/")):
            match = regex.match(path.replace(os.sep, "/"))
            key = match.groups() if match else (path,)
            name = path[len(root):].lstrip("/") if storage.is_url(path) else _relative(path, root)
            found[key] = (name, path)
    return found


def source_folder(source):
    """The folder a batch source reads images from: the folder itself, or a glob's fixed part."""
    return _glob_root(source) if _is_glob(source) else source


def find_images(source):
    """The images of a folder (recursively, hidden files skipped) or of a glob; either may be
    an fsspec URL (``s3://bucket/scans/``).

    Returns
    -------
    list of (str, str)
        ``(relative name, path)``, sorted by name.

    Raises
    ------
    InputError
        When `source` is neither an existing folder nor a glob that matches an image.
    """
    if _is_glob(source):
        found = sorted(_glob_images(source).values())
        if not found:
            raise InputError(f"no image files match {source!r}; check the pattern (quote it so that the shell "
                             f"does not expand it) and the extensions ({', '.join(IMAGE_EXTENSIONS)})")
        return found
    if not storage.is_url(source) and not os.path.isdir(source):
        raise InputError(f"{source} is not a folder or a glob pattern; give a folder of images or a pattern "
                         "such as 'scans/*.png'")
    found = sorted(_folder_images(source).items())
    if not found:
        raise InputError(f"{source} holds no image files ({', '.join(IMAGE_EXTENSIONS)})")
    return found


def find_pairs(originals, filtered):
    """Pair the images of two folders by relative path, or of two globs by their wildcards.

    Within folders a filtered image may also have another extension than its original
    (``a.png`` with ``a.tif``) when that leaves no doubt.

    Returns
    -------
    pairs : list of Job
        Named after the filtered image's relative path.
    unmatched : list of str
        Originals without a filtered image (each is reported as a failure of the batch).

    Raises
    ------
    InputError
        On a source that is neither a folder nor a glob, or a folder paired with a glob.
    """
    if _is_glob(originals) != _is_glob(filtered):
        raise InputError(f"give two folders or two glob patterns, not one of each ({originals!r}, {filtered!r})")
    if _is_glob(originals):
        left, right = _glob_images(originals), _glob_images(filtered)
        if not left:
            raise InputError(f"no image files match {originals!r}; check the pattern (quote it)")
        jobs, unmatched = [], []
        for key, (name, path) in sorted(left.items(), key=lambda item: item[1]):
            if key in right:
                jobs.append(Job(right[key][0], path, right[key][1]))
            else:
                unmatched.append(path)
        return jobs, unmatched
    left = dict(find_images(originals))
    if not storage.is_url(filtered) and not os.path.isdir(filtered):
        raise InputError(f"{filtered} is not a folder; give the folder that holds the filtered images")
    right = _folder_images(filtered)
    by_stem = {}
    for name in right:
        by_stem.setdefault(os.path.splitext(name)[0], []).append(name)
    jobs, unmatched = [], []
    for name, path in left.items():
        candidates = [name] if name in right else by_stem.get(os.path.splitext(name)[0], [])
        if len(candidates) == 1:
            jobs.append(Job(candidates[0], path, right[candidates[0]]))
        else:
            unmatched.append(path)
    return jobs, unmatched


def output_name(name, extension=None):
    """The result's relative path: `name` with `extension` (``".png"``), if given, instead of its own.

    Raises
    ------
    InputError
        When the format cannot be written (a GIF input without a chosen format).
    """
    stem, own = os.path.splitext(name)
    chosen = (extension or own).lower()
    if not chosen.startswith("."):
        chosen = "." + chosen
    if chosen not in WRITE_FORMATS:
        raise InputError(f"results cannot be written as {chosen} ({name}); choose a format with --format, one of "
                         f"{', '.join(sorted({e.lstrip('.') for e in WRITE_FORMATS}))}")
    return stem + (chosen if extension else own)
