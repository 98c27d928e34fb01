"""The Python that GIMP runs plug-ins with, and the wheels it can load.

A bundle is only of use if GIMP's own Python can load its compiled packages, so the installer
asks that Python for its version and platform where it can:

* ``--gimp-python PATH``: that Python;
* the Flatpak GIMP: ``flatpak run --command=python3 org.gimp.GIMP``, the Python inside the
  sandbox, found the way the plug-in's ``#!/usr/bin/env python3`` finds it;
* a native GIMP: the Python that GIMP's ``interpreters/*.interp`` files map ``python3`` to
  (GIMP's Windows and macOS builds ship them), else a ``python3`` next to the GIMP executable,
  else, on Linux, the ``python3`` on PATH (what the shebang starts there).

Where asking is impossible (a bundle for another machine, a Flatpak without the ``flatpak``
command), ``--python-version X.Y --platform TAG`` say it instead.
"""

import json
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

from . import InstallError
from .profiles import FLATPAK_APP, GIMP_SERIES, NATIVE_GIMP_COMMANDS

__all__ = ["Target", "target_for", "from_tags", "ask", "native_gimp_python", "caveat"]

# Run by the Python being asked; it prints one JSON line. sysconfig.get_platform() is the form
# the plug-in compares with at run time (see use_bundle in the plug-in script).
PROBE = """\
import json, os, platform, sys, sysconfig
try:
    libc = os.confstr("CS_GNU_LIBC_VERSION")
except (AttributeError, ValueError, OSError):
    libc = None
print(json.dumps({"implementation": sys.implementation.name,
                  "version": "%d.%d" % sys.version_info[:2],
                  "platform": sysconfig.get_platform(), "machine": platform.machine(),
                  "libc": libc, "executable": sys.executable}))
"""
# PEP 600 names the old manylinux tags after the glibc they need.
LEGACY_MANYLINUX = {17: "manylinux2014", 12: "manylinux2010", 5: "manylinux1"}
OLDEST_GLIBC_MINOR = 5
WINDOWS_TAGS = {"win32": "win32", "win_amd64": "win-amd64", "win_arm64": "win-arm64"}
TAG_EXAMPLES = "manylinux_2_28_x86_64, macosx_11_0_arm64 or win_amd64"


@dataclass(frozen=True)
class Target:
    """The Python a bundle is made for.

    Attributes
    ----------
    python : str
        Its version, "X.Y".
    platform : str
        ``sysconfig.get_platform()`` of that Python, less macOS's version ("linux-x86_64",
        "macosx-arm64", "win-amd64"): the plug-in compares it with its own before it uses
        the bundle.
    pip_platforms : tuple of str
        pip's ``--platform`` values for it, the newest first.
    source : str
        How it was found, for messages.
    """

    python: str
    platform: str
    pip_platforms: tuple
    source: str

    def __str__(self):
        return f"CPython {self.python} on {self.platform} ({self.source})"


def manylinux_platforms(glibc_minor, arch):
    """pip platform tags for a glibc 2.`glibc_minor` system: that glibc's and every older one."""
    tags = []
    for minor in range(glibc_minor, OLDEST_GLIBC_MINOR - 1, -1):
        tags.append(f"manylinux_2_{minor}_{arch}")
        if minor in LEGACY_MANYLINUX:
            tags.append(f"{LEGACY_MANYLINUX[minor]}_{arch}")
    return tuple(tags)


def from_tags(python_version, platform_tag, source="given"):
    """A target from ``--python-version`` and ``--platform``.

    Parameters
    ----------
    python_version : str
        "X.Y", e.g. "3.12".
    platform_tag : str
        A wheel platform tag: ``manylinux_2_28_x86_64`` (or ``manylinux2014_x86_64``; wheels
        for older glibc versions are accepted too), ``macosx_11_0_arm64`` (pip accepts older
        macOS versions itself), ``win_amd64``.
    """
    if not re.fullmatch(r"3\.\d{1,2}", python_version or ""):
        raise InstallError(f"--python-version takes the Python version GIMP runs as X.Y, e.g. "
                           f"3.12, not '{python_version}'")
    tag = platform_tag or ""
    modern = re.fullmatch(r"manylinux_2_(\d+)_(\w+)", tag)
    legacy = re.fullmatch(r"(manylinux2014|manylinux2010|manylinux1)_(\w+)", tag)
    mac = re.fullmatch(r"macosx_(\d+)_(\d+)_(\w+)", tag)
    if modern or legacy:
        minor = int(modern[1]) if modern else next(
            m for m, name in LEGACY_MANYLINUX.items() if name == legacy[1])
        arch = (modern or legacy)[2]
        return Target(python_version, f"linux-{arch}", manylinux_platforms(minor, arch), source)
    if mac:
        return Target(python_version, f"macosx-{mac[3]}", (tag,), source)
    if tag in WINDOWS_TAGS:
        return Target(python_version, WINDOWS_TAGS[tag], (tag,), source)
    raise InstallError(f"--platform '{tag}' is not a wheel platform tag the bundle knows; use "
                       f"one such as {TAG_EXAMPLES}")


