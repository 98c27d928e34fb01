"""GIMP 3 profile folders: the native one of each system, and the Flatpak's.

GIMP keeps its per-user files (``gimp_dir``, with ``plug-ins`` inside) in a folder for version
3.0, unless the environment variable ``GIMP3_DIRECTORY`` names another:

========  ==================================================================
Linux     ``$XDG_CONFIG_HOME/GIMP/3.0`` (default ``~/.config/GIMP/3.0``)
Windows   ``%APPDATA%\\GIMP\\3.0``
macOS     ``~/Library/Application Support/GIMP/3.0``
Flatpak   ``~/.var/app/org.gimp.GIMP/config/GIMP/3.0`` (Flathub's GIMP, any Linux)
========  ==================================================================

The Flatpak's GIMP sees only its own folder, so a plug-in installed into the native profile
never appears in it, and the reverse.
"""

import os
import shutil
import sys
from dataclasses import dataclass
from pathlib import Path

__all__ = ["FLATPAK_APP", "GIMP_SERIES", "Profile", "gimp_dir", "flatpak_gimp_dir",
           "find_profiles", "choose_profile"]

GIMP_SERIES = "3.0"
FLATPAK_APP = "org.gimp.GIMP"
# A native GIMP 3 on PATH; plain "gimp" may be 2.10, whose profile is another folder anyway.
NATIVE_GIMP_COMMANDS = ("gimp-3.0", "gimp-3", "gimp-console-3.0")


@dataclass(frozen=True)
class Profile:
    """The plug-ins folder of a GIMP profile, and which GIMP uses it.

    Attributes
    ----------
    kind : str
        "native" (GIMP installed for this system), "flatpak" (Flathub's org.gimp.GIMP) or
        "custom" (GIMP3_DIRECTORY or ``--plugins-dir``).
    plugins_dir : pathlib.Path
        The profile's ``plug-ins`` folder.
    found : bool
        Whether that GIMP or its profile exists on this machine.
    """

    kind: str
    plugins_dir: Path
    found: bool = True


def _home(env):
    return Path(env.get("HOME") or env.get("USERPROFILE") or Path.home())


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
    home = _home(env)
    if platform.startswith("win"):
        appdata = env.get("APPDATA") or str(home / "AppData" / "Roaming")
        return Path(appdata) / "GIMP" / GIMP_SERIES
    if platform == "darwin":
        return home / "Library" / "Application Support" / "GIMP" / GIMP_SERIES
    config = env.get("XDG_CONFIG_HOME") or str(home / ".config")
    return Path(config) / "GIMP" / GIMP_SERIES


def flatpak_gimp_dir(environ=None):
    """The Flatpak GIMP's profile folder (its sandbox maps XDG_CONFIG_HOME into ~/.var/app)."""
    env = os.environ if environ is None else environ
    return _home(env) / ".var" / "app" / FLATPAK_APP / "config" / "GIMP" / GIMP_SERIES


def _flatpak_found(env):
    """The Flatpak GIMP is installed (per user or system-wide) or has run here."""
    home = _home(env)
    return any(p.exists() for p in (
        home / ".var" / "app" / FLATPAK_APP,                        # made on its first start
        home / ".local" / "share" / "flatpak" / "app" / FLATPAK_APP,
        Path("/var/lib/flatpak/app") / FLATPAK_APP))


def _native_found(platform, env):
    if not platform.startswith("linux"):
        return True                   # Windows and macOS have no Flatpak to tell apart from
    return gimp_dir(platform, {**env, "GIMP3_DIRECTORY": ""}).is_dir() or any(
        shutil.which(name, path=env.get("PATH")) for name in NATIVE_GIMP_COMMANDS)


def find_profiles(platform=None, environ=None):
    """The profiles on this machine: native first, then the Flatpak's (Linux only).

    The native profile is always listed (``found`` says whether GIMP or the folder is there);
    the Flatpak's only when the Flatpak GIMP is installed or its folder exists.
    """
    env = os.environ if environ is None else environ
    platform = sys.platform if platform is None else platform
    native = Profile("native", gimp_dir(platform, {**env, "GIMP3_DIRECTORY": ""}) / "plug-ins",
                     _native_found(platform, env))
    profiles = [native]
    if platform.startswith("linux") and (_flatpak_found(env) or flatpak_gimp_dir(env).is_dir()):
        profiles.append(Profile("flatpak", flatpak_gimp_dir(env) / "plug-ins"))
    return profiles


def choose_profile(plugins_dir=None, flatpak=False, platform=None, environ=None):
    """The profile to act on, and a note for the user when the choice was not obvious.

    Order: `plugins_dir`, `flatpak`, ``GIMP3_DIRECTORY``, then the native profile, except when
    only the Flatpak GIMP is found on this machine: then the Flatpak's.

    Returns
    -------
    (Profile, str or None)
    """
    env = os.environ if environ is None else environ
    if plugins_dir:
        return Profile("custom", Path(plugins_dir)), None
    if flatpak:
        return Profile("flatpak", flatpak_gimp_dir(env) / "plug-ins", _flatpak_found(env)), None
    if env.get("GIMP3_DIRECTORY"):
        return Profile("custom", gimp_dir(platform, env) / "plug-ins"), None
    native, *others = find_profiles(platform, env)
    if others and not native.found:
        return others[0], (f"only the Flatpak GIMP was found, so its profile "
                           f"{others[0].plugins_dir.parent} is used (--plugins-dir picks another)")
    if others:
        return native, (f"the Flatpak GIMP has its own profile, {others[0].plugins_dir.parent}; "
                        "add --flatpak to use that one")
    return native, None
