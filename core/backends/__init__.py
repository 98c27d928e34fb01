"""Where the passes run: a registry of backends behind one protocol (``base.Backend``).

``numpy`` is the specification run on the CPU; ``gl`` runs the same passes as OpenGL
shaders. :func:`make_backend` picks one by name; ``auto`` prefers GL and falls back to
NumPy with a one-line warning when no OpenGL 3.3 context can be made.
"""

import warnings

from ..errors import BackendFallbackWarning, InputError
from ..params import check_backend, check_gl_path
from .base import Backend, Capabilities, Plan, RecoveryMaps
from .gl.context import GLUnavailable

__all__ = ["make_backend", "Backend", "Capabilities", "Plan", "RecoveryMaps", "GLUnavailable"]


def _numpy():
    from .numpy import NumpyBackend
    return NumpyBackend()


def _gl(context, gl_path):
    from .gl.backend import GLBackend
    return GLBackend(context, gl_path)


def make_backend(name="auto", context=None, gl_path="auto"):
    """A backend by name.

    Parameters
    ----------
    name : {"auto", "gl", "numpy"}
    context : moderngl.Context, optional
        A GL context to borrow (a viewer's window); only with ``"gl"`` or ``"auto"``.
    gl_path : {"auto", "fragment", "compute"}
        How the GL backend runs its passes (``aarecovery.params.GL_PATHS``); only
        ``"auto"`` with ``"numpy"``.

    Returns
    -------
    Backend

    Raises
    ------
    GLUnavailable
        With ``"gl"`` when no OpenGL 3.3 context can be made.
    InputError
        For ``gl_path="compute"`` where the context has no OpenGL 4.3.
    """
    check_backend(name)
    check_gl_path(gl_path)
    if name == "numpy":
        if context is not None:
            raise InputError("a GL context was passed with backend='numpy'; pass backend='gl' or drop the context")
        if gl_path != "auto":
            raise InputError(f"gl_path={gl_path!r} was passed with backend='numpy'; pass backend='gl' or drop "
                             "the gl_path")
        return _numpy()
    try:
        return _gl(context, gl_path)
    except GLUnavailable as error:
        if name == "gl":
            raise
        warnings.warn(f"no OpenGL 3.3 context ({error.reason}); using the NumPy backend (the same result "
                      "up to float rounding, slower)", BackendFallbackWarning, stacklevel=3)
        return _numpy()
