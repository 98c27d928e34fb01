"""Install, remove and inspect the Krita plug-in in a Krita resource folder.

Krita 5 loads Python plug-ins from ``pykrita`` in its resource folder: a ``NAME.desktop`` file
and the package ``NAME``, imported only when ``kritarc`` has ``enable_NAME=true`` in its
``[python]`` group (the Python Plugin Manager's tick). The installer copies the plug-in and
the shared ``aarecovery_bridge`` package there, records the Python that ran it in the
plug-in's ``config.json`` (the worker's Python when Krita's cannot import aarecovery), and
sets the tick.

===========  ==========================================  ======================================
Krita        resource folder                             kritarc
===========  ==========================================  ======================================
Linux        ``$XDG_DATA_HOME/krita`` (~/.local/share)    ``$XDG_CONFIG_HOME/kritarc`` (~/.config)
AppImage     the same as Linux                           the same as Linux
Flatpak      ``~/.var/app/org.kde.krita/data/krita``     ``~/.var/app/org.kde.krita/config/kritarc``
Windows      ``%APPDATA%\\krita``                         ``%LOCALAPPDATA%\\kritarc``
macOS        ``~/Library/Application Support/krita``     ``~/Library/Preferences/kritarc``
===========  ==========================================  ======================================
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from . import InstallError

__all__ = ["PLUGIN_NAME", "FLATPAK_APP", "Profile", "find_profiles", "choose_profile", "plugin_files",
           "install", "remove", "status", "set_enabled", "is_enabled"]

PLUGIN_NAME = "aarecovery_krita"
BRIDGE = "aarecovery_bridge"
FLATPAK_APP = "org.kde.krita"
PYTHON_GROUP = "[python]"


@dataclass(frozen=True)
class Profile:
    """A Krita's resource folder and settings file.

    Attributes
    ----------
    kind : str
        "native" (Linux package or AppImage, Windows, macOS), "flatpak" or "custom".
    resource_dir : pathlib.Path
        The folder holding ``pykrita``.
    kritarc : pathlib.Path or None
        Its settings file, where the plug-in is enabled (None: not known, for a custom folder).
    found : bool
        Whether that Krita or its folder exists on this machine.
    """

    kind: str
    resource_dir: Path
    kritarc: Path = None
    found: bool = True

    @property
    def pykrita(self):
        return self.resource_dir / "pykrita"


def _home(env):
    return Path(env.get("HOME") or env.get("USERPROFILE") or Path.home())


def native_profile(platform=None, environ=None):
    """The resource folder and kritarc of Krita installed for this system (or its AppImage)."""
    env = os.environ if environ is None else environ
    platform = sys.platform if platform is None else platform
    home = _home(env)
    if platform.startswith("win"):
        appdata = Path(env.get("APPDATA") or home / "AppData" / "Roaming")
        local = Path(env.get("LOCALAPPDATA") or home / "AppData" / "Local")
        return Profile("native", appdata / "krita", local / "kritarc")
    if platform == "darwin":
        return Profile("native", home / "Library" / "Application Support" / "krita",
                       home / "Library" / "Preferences" / "kritarc")
    data = Path(env.get("XDG_DATA_HOME") or home / ".local" / "share")
    config = Path(env.get("XDG_CONFIG_HOME") or home / ".config")
    return Profile("native", data / "krita", config / "kritarc")


def flatpak_profile(environ=None):
    """Flathub's Krita: its sandbox maps XDG_DATA_HOME and XDG_CONFIG_HOME into ~/.var/app."""
    base = _home(os.environ if environ is None else environ) / ".var" / "app" / FLATPAK_APP
    return Profile("flatpak", base / "data" / "krita", base / "config" / "kritarc", base.is_dir())


