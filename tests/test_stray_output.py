"""Everything the command line prints on stderr is its own one-line ``aarecovery:`` messages:
no warnings of the libraries below it (libpng, Mesa's EGL) beside them."""

import os
import subprocess
import sys
from importlib import resources

import numpy as np
from xvfb import xvfb_server

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


def _recover_with_a_broken_driver(folder, **variables):
    """stderr lines of ``recover`` where Mesa has no Gallium driver it can load, with our
    settings of the libraries' logging left to the command."""
    ramp = np.tile(np.linspace(0, 255, 32).astype(np.uint8), (24, 1))
    write_image(folder / "o.png", ramp)
    write_image(folder / "f.png", np.where(ramp > 127, 255, 0).astype(np.uint8))
    environment = {name: value for name, value in os.environ.items() if name not in ("EGL_LOG_LEVEL", "LIBGL_DEBUG")}
    environment.update(GALLIUM_DRIVER="no-such-driver", **variables)
    status, lines = _stderr_lines("recover", folder / "o.png", folder / "f.png", "-o", folder / "r.png",
                                  env=environment)
    assert status == 0 and lines, lines
    return lines


def test_a_gl_driver_that_fails_to_load_says_so_in_our_line_only(tmp_path):
    # Mesa without a usable Gallium driver: its EGL printed "libEGL warning: egl: failed to
    # create dri2 screen" twice before our fallback warning.
    lines = _recover_with_a_broken_driver(tmp_path)
    assert all(line.startswith("aarecovery: ") for line in lines), lines


def test_a_gl_driver_that_fails_to_load_beside_an_x_server_says_so_in_our_line_only(tmp_path):
    # Where EGL fails, the platform's default (GLX) is tried next, and where an X server
    # answers (a desktop, or any Xvfb on display :0 even without DISPLAY set) libGL printed
    # "libGL error: failed to load driver: swrast" and three more lines before ours.
    with xvfb_server("320x240x24") as display:
        lines = _recover_with_a_broken_driver(tmp_path, DISPLAY=display)
    assert all(line.startswith("aarecovery: ") for line in lines), lines