def _from_probe(info, source):
    """A target from what `source` reported about itself (see PROBE)."""
    implementation, version, platform = info["implementation"], info["version"], info["platform"]
    if implementation != "cpython":
        raise InstallError(f"{source} is {implementation} {version}; the bundle's wheels are "
                           "built for CPython only")
    if platform.startswith("mingw"):
        # MSYS2's CPython fork: its extension modules have their own ABI and file names.
        raise InstallError(
            f"{source} is an MSYS2 (MinGW) build of Python {version}, as in GIMP's Windows "
            "installer, and cannot load PyPI's Windows wheels, so no bundle can serve it; "
            "install aarecovery into a Python from python.org and run 'aarecovery gimp install' "
            "without --bundle")
    key = re.sub(r"^macosx-[0-9.]+-", "macosx-", platform)
    if platform.startswith("linux-"):
        arch = platform[len("linux-"):]
        glibc = re.fullmatch(r"glibc (\d+)\.(\d+)", info.get("libc") or "")
        if not glibc:
            raise InstallError(f"{source} does not run on glibc ({info.get('libc') or 'no glibc'})"
                               "; say which wheels it takes with --python-version and --platform "
                               f"(e.g. musllinux_1_2_{arch} is not supported by the bundle)")
        return Target(version, key, manylinux_platforms(int(glibc[2]), arch), source)
    if platform.startswith("macosx-"):
        _, macos, arch = platform.split("-")
        if arch.startswith("universal"):
            arch = info["machine"]            # universal2 builds: the wheels of this machine
        major, _, minor = macos.partition(".")
        return Target(version, key, (f"macosx_{major}_{minor or 0}_{arch}",), source)
    tag = platform.replace("-", "_")
    if tag in WINDOWS_TAGS:
        return Target(version, key, (tag,), source)
    raise InstallError(f"{source} runs on '{platform}', for which the bundle knows no wheels; "
                       f"give --python-version and --platform (e.g. {TAG_EXAMPLES})")


def ask(argv, source):
    """Run the Python `argv` with the probe and return its target.

    Parameters
    ----------
    argv : list of str
        The command that starts that Python (a path, or ``flatpak run ...``).
    source : str
        How to name it in messages.
    """
    try:
        proc = subprocess.run([*argv, "-c", PROBE], capture_output=True, text=True, timeout=120,
                              stdin=subprocess.DEVNULL)
    except (OSError, subprocess.TimeoutExpired) as error:
        raise InstallError(f"cannot run {source} to ask its version ({error}); give "
                           "--python-version and --platform instead") from None
    lines = proc.stdout.strip().splitlines()
    try:
        info = json.loads(lines[-1])
    except (IndexError, ValueError):
        tail = (proc.stderr.strip().splitlines() or ["no output"])[-1]
        raise InstallError(f"{source} did not report its version (exit {proc.returncode}: "
                           f"{tail}); give --python-version and --platform instead") from None
    return _from_probe(info, source)