def find_profiles(platform=None, environ=None):
    """The native profile (``found`` says whether Krita or its folder is there), then the
    Flatpak's where that Krita has run on this machine (Linux only)."""
    env = os.environ if environ is None else environ
    platform = sys.platform if platform is None else platform
    native = native_profile(platform, env)
    found = native.resource_dir.is_dir() or bool(shutil.which("krita", path=env.get("PATH")))
    profiles = [Profile(native.kind, native.resource_dir, native.kritarc, found)]
    flatpak = flatpak_profile(env)
    if platform.startswith("linux") and flatpak.found:
        profiles.append(flatpak)
    return profiles


def choose_profile(resource_dir=None, kritarc=None, flatpak=False, platform=None, environ=None):
    """The profile to act on, and a note when the choice was not obvious.

    Order: `resource_dir` (with `kritarc`, if given), `flatpak`, then the native profile,
    except when only the Flatpak's Krita is found: then the Flatpak's.
    """
    if resource_dir:
        return Profile("custom", Path(resource_dir), Path(kritarc) if kritarc else None), None
    if flatpak:
        return flatpak_profile(environ), None
    native, *others = find_profiles(platform, environ)
    if others and not native.found:
        return others[0], f"only the Flatpak Krita was found, so its folder {others[0].resource_dir} is used"
    if others:
        return native, f"the Flatpak Krita has its own folder, {others[0].resource_dir}; add --flatpak for it"
    return native, None


def plugin_files():
    """``(path inside pykrita, source)`` of every file the plug-in runs: its ``.desktop``
    file, its package, and the ``aarecovery_bridge`` it shares with the GIMP plug-in."""
    import aarecovery_bridge
    source = Path(str(resources.files(__package__) / "pykrita"))
    files = [(Path(f"{PLUGIN_NAME}.desktop"), source / f"{PLUGIN_NAME}.desktop")]
    files += [(Path(PLUGIN_NAME, p.name), p) for p in sorted((source / PLUGIN_NAME).glob("*.py"))]
    return files + [(Path(BRIDGE, name), Path(path)) for name, path in aarecovery_bridge.module_files()]


def _write_atomically(path, text):
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, staged = tempfile.mkstemp(prefix=f".{path.name}-", dir=path.parent)
    with os.fdopen(fd, "w", encoding="utf-8") as fh:
        fh.write(text)
    os.replace(staged, path)


def set_enabled(kritarc, enabled=True):
    """Set ``enable_aarecovery_krita`` in the ``[python]`` group of `kritarc`, keeping the rest
    of the file as it is (Krita writes its own keys there; a parser would reorder them)."""
    kritarc = Path(kritarc)
    lines = kritarc.read_text(encoding="utf-8").splitlines() if kritarc.is_file() else []
    key = f"enable_{PLUGIN_NAME}"
    entry = f"{key}={'true' if enabled else 'false'}"
    lines = [line for line in lines if line.split("=", 1)[0].strip() != key]
    if PYTHON_GROUP in lines:
        lines.insert(lines.index(PYTHON_GROUP) + 1, entry)
    else:
        lines += ([""] if lines and lines[-1].strip() else []) + [PYTHON_GROUP, entry]
    _write_atomically(kritarc, "\n".join(lines) + "\n")


def is_enabled(kritarc):
    """Whether `kritarc` enables the plug-in (False when the file or the key is missing)."""
    kritarc = Path(kritarc)
    if not kritarc.is_file():
        return False
    group = None
    for line in kritarc.read_text(encoding="utf-8", errors="replace").splitlines():
        line = line.strip()
        if line.startswith("["):
            group = line
        elif group == PYTHON_GROUP and line.split("=", 1)[0].strip() == f"enable_{PLUGIN_NAME}":
            return line.split("=", 1)[1].strip().lower() == "true"
    return False


