"""Where the passes run: a registry of backends behind one protocol (``base.Backend``).

``numpy`` is the specification run on the CPU; ``gl`` runs the same passes as OpenGL
shaders. :func:`make_backend` picks one by name; ``auto`` prefers GL and falls back to
NumPy with a one-line warning when no OpenGL 3.3 context can be made.
"""

import warnings

from ..errors import BackendFallbackWarning, InputError
from ..params import check_backend
from .base import Backend, Capabilities, Plan, RecoveryMaps
from .gl.context import GLUnavailable

__all__ = ["make_backend", "Backend", "Capabilities", "Plan", "RecoveryMaps", "GLUnavailable"]


def _numpy():
    from .numpy import NumpyBackend
    return NumpyBackend()


def _gl(context):
    from .gl.backend import GLBackend
    return GLBackend(context)


def make_backend(name="auto", context=None):
    """A backend by name.

    Parameters
    ----------
    name : {"auto", "gl", "numpy"}
    context : moderngl.Context, optional
        A GL context to borrow (a viewer's window); only with ``"gl"`` or ``"auto"``.

    Returns
    -------
    Backend

    Raises
    ------
    GLUnavailable
        With ``"gl"`` when no OpenGL 3.3 context can be made.
    """
    check_backend(name)
    if name == "numpy":
        if context is not None:
            raise InputError("a GL context was passed with backend='numpy'; pass backend='gl' or drop the context")
        return _numpy()
    try:
        return _gl(context)
    except GLUnavailable as error:
        if name == "gl":
            raise
        warnings.warn(f"no OpenGL 3.3 context ({error.reason}); using the NumPy backend (the same result, "
                      "slower)", BackendFallbackWarning, stacklevel=3)
        return _numpy()
