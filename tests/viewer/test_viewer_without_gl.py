"""``aarecovery view`` where the display offers no OpenGL 3.3: one line, no GLFW warning trace."""

import os
import subprocess
import sys

from conftest import require_viewer_extra


def test_view_without_gl_33_says_so_in_one_line(xvfb_display, image_pair, tmp_path):
    require_viewer_extra()
    # Mesa then offers OpenGL 3.0 on the X display, as an old driver would.
    env = {**os.environ, "MESA_GL_VERSION_OVERRIDE": "3.0"}
    for extra in (["--screenshot", str(tmp_path / "shot.png")], ["--bench", "--bench-size", "64x48"]):
        done = subprocess.run([sys.executable, "-m", "aarecovery", "view", *image_pair, *extra],
                              capture_output=True, text=True, timeout=120, env=env)
        assert done.returncode == 1
        lines = done.stderr.splitlines()
        assert len(lines) == 1 and lines[0].startswith("aarecovery: error: ") and "OpenGL 3.3" in lines[0], done.stderr
    assert not (tmp_path / "shot.png").exists()
