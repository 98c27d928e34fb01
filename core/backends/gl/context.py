"""Making a standalone OpenGL 3.3 context, or saying clearly why there is none."""

import os
import sys
from contextlib import contextmanager, nullcontext

import moderngl

from ...errors import InputError

__all__ = ["GLUnavailable", "create_context", "REQUIRED_VERSION", "COMPUTE_VERSION"]

REQUIRED_VERSION = 330
#: The first GL version with compute shaders, storage buffers and indirect dispatch.
COMPUTE_VERSION = 430


class GLUnavailable(InputError, RuntimeError):
    """No usable OpenGL 3.3 context could be created.

    An :class:`~aarecovery.InputError` (the backend asked for cannot be used here), so that
    every interface shows it as its one-line error; `reason` holds the drivers' own words.
    """

    def __init__(self, reason):
        super().__init__(f"no OpenGL 3.3 context here ({reason}); use the NumPy backend (--backend numpy, "
                         "backend='numpy': the same result up to float rounding, slower), or install an OpenGL 3.3 driver "
                         "(Debian and Ubuntu: apt-get install libegl1 libgl1-mesa-dri)")
        self.reason = reason


def create_context():
    """Create a headless OpenGL context: 4.3 where the driver offers it, else 3.3.

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
    # Mesa's EGL prints its warnings (a driver it could not load, a screen it could not
    # make) straight to stderr, beside our one-line messages; the reasons that matter come
    # back in the exception. A level the user set is kept.
    os.environ.setdefault("EGL_LOG_LEVEL", "fatal")
    reasons = []
    for options in ({"backend": "egl"}, {}):
        label = options.get("backend", "default")
        # GL 4.3 first, for the compute path: NVIDIA's EGL makes exactly the version asked
        # for (a request for 3.3 gave an H100 a 3.3 context and so only the fragment path,
        # 0.11-0.15 GP/s), where Mesa makes its newest either way.
        for version in (COMPUTE_VERSION, REQUIRED_VERSION):
            # Where EGL failed, the platform's default follows: on Linux GLX, whose libGL
            # prints "libGL error: failed to load driver" as a fatal message, which no
            # variable quiets, wherever an X server answers (any on display :0, DISPLAY set
            # or not). Its reasons come back in the exception too.
            with _stderr_discarded() if label == "default" else nullcontext():
                try:
                    return moderngl.create_standalone_context(require=version, **options)
                except Exception as error:  # the context libraries raise bare Exception subclasses
                    text = str(error).strip()
                    reasons.append(f"{label} {version // 100}.{version // 10 % 10}: "
                                   f"{text.splitlines()[0] if text else type(error).__name__}")
    raise GLUnavailable("; ".join(reasons))


@contextmanager
def _stderr_discarded():
    """Send what C libraries write to file descriptor 2 to the null device inside the block."""
    try:
        sys.stderr.flush()
        saved = os.dup(2)
    except (OSError, ValueError, AttributeError):  # no descriptor 2 (a GUI host without one)
        yield
        return
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(null)
