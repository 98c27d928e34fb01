"""The bundle: aarecovery's core and the compiled packages it needs, for the Python GIMP runs.

:func:`build` fills a folder (the plug-in's ``site-packages``) that GIMP's Python imports
from, with nothing installed outside it:

* NumPy and moderngl (with glcontext, its context library), as binary wheels for the target
  Python and platform, which this Python's pip downloads into a wheel folder (``pip download
  --only-binary=:all: --python-version --platform``) and then installs from that folder alone
  (``pip install --target --no-index``); their version ranges are aarecovery's own
  requirements. A kept wheel folder (``--wheel-dir``) makes the next bundle download only what
  is new, and lets one be made offline;
* a copy of the installed aarecovery core (pure Python, shaders and data files).

aarecovery's other requirements, Pillow, imagecodecs and tifffile, read and write image files.
The plug-in hands the core arrays, so they stay out: they are two thirds of the download
(36 of 52 MB for CPython 3.13 on x86_64 Linux).
"""

import importlib.util
import re
import shutil
import subprocess
import sys
import tempfile
from importlib import metadata
from pathlib import Path

from . import InstallError

__all__ = ["PLUGIN_PACKAGES", "requirements", "build", "core_files", "core_is_current",
           "folder_size"]

#: The distributions the plug-in's call of ``aarecovery.recover`` imports.
PLUGIN_PACKAGES = ("numpy", "moderngl")
# pip's ways of saying that it never reached the index.
NETWORK_FAILURES = ("NewConnectionError", "Failed to establish", "Temporary failure in name "
                    "resolution", "Name or service not known", "ConnectTimeout", "ReadTimeout",
                    "ProxyError", "SSLError", "Network is unreachable", "Connection refused")


def requirements():
    """The requirement strings for :data:`PLUGIN_PACKAGES`, from aarecovery's metadata."""
    try:
        declared = metadata.requires("aarecovery") or []
    except metadata.PackageNotFoundError:
        raise InstallError("aarecovery has no package metadata in this Python (a bare source "
                           "tree?); install it with pip first: pip install -e .") from None
    chosen = {}
    for requirement in declared:
        if re.search(r"\bextra\s*==", requirement):          # the viewer's, the tests'
            continue
        name = re.match(r"[A-Za-z0-9._-]+", requirement)[0].lower()
        if name in PLUGIN_PACKAGES:
            chosen[name] = requirement
    missing = set(PLUGIN_PACKAGES) - set(chosen)
    if missing:
        raise InstallError(f"aarecovery's metadata does not require {', '.join(sorted(missing))}; "
                           "the installed aarecovery does not match this plug-in")
    return [chosen[name] for name in PLUGIN_PACKAGES]


def core_files():
    """``(path inside the bundle, source file)`` for each file of the installed core.

    The viewer and this plug-in package are left out: in an installed tree they are
    subfolders of aarecovery, in a checkout folders of their own.
    """
    import aarecovery
    left_out = []
    for name in ("aarecovery.viewer", "aarecovery.gimp", "aarecovery.krita"):
        spec = importlib.util.find_spec(name)
        if spec is not None:
            left_out += [Path(p).resolve() for p in spec.submodule_search_locations or []]
    for root in map(Path, aarecovery.__path__):
        for path in sorted(root.rglob("*")):
            if (not path.is_file() or "__pycache__" in path.parts or path.suffix == ".pyc"
                    or any(path.resolve().is_relative_to(folder) for folder in left_out)):
                continue
            yield Path("aarecovery", path.relative_to(root)), path


def core_is_current(site_dir):
    """Whether `site_dir` holds exactly the installed core's files."""
    site_dir = Path(site_dir)
    expected = dict(core_files())
    bundled = {p.relative_to(site_dir) for p in (site_dir / "aarecovery").rglob("*")
               if p.is_file() and "__pycache__" not in p.parts}
    return bundled == set(expected) and all(
        (site_dir / rel).read_bytes() == source.read_bytes() for rel, source in expected.items())