def _interp_python(interp_dir, bin_dir):
    """The Python that the ``*.interp`` files in `interp_dir` give ``python3`` plug-ins, or None.

    Lines are ``name=program`` (a shebang's program; ``#!/usr/bin/env python3`` looks up
    ``python3``) or binfmt-style ``:name:E::py::program:`` (by file extension). A bare
    program name is looked up in GIMP's bin folder, which GIMP puts on the plug-ins' PATH.
    """
    programs, by_extension = {}, None
    for interp in sorted(interp_dir.glob("*.interp")):
        for line in interp.read_text(encoding="utf-8", errors="replace").splitlines():
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            if "=" in line and not line.startswith((":", ",")):
                name, _, program = line.partition("=")
                programs[name.strip()] = program.strip()
            else:
                fields = line.split(line[0])
                if len(fields) > 6 and fields[2] == "E" and fields[4] == "py":
                    by_extension = fields[6]
    for program in (*(programs.get(k) for k in ("python3", "/usr/bin/env python3",
                                                "/usr/bin/python3", "python")), by_extension):
        if program:
            path = Path(program)
            return path if path.is_absolute() else bin_dir / program
    return None


def _gimp_installs(platform, env):
    """``(bin folder, lib folders)`` of the native GIMP 3 installations to look at."""
    installs = []
    for name in NATIVE_GIMP_COMMANDS:
        found = shutil.which(name, path=env.get("PATH"))
        if found:
            prefix = Path(found).resolve().parent.parent
            installs.append((Path(found).parent, [prefix / "lib", prefix / "lib64",
                                                  *sorted((prefix / "lib").glob("*-*-*"))]))
    if platform.startswith("win"):
        for base in (env.get("ProgramFiles"), env.get("LOCALAPPDATA") and
                     str(Path(env["LOCALAPPDATA"]) / "Programs")):
            if base:
                prefix = Path(base) / "GIMP 3"
                installs.append((prefix / "bin", [prefix / "lib"]))
    if platform == "darwin":
        for apps in (Path("/Applications"), Path(env.get("HOME") or Path.home()) / "Applications"):
            contents = apps / "GIMP.app" / "Contents"
            installs.append((contents / "MacOS", [contents / "Resources" / "lib"]))
    return installs


def native_gimp_python(platform=None, environ=None):
    """The Python a native GIMP 3 on this machine runs ``#!/usr/bin/env python3`` plug-ins with.

    Returns
    -------
    pathlib.Path or None
        None when no GIMP 3 is found.
    """
    env = os.environ if environ is None else environ
    platform = sys.platform if platform is None else platform
    for bin_dir, lib_dirs in _gimp_installs(platform, env):
        for lib in lib_dirs:
            interp_dir = lib / "gimp" / GIMP_SERIES / "interpreters"
            mapped = _interp_python(interp_dir, bin_dir) if interp_dir.is_dir() else None
            if mapped is not None:
                return mapped
        for name in ("python3", "python3.exe", "python.exe"):
            if (bin_dir / name).is_file():
                return bin_dir / name
        if bin_dir.is_dir() and platform.startswith("linux"):
            found = shutil.which("python3", path=env.get("PATH"))
            if found:
                return Path(found)
    return None


def target_for(kind, gimp_python=None, python_version=None, platform_tag=None):
    """The target for a profile of `kind` ("native", "flatpak", "custom").

    Parameters
    ----------
    gimp_python : str, optional
        The Python to ask instead of looking for GIMP's.
    python_version, platform_tag : str, optional
        Both or neither: the target as given, nothing asked.
    """
    if python_version or platform_tag:
        if not (python_version and platform_tag):
            raise InstallError("--python-version and --platform go together: give both, e.g. "
                               "--python-version 3.12 --platform manylinux_2_28_x86_64")
        return from_tags(python_version, platform_tag)
    if gimp_python:
        return ask([gimp_python], gimp_python)
    if kind == "flatpak":
        flatpak = shutil.which("flatpak")
        if not flatpak:
            raise InstallError("cannot ask the Flatpak GIMP for its Python: there is no flatpak "
                               "command on PATH; give --python-version and --platform (e.g. "
                               "3.12 and manylinux_2_28_x86_64)")
        return ask([flatpak, "run", "--command=python3", FLATPAK_APP],
                   f"the Flatpak {FLATPAK_APP}'s python3")
    found = native_gimp_python()
    if found is None:
        raise InstallError("found no GIMP 3 to ask which Python it runs; give --gimp-python PATH, "
                           "or --python-version X.Y and --platform TAG")
    return ask([str(found)], str(found))


def caveat(target):
    """A warning about a target that a GIMP is unlikely to load, or None."""
    if target.platform.startswith("win"):
        return ("GIMP's own Windows builds run an MSYS2 Python, which cannot load PyPI's Windows "
                "wheels; there the plug-in skips this bundle and says so")
    return None
