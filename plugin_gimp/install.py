"""Install, remove and inspect the GIMP 3 plug-in in a GIMP profile's plug-ins folder.

GIMP 3 loads a plug-in from ``plug-ins/NAME/NAME.py`` and only if that file is executable (it
skips a non-executable one without a word). The profile folders are in
:mod:`aarecovery.gimp.profiles`.

Next to the script, ``config.json`` records the Python that ran the installer (``python``).
GIMP runs the plug-in with its own Python; when that one cannot ``import aarecovery`` (GIMP's
Windows and macOS builds), the plug-in runs the core in the recorded Python instead. With a
bundle, ``site-packages`` next to the script holds the core and its compiled packages for
GIMP's Python, and ``config.json`` describes it (``bundle``; see
:func:`aarecovery.gimp.bundle.build`).

An install is staged in a hidden folder beside its destination and renamed into place only
when complete, so a failed download leaves any earlier installation as it was.
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import uuid
from importlib import resources
from pathlib import Path

from . import InstallError, bundle
from .profiles import gimp_dir

__all__ = ["PLUGIN_NAME", "BUNDLE_FOLDER", "plugin_source", "plugin_files", "stage", "install",
           "uninstall", "status"]

PLUGIN_NAME = "aarecovery-gimp"
BUNDLE_FOLDER = "site-packages"           # the plug-in script looks for this name


def plugin_source():
    """Path of the plug-in script shipped inside this package."""
    return Path(str(resources.files(__package__) / PLUGIN_NAME / f"{PLUGIN_NAME}.py"))


def plugin_files():
    """``(path inside the plug-in folder, source)`` of every file the plug-in runs.

    The script and its GIMP filter module, and the host-neutral ``aarecovery_bridge`` that the
    Krita plug-in installs too (one copy of each in the repository).
    """
    import aarecovery_bridge
    script_dir = plugin_source().parent
    files = [(Path(path.name), Path(path)) for path in sorted(script_dir.glob("*.py"))]
    return files + [(Path("aarecovery_bridge", name), Path(path))
                    for name, path in aarecovery_bridge.module_files()]


def _target(plugins_dir):
    plugins_dir = Path(plugins_dir) if plugins_dir else gimp_dir() / "plug-ins"
    folder = plugins_dir / PLUGIN_NAME
    return plugins_dir, folder, folder / f"{PLUGIN_NAME}.py", folder / "config.json"


def stage(folder, python, target=None, wheel_dir=None, log=print):
    """Write a complete plug-in folder: the script, ``config.json``, and a bundle for `target`.

    Parameters
    ----------
    folder : path-like
        The plug-in folder to fill (created if needed).
    python : str
        The Python with aarecovery to record as the out-of-process fallback; "" for none.
    target : aarecovery.gimp.gimp_python.Target, optional
        Bundle the core for this Python; None: no bundle.
    wheel_dir : path-like, optional
        Keep the bundle's wheels here and reuse those already there.
    log : callable
        Receives progress lines.
    """
    from aarecovery import __version__
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for rel, source in plugin_files():
        (folder / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source, folder / rel)
    script = folder / f"{PLUGIN_NAME}.py"
    # GIMP ignores a plug-in it cannot execute, silently: set the mode explicitly.
    script.chmod(0o755)
    config = {"python": python, "aarecovery_version": __version__}
    if target is not None:
        config["bundle"] = bundle.build(folder / BUNDLE_FOLDER, target, wheel_dir, log)
    (folder / "config.json").write_text(json.dumps(config, indent=2) + "\n", encoding="utf-8")


def _swap_in(staged, folder):
    """Rename `staged` to `folder`, replacing what was there only once the rename can happen."""
    old = folder.with_name(f".{PLUGIN_NAME}-old-{uuid.uuid4().hex[:8]}")
    had_old = folder.exists()
    try:
        if had_old:
            folder.rename(old)
        staged.rename(folder)
    except OSError as error:
        if had_old and old.exists() and not folder.exists():
            old.rename(folder)
        raise InstallError(f"cannot replace {folder} ({error.strerror or error}); close GIMP "
                           "and run the install again") from None
    if had_old:
        shutil.rmtree(old, ignore_errors=True)


def install(plugins_dir=None, python=None, target=None, wheel_dir=None, log=print):
    """Install the plug-in into `plugins_dir` (default: GIMP 3's user plug-ins folder).

    Parameters
    ----------
    plugins_dir : path-like, optional
        A GIMP plug-ins folder; by default ``gimp_dir() / "plug-ins"``.
    python : str, optional
        The Python with aarecovery that the plug-in falls back to; default: this one. ""
        records none (the Flatpak's GIMP cannot start a Python outside its sandbox).
    target : aarecovery.gimp.gimp_python.Target, optional
        Bundle the core and its compiled packages for this Python.
    wheel_dir : path-like, optional
        Keep the bundle's wheels here and reuse those already there.
    log : callable
        Receives progress lines.

    Returns
    -------
    pathlib.Path
        The installed script.
    """
    plugins_dir, folder, script, _ = _target(plugins_dir)
    plugins_dir.mkdir(parents=True, exist_ok=True)
    # Staged beside the destination, on the same file system, so that the final step is a
    # rename. GIMP looks only for plug-ins/NAME/NAME.py, so it ignores the hidden folder.
    staged = Path(tempfile.mkdtemp(prefix=f".{PLUGIN_NAME}-new-", dir=plugins_dir))
    try:
        staged.chmod(0o755)                       # mkdtemp's 0700 would be kept by the rename
        stage(staged, sys.executable if python is None else python, target, wheel_dir, log)
        _swap_in(staged, folder)
    finally:
        shutil.rmtree(staged, ignore_errors=True)
    return script


def uninstall(plugins_dir=None):
    """Remove the plug-in's folder; return True if there was one."""
    _, folder, _, _ = _target(plugins_dir)
    if not folder.exists():
        return False
    shutil.rmtree(folder)
    return True


def _check_bundle(info, folder, manifest, gimp_target):
    """Add the bundle's state to `info`: present, current, made for GIMP's Python."""
    site = folder / BUNDLE_FOLDER
    info["bundle"] = manifest
    if not (site / "aarecovery").is_dir():
        info["problems"].append(f"the bundle folder {site} is missing or incomplete; run: "
                                "aarecovery gimp install --bundle")
        return
    info["bundle_current"] = bundle.core_is_current(site)
    if not info["bundle_current"]:
        info["problems"].append("the bundled core differs from this aarecovery's; run: "
                                "aarecovery gimp install --bundle")
    if gimp_target is None:
        return
    try:
        target = gimp_target()
    except InstallError as error:
        info["gimp_python"] = f"unknown ({error})"
        return
    info["gimp_python"] = str(target)
    if (target.python, target.platform) != (manifest.get("python"), manifest.get("platform")):
        info["problems"].append(
            f"the bundle is for CPython {manifest.get('python')} on {manifest.get('platform')} "
            f"but GIMP runs {target.python} on {target.platform}; run: aarecovery gimp install "
            "--bundle")


def status(plugins_dir=None, gimp_target=None):
    """Describe the installation.

    Parameters
    ----------
    plugins_dir : path-like, optional
        As for :func:`install`.
    gimp_target : callable, optional
        Returns the :class:`~aarecovery.gimp.gimp_python.Target` of the Python this profile's
        GIMP runs (raising InstallError when unknown); a bundle is checked against it.

    Returns
    -------
    dict
        ``folder``, ``installed``, ``executable``, ``current`` (same as the packaged script),
        ``python`` (the recorded Python), ``python_ok`` (it imports aarecovery), ``bundle``
        (its manifest, or None), ``bundle_current`` (it holds this aarecovery's core),
        ``gimp_python`` (what GIMP runs, as text, when asked), and ``problems``: sentences
        saying what to fix (empty when all is well).
    """
    plugins_dir, folder, script, config = _target(plugins_dir)
    info = {"folder": str(folder), "installed": script.is_file(), "executable": False,
            "current": False, "python": None, "python_ok": False, "bundle": None,
            "bundle_current": False, "gimp_python": None, "problems": []}
    if not info["installed"]:
        info["problems"].append(f"the plug-in is not installed in {plugins_dir}; "
                                "run: aarecovery gimp install")
        return info
    info["executable"] = os.access(script, os.X_OK) or sys.platform.startswith("win")
    if not info["executable"]:
        info["problems"].append(f"{script} is not executable, so GIMP skips it; "
                                "run: aarecovery gimp install")
    info["current"] = all((folder / rel).is_file() and (folder / rel).read_bytes() == source.read_bytes()
                          for rel, source in plugin_files())
    if not info["current"]:
        info["problems"].append("the installed plug-in differs from this aarecovery's; "
                                "run: aarecovery gimp install")
    try:
        recorded = json.loads(config.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        info["problems"].append(f"{config} is missing or unreadable; run: aarecovery gimp install")
        return info
    info["python"] = recorded.get("python")
    if recorded.get("bundle"):
        _check_bundle(info, folder, recorded["bundle"], gimp_target)
    if info["python"]:
        try:
            probe = subprocess.run([info["python"], "-c", "import aarecovery"],
                                   capture_output=True, timeout=120)
            info["python_ok"] = probe.returncode == 0
        except (OSError, subprocess.TimeoutExpired):
            info["python_ok"] = False
    if not info["bundle"] and not info["python_ok"]:
        # Without a bundle the recorded Python is the way to the core (unless GIMP's own
        # Python has aarecovery, which only a run inside GIMP can tell).
        info["problems"].append(f"the recorded Python {info['python'] or '(none)'} cannot "
                                "import aarecovery; reinstall from a Python that has it, or "
                                "add --bundle")
    return info