def install(profile, python=None):
    """Copy the plug-in into `profile`'s ``pykrita`` and enable it; return the plug-in folder.

    The two package folders are staged beside their places and renamed into them, so a failed
    copy leaves an earlier installation as it was. `python`: the Python with aarecovery the
    plug-in falls back to (default: this one; "" for none).
    """
    from aarecovery import __version__
    pykrita = profile.pykrita
    try:
        pykrita.mkdir(parents=True, exist_ok=True)
        staged = Path(tempfile.mkdtemp(prefix=".aarecovery-new-", dir=pykrita))
    except OSError as error:
        raise InstallError(f"cannot write to {pykrita} ({error.strerror or error}); choose "
                           "another folder with --resource-dir") from None
    try:
        for rel, source in plugin_files():
            (staged / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(source, staged / rel)
        config = {"python": sys.executable if python is None else python, "aarecovery_version": __version__}
        (staged / PLUGIN_NAME / "config.json").write_text(json.dumps(config, indent=2) + "\n", encoding="utf-8")
        for name in (BRIDGE, PLUGIN_NAME, f"{PLUGIN_NAME}.desktop"):
            target = pykrita / name
            if target.is_dir():
                shutil.rmtree(target)
            (staged / name).replace(target)
    finally:
        shutil.rmtree(staged, ignore_errors=True)
    if profile.kritarc is not None:
        set_enabled(profile.kritarc)
    return pykrita / PLUGIN_NAME


def remove(profile):
    """Remove the plug-in and its bridge, and untick it; return True if it was there."""
    there = False
    for name in (PLUGIN_NAME, BRIDGE, f"{PLUGIN_NAME}.desktop"):
        target = profile.pykrita / name
        there |= target.exists()
        if target.is_dir():
            shutil.rmtree(target)
        elif target.exists():
            target.unlink()
    if profile.kritarc is not None and profile.kritarc.is_file():
        set_enabled(profile.kritarc, False)
    return there


def status(profile):
    """Describe the installation in `profile`.

    Returns
    -------
    dict
        ``folder``, ``installed``, ``current`` (the same files as this aarecovery's),
        ``enabled`` (ticked in kritarc; None when no kritarc is known), ``python`` (the
        recorded Python), ``python_ok`` (it imports aarecovery), and ``problems``: sentences
        saying what to fix.
    """
    folder = profile.pykrita / PLUGIN_NAME
    info = {"folder": str(folder), "installed": (folder / "__init__.py").is_file(), "current": False,
            "enabled": None, "python": None, "python_ok": False, "problems": []}
    if not info["installed"]:
        info["problems"].append(f"the plug-in is not installed in {profile.pykrita}; run: aarecovery krita install")
        return info
    info["current"] = all((profile.pykrita / rel).is_file() and (profile.pykrita / rel).read_bytes() ==
                          source.read_bytes() for rel, source in plugin_files())
    if not info["current"]:
        info["problems"].append("the installed plug-in differs from this aarecovery's; run: aarecovery krita install")
    if profile.kritarc is not None:
        info["enabled"] = is_enabled(profile.kritarc)
        if not info["enabled"]:
            info["problems"].append(f"the plug-in is not enabled in {profile.kritarc}; run: aarecovery krita "
                                    "install, or tick it in Settings > Configure Krita > Python Plugin Manager")
    try:
        info["python"] = json.loads((folder / "config.json").read_text(encoding="utf-8")).get("python")
    except (OSError, ValueError):
        info["problems"].append(f"{folder / 'config.json'} is missing or unreadable; run: aarecovery krita install")
    if info["python"]:
        try:
            probe = subprocess.run([info["python"], "-c", "import aarecovery"], capture_output=True, timeout=120)
            info["python_ok"] = probe.returncode == 0
        except (OSError, subprocess.TimeoutExpired):
            info["python_ok"] = False
    if not info["python_ok"]:
        info["problems"].append(f"the recorded Python {info['python'] or '(none)'} cannot import aarecovery; "
                                "reinstall from a Python that has it (unless Krita's own Python has aarecovery)")
    return info
