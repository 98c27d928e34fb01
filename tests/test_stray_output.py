"""Everything the command line prints on stderr is its own one-line ``aarecovery:`` messages:
no warnings of the libraries below it (libpng, Mesa's EGL) beside them."""

import os
import subprocess
import sys
from importlib import resources

import numpy as np

from aarecovery import write_image


def _stderr_lines(*args, env):
    done = subprocess.run([sys.executable, "-m", "aarecovery", *map(str, args)], capture_output=True, text=True,
                          timeout=300, env=env)
    return done.returncode, done.stderr.splitlines()


def test_the_bundled_images_decode_without_library_warnings():
    # photo_towers.png carried an RGB ICC profile in a grey PNG: libpng printed "PNG warning:
    # iCCP: ... not permitted on grayscale PNG" on every read (the chunk is gone, the pixels
    # are the same).
    folder = resources.files("aarecovery") / "data"
    names = sorted(entry.name for entry in folder.iterdir() if entry.name.endswith((".png", ".jpg")))
    code = "import sys, aarecovery\nfor path in sys.argv[1:]:\n    aarecovery.read_image(path)\n"
    done = subprocess.run([sys.executable, "-c", code, *(str(folder / name) for name in names)],
                          capture_output=True, text=True, timeout=120)
    assert "photo_towers.png" in names
    assert done.returncode == 0 and done.stderr == "", done.stderr


def test_a_gl_driver_that_fails_to_load_says_so_in_our_line_only(tmp_path):
    # Mesa without a usable Gallium driver: its EGL printed "libEGL warning: egl: failed to
    # create dri2 screen" twice before our fallback warning.
    ramp = np.tile(np.linspace(0, 255, 32).astype(np.uint8), (24, 1))
    write_image(tmp_path / "o.png", ramp)
    write_image(tmp_path / "f.png", np.where(ramp > 127, 255, 0).astype(np.uint8))
    environment = {name: value for name, value in os.environ.items() if name != "EGL_LOG_LEVEL"}
    environment["GALLIUM_DRIVER"] = "no-such-driver"
    status, lines = _stderr_lines("recover", tmp_path / "o.png", tmp_path / "f.png", "-o", tmp_path / "r.png",
                                  env=environment)
    assert status == 0 and lines, lines
    assert all(line.startswith("aarecovery: ") for line in lines), lines
