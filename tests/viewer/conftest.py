"""Fixtures for the viewer tests: a standalone EGL context, and a real X server (Xvfb).

Tests that need something this machine lacks never pass quietly: with the environment
variable CI set they fail and say what to install; elsewhere they skip with the reason.
"""

import os
import shutil
import subprocess

import pytest


def _missing(reason):
    if os.environ.get("CI"):
        pytest.fail(reason, pytrace=False)
    pytest.skip(reason)


def require_viewer_extra():
    """Import glfw (first) and imgui_bundle, or fail/skip naming the extra."""
    try:
        import glfw  # noqa: F401
        import imgui_bundle  # noqa: F401
    except ImportError as error:
        _missing(f"the viewer tests need the viewer extra ({error}): pip install -e '.[viewer]'")


@pytest.fixture(scope="module")
def egl_context():
    """A standalone OpenGL 3.3 core context made with EGL (no display needed)."""
    import moderngl
    try:
        context = moderngl.create_standalone_context(backend="egl", require=330)
    except Exception as error:  # glcontext raises plain Exceptions
        _missing(f"no EGL OpenGL 3.3 context ({error}); install Mesa: apt-get install libegl1 libgl1-mesa-dri")
    yield context
    context.release()


@pytest.fixture(scope="session")
def xvfb_display():
    """Start Xvfb on a free display number for the session and point DISPLAY at it."""
    executable = shutil.which("Xvfb")
    if executable is None:
        _missing("Xvfb is not installed: apt-get install xvfb")
    read_end, write_end = os.pipe()
    # -displayfd: Xvfb picks a free display number and writes it to the pipe once it is ready.
    # -noreset: an X server resets when its last client leaves, and a test connecting during
    # that reset failed with "Failed to open display" (seen in about one run in three).
    server = subprocess.Popen([executable, "-displayfd", str(write_end), "-screen", "0", "1400x900x24",
                               "-nolisten", "tcp", "-noreset"], pass_fds=(write_end,), stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
    os.close(write_end)
    with os.fdopen(read_end) as pipe:
        number = pipe.readline().strip()
    if not number:
        server.kill()
        pytest.fail("Xvfb started but reported no display number")
    previous = os.environ.get("DISPLAY")
    os.environ["DISPLAY"] = f":{number}"
    yield os.environ["DISPLAY"]
    if previous is None:
        os.environ.pop("DISPLAY", None)
    else:
        os.environ["DISPLAY"] = previous
    server.terminate()
    server.wait(timeout=10)


@pytest.fixture
def image_pair(tmp_path):
    """A small antialiased pair on disk: paths of ORIGINAL and FILTERED (96x64 RGB PNGs)."""
    from aarecovery import write_image
    from aarecovery.viewer.bench import make_bench_pair
    original, filtered = make_bench_pair(96, 64)
    paths = tmp_path / "original.png", tmp_path / "filtered.png"
    write_image(paths[0], original)
    write_image(paths[1], filtered)
    return str(paths[0]), str(paths[1])
