"""Test options shared by the whole suite.

``--backend numpy|gl|all`` picks which backends the backend-parametrised tests run on
(kornia-style: every such test body runs once per backend), and ``--gl-path
fragment|compute|all`` which GL paths the tests taking ``gl_path`` run on (module-scoped,
so that a module's engine is made once per path), and ``--parity-cases N`` / ``--parity-seed
S`` how many random GL/NumPy cases ``test_gl_fuzz.py`` draws and from which seed. GL tests never skip quietly: when no
OpenGL context can be made they fail in CI (CI=true) and skip loudly elsewhere.
"""

import os

import pytest

BACKEND_NAMES = ("numpy", "gl")
GL_PATH_NAMES = ("fragment", "compute")


def pytest_addoption(parser):
    parser.addoption("--backend", default="all", choices=("all",) + BACKEND_NAMES,
                     help="run backend-parametrised tests on this backend only (default: all)")
    parser.addoption("--gl-path", default="all", choices=("all",) + GL_PATH_NAMES,
                     help="run GL-path-parametrised tests on this path only (default: all)")
    parser.addoption("--parity-cases", type=int, default=int(os.environ.get("AARECOVERY_PARITY_CASES", 24)),
                     help="random cases of tests/test_gl_fuzz.py per GL path (default: 24, or "
                          "$AARECOVERY_PARITY_CASES)")
    parser.addoption("--parity-seed", type=int, default=0, help="the first seed of tests/test_gl_fuzz.py's cases")


def pytest_generate_tests(metafunc):
    if "backend" in metafunc.fixturenames:
        chosen = metafunc.config.getoption("--backend")
        names = BACKEND_NAMES if chosen == "all" else (chosen,)
        metafunc.parametrize("backend", names)
    if "gl_path" in metafunc.fixturenames:
        chosen = metafunc.config.getoption("--gl-path")
        metafunc.parametrize("gl_path", GL_PATH_NAMES if chosen == "all" else (chosen,), scope="module")


_gl_problem = None


def gl_unavailable_reason():
    """None when a standalone GL 3.3 context can be made here, else why not."""
    global _gl_problem
    if _gl_problem is None:
        from aarecovery.backends.gl.context import GLUnavailable, create_context
        try:
            create_context().release()
            _gl_problem = ""
        except GLUnavailable as error:
            _gl_problem = str(error)
    return _gl_problem or None


def require_gl():
    reason = gl_unavailable_reason()
    if reason:
        message = (f"no OpenGL 3.3 context ({reason}); install Mesa's EGL and llvmpipe: "
                   "apt-get install libegl1 libgl1-mesa-dri (packaging/test.sh does)")
        if os.environ.get("CI"):
            pytest.fail(message)
        pytest.skip("GL TESTS NOT RUN: " + message)


@pytest.fixture(autouse=True)
def _gl_needed(request):
    params = getattr(request.node, "callspec", None) and request.node.callspec.params or {}
    if request.node.get_closest_marker("gl") or params.get("backend") == "gl" or "gl_path" in params:
        require_gl()
