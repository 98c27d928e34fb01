"""How to add an optional extra (``viewer``, ``eval``) to aarecovery as it was installed here.

``pip install 'aarecovery[viewer]'`` only works where aarecovery came from PyPI. An install
from a checkout records where it came from (``direct_url.json``, PEP 610), and the command
that works there names that folder; the pip is the one beside this Python, so that it installs
into the same environment (``.venv/bin/pip``, as the README's set-up makes it).
"""

import json
import os
import sys
from urllib.parse import unquote, urlparse

__all__ = ["install_command", "missing_extra", "extra_for"]

#: The optional packages and the extra that installs each (pyproject.toml).
EXTRA_OF_MODULE = {"glfw": "viewer", "imgui_bundle": "viewer", "matplotlib": "eval"}


def _pip():
    pip = os.path.join(os.path.dirname(sys.executable), "pip")
    if os.path.exists(pip):
        relative = os.path.relpath(pip)
        return relative if not relative.startswith("..") else pip
    return f"{sys.executable} -m pip"


def _source():
    """``(folder, editable)`` when aarecovery was installed from a local folder, else None."""
    # Imported here, not with the module: importlib.metadata (with the email package) took
    # 34 ms of every command's start, which needs it only to word a missing extra's fix.
    from importlib import metadata
    try:
        text = metadata.distribution("aarecovery").read_text("direct_url.json")
    except metadata.PackageNotFoundError:
        text = None
    if not text:
        return None
    try:
        origin = json.loads(text)
    except ValueError:
        return None
    url = urlparse(origin.get("url", ""))
    if url.scheme != "file" or "dir_info" not in origin:
        return None
    folder = unquote(url.path)
    relative = os.path.relpath(folder)
    return (relative if not relative.startswith("..") else folder), bool(origin["dir_info"].get("editable"))


def _requirements(extra):
    """The extra's own requirements, as the installed metadata lists them."""
    from importlib import metadata
    marker = f'extra == "{extra}"'
    found = []
    for requirement in metadata.distribution("aarecovery").requires or ():
        if marker in requirement:
            found.append(requirement.split(";")[0].strip())
    return found


def install_command(extra):
    """The command that adds `extra` to this installation, e.g. ``.venv/bin/pip install '.[viewer]'``.

    From a folder (a checkout): that folder with the extra. From PyPI (no record of a
    source): ``aarecovery[extra]``. From a wheel or an archive, which pip cannot add an extra
    to by name: the extra's packages themselves.
    """
    from importlib import metadata
    source = _source()
    if source is not None:
        folder, editable = source
        return f"{_pip()} install {'-e ' if editable else ''}'{folder}[{extra}]'"
    try:
        recorded = metadata.distribution("aarecovery").read_text("direct_url.json")
        requirements = _requirements(extra) if recorded else []
    except metadata.PackageNotFoundError:
        requirements = []
    if requirements:
        return f"{_pip()} install " + " ".join(f"'{requirement}'" for requirement in requirements)
    return f"{_pip()} install 'aarecovery[{extra}]'"


def missing_extra(command, extra, error):
    """One line for a command whose optional packages are missing."""
    return (f"{command} needs the {extra} extra ({error}); install it with: {install_command(extra)}")


def extra_for(error):
    """The extra whose package an ImportError is about, or None when it is not an extra's."""
    name = (getattr(error, "name", None) or "").split(".")[0]
    return EXTRA_OF_MODULE.get(name)
