"""The window: GLFW with one OpenGL 3.3 core context, shared by the engine, the image view and ImGui."""

import warnings

import glfw  # before imgui_bundle: see glfw_platform
import moderngl

__all__ = ["WindowError", "open_window", "close_window"]


class WindowError(RuntimeError):
    """No window with an OpenGL 3.3 core context could be opened."""


def _glfw_error_text():
    code, description = glfw.get_error()
    if not code:
        return "no reason given"
    return description.decode("utf-8", "replace") if isinstance(description, bytes) else str(description)


def open_window(size, *, visible=True, vsync=True, title="aarecovery view"):
    """Open a window and wrap its OpenGL core context (4.3 where the driver offers it, else 3.3) for moderngl.

    Parameters
    ----------
    size : tuple of int
        ``(width, height)`` in screen units.
    visible : bool
        False for an off-screen window (still a real window and framebuffer).
    vsync : bool
        Wait for the display's refresh on each swap.
    title : str

    Returns
    -------
    window : glfw window handle
    context : moderngl.Context
        The window's context, current on this thread.

    Raises
    ------
    WindowError
        When GLFW cannot start or make an OpenGL 3.3 core window (no display, old driver).
    """
    with warnings.catch_warnings():
        # GLFW's own warning repeats the reason that the one-line error below gives.
        warnings.simplefilter("ignore", glfw.GLFWError)
        started = glfw.init()
    if not started:
        raise WindowError(f"cannot start GLFW ({_glfw_error_text()}); "
                          "is there a display (DISPLAY or WAYLAND_DISPLAY)?")
    glfw.window_hint(glfw.OPENGL_PROFILE, glfw.OPENGL_CORE_PROFILE)
    glfw.window_hint(glfw.OPENGL_FORWARD_COMPAT, True)  # required for 3.3 core on macOS
    glfw.window_hint(glfw.SCALE_TO_MONITOR, True)
    glfw.window_hint(glfw.VISIBLE, bool(visible))
    window = None
    # 4.3 first, for the engine's compute path: NVIDIA's drivers make exactly the version
    # asked for (an H100 asked for 3.3 through EGL got 3.3); macOS stops at 4.1.
    for major, minor in ((4, 3), (3, 3)):
        glfw.window_hint(glfw.CONTEXT_VERSION_MAJOR, major)
        glfw.window_hint(glfw.CONTEXT_VERSION_MINOR, minor)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", glfw.GLFWError)
            window = glfw.create_window(int(size[0]), int(size[1]), title, None, None)
        if window:
            break
    if not window:
        reason = _glfw_error_text()
        glfw.terminate()
        raise WindowError(f"cannot open a window with OpenGL 3.3 core ({reason})")
    glfw.make_context_current(window)
    glfw.swap_interval(1 if vsync else 0)
    return window, moderngl.create_context(require=330)


def close_window(window, context):
    """Release the context, destroy the window and stop GLFW."""
    context.release()
    glfw.destroy_window(window)
    glfw.terminate()
