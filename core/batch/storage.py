"""Files a batch reads and writes: local paths, or fsspec URLs (``s3://``, ``gs://``, ``file://``).

The readers and writers of ``aarecovery.io`` take local files. An input given as a URL is
copied into the image's scratch folder first; a result for a URL is written locally, then
uploaded under a temporary name next to its destination and moved into place, so that no
half-written result ever appears there (on object stores the upload itself is atomic).
fsspec is needed only when a URL is given (``pip install 'aarecovery[dask]'`` brings it).
"""

import os
import uuid

from ..errors import InputError

__all__ = ["is_url", "filesystem", "fetch", "publish", "modified", "exists", "join", "listing"]


def is_url(path):
    """True for ``protocol://...`` strings other than plain local paths."""
    return isinstance(path, str) and "://" in path


def filesystem(url):
    """``(fs, path)`` for a URL; a clear error when fsspec or the protocol's package is missing."""
    try:
        import fsspec
    except ImportError:
        raise InputError(f"{url} is a URL, which needs fsspec: pip install 'aarecovery[dask]' (or fsspec and the "
                         "package of its protocol)") from None
    try:
        return fsspec.core.url_to_fs(url)
    except (ImportError, ValueError) as error:
        raise InputError(f"cannot open {url}: {error}") from None


def fetch(url, folder):
    """Copy the file at `url` into `folder`; return the local path (keeping the extension)."""
    fs, path = filesystem(url)
    local = os.path.join(folder, uuid.uuid4().hex + os.path.splitext(path)[1])
    try:
        fs.get_file(path, local)
    except FileNotFoundError:
        raise InputError(f"{url} does not exist; check the address") from None
    return local


def publish(local, url):
    """Upload the local file `local` to `url` atomically (temporary name beside it, then a move)."""
    fs, path = filesystem(url)
    folder, name = path.rsplit("/", 1) if "/" in path else ("", path)
    stem, extension = os.path.splitext(name)
    temporary = f"{folder}/.{stem}.{uuid.uuid4().hex[:8]}.part{extension}"
    fs.makedirs(folder, exist_ok=True)
    fs.put_file(local, temporary)
    try:
        fs.mv(temporary, path)
    except BaseException:
        fs.rm(temporary)
        raise


def modified(path):
    """Modification time (seconds) of a local path or URL, or None when it does not exist."""
    if not is_url(path):
        try:
            return os.stat(path).st_mtime
        except OSError:
            return None
    fs, inner = filesystem(path)
    try:
        return fs.modified(inner).timestamp()
    except FileNotFoundError:
        return None
    except (NotImplementedError, OSError, AttributeError):
        # A store without times: existing counts as up to date.
        return float("inf") if fs.exists(inner) else None


def exists(path):
    return modified(path) is not None


def join(folder, name):
    """`folder` / `name` (a ``/``-separated relative path), for local folders and URLs."""
    if is_url(folder):
        return folder.rstrip("/") + "/" + name
    return os.path.join(folder, *name.split("/"))


def listing(url):
    """The files under a URL folder, or matching a URL glob: ``{relative name: url}``."""
    fs, path = filesystem(url)
    if any(char in path for char in "*?["):
        root = path[:min(path.find(char) for char in "*?[" if char in path)].rsplit("/", 1)[0]
        found = fs.glob(path)
    else:
        root, found = path.rstrip("/"), fs.find(path)
    return {item[len(root):].lstrip("/"): fs.unstrip_protocol(item) for item in found
            if not item.rsplit("/", 1)[-1].startswith(".")}
