#!/usr/bin/env python3
"""Build ``dist/aarecovery-gimp-VERSION[-cpXY-PLATFORM].zip``: the GIMP 3 plug-in, ready to unpack.

Unpack it into GIMP 3's plug-ins folder (Edit > Preferences > Folders > Plug-ins shows it);
that gives ``plug-ins/aarecovery-gimp/aarecovery-gimp.py``. The zip keeps the files' Unix
modes, the script's 755 included, because GIMP skips a plug-in file that is not executable
without a word.

With ``--python-version X.Y --platform TAG`` the zip also holds the bundle, the core with NumPy
and moderngl for that Python (pip downloads the wheels), so that a GIMP running that Python
needs nothing else; for people who have no pip to run ``aarecovery gimp install --bundle``.
The plug-in folder is written by the same code as ``aarecovery gimp install``, so run this
with a Python that has this checkout installed (``pip install -e .``).

Usage: python packaging/build-gimp-zip.py [--out DIR] [--python-version X.Y --platform TAG]
"""

import argparse
import re
import sys
import tempfile
import time
import zipfile
from pathlib import Path

CHECKOUT = Path(__file__).resolve().parents[1]
NAME = "aarecovery-gimp"

README = """\
aarecovery GIMP 3 plug-in {version}
=================================

1. Unpack this zip into GIMP 3's plug-ins folder, so that you get
   plug-ins/aarecovery-gimp/aarecovery-gimp.py
   (GIMP shows the folder under Edit > Preferences > Folders > Plug-ins; the Flatpak GIMP's
   is ~/.var/app/org.gimp.GIMP/config/GIMP/3.0/plug-ins).
   On Linux/macOS keep the file executable (chmod +x aarecovery-gimp.py).
2. {core}
3. Restart GIMP: Filters > Enhance > Antialiasing Recovery (apply filter)... and
   Antialiasing Recovery (from layer)...
"""
CORE_SEPARATE = """\
The plug-in needs the aarecovery Python package. If GIMP's own Python can import it
   (Linux: a distribution package of aarecovery), nothing else is needed.
   Otherwise install aarecovery into any Python 3.10+ and tell the plug-in where that Python
   is, in one of these ways:
   - edit config.json next to the script: {"python": "C:/Python312/python.exe"}
   - set the environment variable AARECOVERY_PYTHON to that Python, or
   - type it into the plug-in dialog's "Python with aarecovery" field.
   Easier: `pip install aarecovery` and `aarecovery gimp install` do all of this."""
CORE_BUNDLED = """\
The folder site-packages holds aarecovery with NumPy and moderngl for CPython {python}
   on {platform}. The plug-in uses them when GIMP runs that Python; for another one it says so
   and falls back to a Python with aarecovery named in config.json ("python")."""


def version():
    text = (CHECKOUT / "pyproject.toml").read_text(encoding="utf-8")
    return re.search(r'^version\s*=\s*"([^"]+)"', text, re.M).group(1)


def write_zip(folder, target_zip, stamp):
    """Zip `folder` (as its own name) with each file's Unix mode."""
    with zipfile.ZipFile(target_zip, "w", zipfile.ZIP_DEFLATED) as zf:
        for path in sorted(p for p in folder.rglob("*") if p.is_file()):
            info = zipfile.ZipInfo(str(path.relative_to(folder.parent).as_posix()), date_time=stamp)
            info.external_attr = (0o100000 | (path.stat().st_mode & 0o777)) << 16
            info.create_system = 3                              # Unix, so unzip applies the mode
            info.compress_type = zipfile.ZIP_DEFLATED
            zf.writestr(info, path.read_bytes())


def build(out_dir, target=None):
    """Write the zip into `out_dir`, with a bundle for `target` if given; return its path."""
    from aarecovery.gimp import install as inst

    script = CHECKOUT / "plugin_gimp" / NAME / f"{NAME}.py"
    if inst.plugin_source().read_bytes() != script.read_bytes():
        raise SystemExit(f"build-gimp-zip.py: error: the aarecovery in {sys.executable} is not "
                         "this checkout's; install it with: pip install -e .")
    ver = version()
    suffix = "" if target is None else \
        f"-cp{target.python.replace('.', '')}-{target.pip_platforms[0]}"
    out_dir.mkdir(parents=True, exist_ok=True)
    target_zip = out_dir / f"{NAME}-{ver}{suffix}.zip"
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / NAME
        inst.stage(folder, python="", target=target)
        core = CORE_SEPARATE if target is None else CORE_BUNDLED.format(
            python=target.python, platform=target.platform)
        (folder / "README.txt").write_text(README.format(version=ver, core=core), encoding="utf-8")
        write_zip(folder, target_zip, time.localtime(script.stat().st_mtime)[:6])
    return target_zip


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=CHECKOUT / "dist", help="output folder")
    parser.add_argument("--python-version", metavar="X.Y",
                        help="bundle the core for this CPython version (with --platform)")
    parser.add_argument("--platform", metavar="TAG",
                        help="the bundle's wheel platform, e.g. manylinux_2_28_x86_64")
    args = parser.parse_args(argv)
    try:
        from aarecovery.gimp import InstallError
        from aarecovery.gimp.gimp_python import target_for
    except ImportError as error:
        print(f"build-gimp-zip.py: error: run it with a Python that has this checkout installed "
              f"(pip install -e .): {error}", file=sys.stderr)
        return 1
    try:
        target = target_for("custom", None, args.python_version, args.platform) \
            if args.python_version or args.platform else None
        print(build(args.out, target))
    except InstallError as error:
        print(f"build-gimp-zip.py: error: {error}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
