#!/usr/bin/env python3
"""Build ``dist/aarecovery-gimp-VERSION.zip``: the GIMP 3 plug-in, ready to unpack.

Unpack it into GIMP 3's plug-ins folder (Edit > Preferences > Folders > Plug-ins shows it);
that gives ``plug-ins/aarecovery-gimp/aarecovery-gimp.py``. The zip stores the script with
Unix mode 755, because GIMP skips a plug-in file that is not executable without a word.

Usage: python packaging/build-gimp-zip.py [--out DIR]
"""

import argparse
import re
import sys
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
   (GIMP shows the folder under Edit > Preferences > Folders > Plug-ins).
   On Linux/macOS keep the file executable (chmod +x aarecovery-gimp.py).
2. The plug-in needs the aarecovery Python package. If GIMP's own Python can import it
   (Linux: pip install aarecovery for the system Python), nothing else is needed.
   Otherwise (GIMP's Windows and macOS builds) install aarecovery into any Python 3.10+
   and tell the plug-in where that Python is, in one of these ways:
   - edit config.json next to the script: {{"python": "C:/Python312/python.exe"}}
   - set the environment variable AARECOVERY_PYTHON to that Python, or
   - type it into the plug-in dialog's "Python with aarecovery" field.
   Easier: `pip install aarecovery` and `aarecovery gimp install` do all of this.
3. Restart GIMP: Filters > Enhance > Antialiasing Recovery (apply filter)... and
   Antialiasing Recovery (from layer)...
"""


def version():
    text = (CHECKOUT / "pyproject.toml").read_text(encoding="utf-8")
    return re.search(r'^version\s*=\s*"([^"]+)"', text, re.M).group(1)


def build(out_dir):
    """Write the zip into `out_dir`; return its path."""
    ver = version()
    script = CHECKOUT / "plugin_gimp" / NAME / f"{NAME}.py"
    out_dir.mkdir(parents=True, exist_ok=True)
    target = out_dir / f"{NAME}-{ver}.zip"
    stamp = time.localtime(script.stat().st_mtime)[:6]
    with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as zf:
        for name, data, mode in (
                (f"{NAME}/{NAME}.py", script.read_bytes(), 0o755),
                (f"{NAME}/config.json", b'{"python": ""}\n', 0o644),
                (f"{NAME}/README.txt", README.format(version=ver).encode(), 0o644)):
            info = zipfile.ZipInfo(name, date_time=stamp)
            info.external_attr = (0o100000 | mode) << 16       # regular file + Unix permissions
            info.create_system = 3                              # Unix, so unzip applies the mode
            info.compress_type = zipfile.ZIP_DEFLATED
            zf.writestr(info, data)
    return target


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=CHECKOUT / "dist", help="output folder")
    args = parser.parse_args(argv)
    print(build(args.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