def folder_size(folder):
    """Bytes in the files under `folder`."""
    return sum(p.stat().st_size for p in Path(folder).rglob("*") if p.is_file())


def _pip_failure(stderr, target):
    """One line for pip's failure: unreachable index, no wheel, or pip's own last words."""
    lines = [line.strip() for line in stderr.splitlines() if line.strip()]
    if any(marker in stderr for marker in NETWORK_FAILURES):
        return (f"pip cannot reach the package index ({lines[-1] if lines else 'no output'}); "
                "check the network or proxy settings and run it again")
    missing = re.search(r"No matching distribution found for (\S+)", stderr)
    if missing:
        return (f"no wheel of {missing[1]} exists for {target}; check the Python version and "
                "platform of the GIMP it is for (--python-version, --platform)")
    return f"pip could not install the bundle's wheels: {lines[-1] if lines else 'no output'}"


def _pip(command, options, wanted, target):
    """Run ``pip COMMAND`` for `target`'s wheels of `wanted`; raise InstallError on failure."""
    platforms = [arg for tag in target.pip_platforms for arg in ("--platform", tag)]
    proc = subprocess.run(
        [sys.executable, "-m", "pip", command, *options, "--only-binary=:all:",
         "--implementation", "cp", "--python-version", target.python, *platforms,
         "--disable-pip-version-check", "--progress-bar", "off", *wanted],
        capture_output=True, text=True, stdin=subprocess.DEVNULL)
    if proc.returncode != 0:
        raise InstallError(_pip_failure(proc.stderr + proc.stdout, target))


def build(site_dir, target, wheel_dir=None, log=print):
    """Install the bundle for `target` into the empty or new folder `site_dir`.

    Parameters
    ----------
    site_dir : path-like
        The folder to fill.
    target : aarecovery.gimp.gimp_python.Target
        The Python and platform the wheels must suit.
    wheel_dir : path-like, optional
        Where the wheels are downloaded and kept; wheels already there are not fetched again
        (pip's ``PIP_NO_INDEX=1`` then makes the bundle offline). Default: a temporary folder.
    log : callable
        Receives progress lines.

    Returns
    -------
    dict
        The manifest for ``config.json``: ``python`` and ``platform`` (what the plug-in checks
        before it uses the bundle), ``wheels`` (the newest pip platform tag accepted) and
        ``packages`` (name to version).

    Raises
    ------
    aarecovery.gimp.InstallError
        Without pip, without a wheel for the target, or without the network.
    """
    from aarecovery import __version__
    site_dir = Path(site_dir)
    if importlib.util.find_spec("pip") is None:
        raise InstallError(f"this Python ({sys.executable}) has no pip, which fetches the "
                           "bundle's wheels; add it with: python -m ensurepip")
    wanted = requirements()
    log(f"fetching {', '.join(wanted)} for {target} with pip")
    with tempfile.TemporaryDirectory(prefix="aarecovery-wheels-") as scratch:
        wheels = str(wheel_dir or scratch)
        Path(wheels).mkdir(parents=True, exist_ok=True)
        # The wheel folder is also a source: a wheel already in it is not downloaded again.
        _pip("download", ["--dest", wheels, "--find-links", wheels], wanted, target)
        _pip("install", ["--target", str(site_dir), "--no-index", "--find-links", wheels,
                         "--no-compile", "--no-warn-script-location"], wanted, target)
    # Console scripts (f2py, numpy-config) start with this Python's path: of no use in GIMP.
    shutil.rmtree(site_dir / "bin", ignore_errors=True)
    for rel, source in core_files():
        (site_dir / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source, site_dir / rel)
    packages = {dist.metadata["Name"].lower(): dist.version
                for dist in metadata.distributions(path=[str(site_dir)])}
    packages["aarecovery"] = __version__
    return {"python": target.python, "platform": target.platform,
            "wheels": target.pip_platforms[0], "packages": dict(sorted(packages.items()))}
