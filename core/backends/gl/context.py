"""Making a standalone OpenGL 3.3 context, or saying clearly why there is none."""

import moderngl

__all__ = ["GLUnavailable", "create_context", "REQUIRED_VERSION"]

REQUIRED_VERSION = 330


class GLUnavailable(RuntimeError):
    """No usable OpenGL 3.3 context could be created."""


def create_context():
    """Create a headless OpenGL 3.3+ context.

    EGL comes first: it needs no display and is what Mesa (llvmpipe) and the NVIDIA driver
    offer on servers. The platform default (WGL, CGL, GLX) is the fallback for desktops.

    Returns
    -------
    moderngl.Context

    Raises
    ------
    GLUnavailable
        With every attempt's reason in the message.
    """
    reasons = []
    for options in ({"backend": "egl"}, {}):
        try:
            return moderngl.create_standalone_context(require=REQUIRED_VERSION, **options)
        except Exception as error:  # the context libraries raise bare Exception subclasses
            label = options.get("backend", "default")
            reasons.append(f"{label}: {str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__}")
    raise GLUnavailable("; ".join(reasons))
