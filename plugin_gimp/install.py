"""Install, remove and inspect the GIMP 3 plug-in in the user's GIMP profile.

GIMP 3 loads a plug-in from ``<gimp_dir>/plug-ins/NAME/NAME.py`` and only if that file is
executable (it skips a non-executable one without a word). ``gimp_dir`` is GIMP's per-user
folder for version 3.0 unless the environment variable ``GIMP3_DIRECTORY`` names another:

========  ==================================================================
Linux     ``$XDG_CONFIG_HOME/GIMP/3.0`` (default ``~/.config/GIMP/3.0``)
Windows   ``%APPDATA%\\GIMP\\3.0``
macOS     ``~/Library/Application Support/GIMP/3.0``
========  ==================================================================

Next to the plug-in, ``config.json`` records the Python that ran the installer. GIMP runs the
plug-in with its own Python; when that one cannot ``import aarecovery`` (GIMP's Windows and
macOS builds), the plug-in runs the core in the recorded Python instead.
"""

import json
import os
import shutil
import stat
import subprocess
import sys
from importlib import resources
from pathlib import Path

__all__ = ["PLUGIN_NAME", "gimp_dir", "plugin_source", "install", "uninstall", "status"]

PLUGIN_NAME = "aarecovery-gimp"
GIMP_SERIES = "3.0"


def gimp_dir(platform=None, environ=None):
    """GIMP 3's per-user folder (``gimp_dir``) for `platform` (default: this one).

    Parameters
    ----------
    platform : str, optional
        A ``sys.platform`` value: "linux", "win32", "darwin".
    environ : mapping, optional
        The environment to read (default ``os.environ``).

    Returns
    -------
    pathlib.Path
    """
    env = os.environ if environ is None else environ
    platform = sys.platform if platform is None else platform
    if env.get("GIMP3_DIRECTORY"):
        return Path(env["GIMP3_DIRECTORY"]).expanduser()
    home = Path(env.get("HOME") or env.get("USERPROFILE") or Path.home())
    if platform.startswith("win"):
        appdata = env.get("APPDATA") or str(home / "AppData" / "Roaming")
        return Path(appdata) / "GIMP" / GIMP_SERIES
    if platform == "darwin":
        return home / "Library" / "Application Support" / "GIMP" / GIMP_SERIES
    config = env.get("XDG_CONFIG_HOME") or str(home / ".config")
    return Path(config) / "GIMP" / GIMP_SERIES


def plugin_source():
    """Path of the plug-in script shipped inside this package."""
    return Path(str(resources.files(__package__) / PLUGIN_NAME / f"{PLUGIN_NAME}.py"))


def _target(plugins_dir):
    folder = Path(plugins_dir) / PLUGIN_NAME
    return folder, folder / f"{PLUGIN_NAME}.py", folder / "config.json"


def install(plugins_dir=None, python=None):
    """Copy the plug-in into `plugins_dir` (default: GIMP 3's user plug-ins folder).

    Parameters
    ----------
    plugins_dir : path-like, optional
        A GIMP plug-ins folder; by default ``gimp_dir() / "plug-ins"``.
    python : str, optional
        The Python with aarecovery that the plug-in falls back to; default: this one.

    Returns
    -------
    pathlib.Path
        The installed script.
    """
    plugins_dir = Path(plugins_dir) if plugins_dir else gimp_dir() / "plug-ins"
    folder, script, config = _target(plugins_dir)
    folder.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(plugin_source(), script)
    # GIMP ignores a plug-in it cannot execute, silently: set the x bits explicitly.
    script.chmod(script.stat().st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
    from aarecovery import __version__
    config.write_text(json.dumps({"python": python or sys.executable,
                                  "aarecovery_version": __version__}, indent=2) + "\n",
                      encoding="utf-8")
    return script


def uninstall(plugins_dir=None):
    """Remove the plug-in's folder; return True if there was one."""
    plugins_dir = Path(plugins_dir) if plugins_dir else gimp_dir() / "plug-ins"
    folder, _, _ = _target(plugins_dir)
    if not folder.exists():
        return False
    shutil.rmtree(folder)
    return True


def status(plugins_dir=None):
    """Describe the installation.

    Returns
    -------
    dict
        ``folder``, ``installed``, ``executable``, ``current`` (same as the packaged script),
        ``python`` (the recorded Python), ``python_ok`` (it imports aarecovery), and
        ``problems``: a list of sentences saying what to fix (empty when all is well).
    """
    plugins_dir = Path(plugins_dir) if plugins_dir else gimp_dir() / "plug-ins"
    folder, script, config = _target(plugins_dir)
    info = {"folder": str(folder), "installed": script.is_file(), "executable": False,
            "current": False, "python": None, "python_ok": False, "problems": []}
    if not info["installed"]:
        info["problems"].append(f"the plug-in is not installed in {plugins_dir}; "
                                "run: aarecovery gimp install")
        return info
    info["executable"] = os.access(script, os.X_OK) or sys.platform.startswith("win")
    if not info["executable"]:
        info["problems"].append(f"{script} is not executable, so GIMP skips it; "
                                "run: aarecovery gimp install")
    info["current"] = script.read_bytes() == plugin_source().read_bytes()
    if not info["current"]:
        info["problems"].append("the installed plug-in differs from this aarecovery's; "
                                "run: aarecovery gimp install")
    try:
        info["python"] = json.loads(config.read_text(encoding="utf-8")).get("python")
    except (OSError, ValueError):
        info["problems"].append(f"{config} is missing or unreadable; run: aarecovery gimp install")
    if info["python"]:
        try:
            probe = subprocess.run([info["python"], "-c", "import aarecovery"],
                                   capture_output=True, timeout=120)
            info["python_ok"] = probe.returncode == 0
        except (OSError, subprocess.TimeoutExpired):
            info["python_ok"] = False
        if not info["python_ok"]:
            info["problems"].append(f"the recorded Python {info['python']} cannot import "
                                    "aarecovery; reinstall from a Python that has it")
    return info
