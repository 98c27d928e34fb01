"""Fixtures for the viewer tests: a standalone EGL context, and a real X server (Xvfb).

Tests that need something this machine lacks never pass quietly: with the environment
variable CI set they fail and say what to install; elsewhere they skip with the reason.
"""

import os

import pytest
from xvfb import missing, xvfb_server


def require_viewer_extra():
    """Import glfw (first) and imgui_bundle, or fail/skip naming the extra."""
    try:
        import glfw  # noqa: F401
        import imgui_bundle  # noqa: F401
    except ImportError as error:
        missing(f"the viewer tests need the viewer extra ({error}): pip install -e '.[viewer]'")


@pytest.fixture(scope="module")
def egl_context():
    """A standalone OpenGL 3.3 core context made with EGL (no display needed)."""
    import moderngl
    try:
        context = moderngl.create_standalone_context(backend="egl", require=330)
    except Exception as error:  # glcontext raises plain Exceptions
        missing(f"no EGL OpenGL 3.3 context ({error}); install Mesa: apt-get install libegl1 libgl1-mesa-dri")
    yield context
    context.release()


@pytest.fixture(scope="session")
def xvfb_display():
    """Start Xvfb on a free display number for the session and point DISPLAY at it."""
    with xvfb_server() as display:
        previous = os.environ.get("DISPLAY")
        os.environ["DISPLAY"] = display
        yield display
        if previous is None:
            os.environ.pop("DISPLAY", None)
        else:
            os.environ["DISPLAY"] = previous


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
