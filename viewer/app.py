"""The viewer application: the window and its frame loop, driving the parts of the viewer.

:meth:`ViewerApp.step` renders one frame, in this order:

1. poll GLFW, whose callbacks feed ImGui (``glfw_platform``);
2. build the widgets (``ui``), which edit the panel's state (``panel_state``), the settings
   and the comparison (``comparison``), and call the file actions (``opening``, ``saving``);
3. apply mouse and keys to the view (``view_input``);
4. re-run the recovery if the settings changed (``live_recovery``);
5. draw the engine's textures (``image_view``) and the widgets (``imgui_renderer``).

:meth:`ViewerApp.run` repeats it, sleeping while nothing happens.
"""

import time

import glfw  # before imgui_bundle: see glfw_platform
import numpy as np
from imgui_bundle import imgui

import aarecovery

from . import ui
from .comparison import Comparison
from .file_dialogs import NativeFileDialogs
from .glfw_platform import GlfwPlatform
from .image_view import ImageView
from .imgui_renderer import ImGuiRenderer
from .live_recovery import LiveRecovery
from .messages import MessageLog
from .opening import PairOpener
from .panel_state import PanelState
from .saving import SaveActions
from .view_input import ViewInput
from .view_state import ViewState
from .window import WindowError, close_window, open_window

__all__ = ["ViewerApp", "WindowError"]

# Frames drawn after the last input event before the loop sleeps: ImGui settles hover and
# click states over a couple of frames.
_SETTLE_FRAMES = 3
# Longest sleep between frames while idle (a native dialog or a fading message is polled).
_IDLE_WAIT = 0.25
# Clear colour of the window (RGBA), behind the panel and around the image.
_BACKGROUND = (0.11, 0.11, 0.12, 1.0)


class ViewerApp:
    """The viewer window.

    Parameters
    ----------
    source : PairSource, optional
        The pair to open; None opens an empty window (files can be opened from it).
    settings : RecoverySettings, optional
        Initial parameters; the defaults by default.
    size : tuple of int
        Window size in screen units.
    visible : bool
        False for an off-screen window (still a real window and framebuffer).
    vsync : bool
        Wait for the display's refresh on each swap (off for --bench).

    Attributes
    ----------
    window, context
        The GLFW window and its moderngl context.
    engine : aarecovery.Engine
        The GL engine, in the window's context.
    recovery : LiveRecovery
        The settings, the shown pair and the R computed from them.
    comparison : Comparison
        The view (R, F, O, split, heat-map, maps), flicker, what R is compared with.
    view : ViewState
        Zoom, pan and the divider.
    panel : PanelState
        The panel's fields and pending questions.
    opener : PairOpener
    saving : SaveActions
    messages : MessageLog
    widget_rects : dict
        Where some widgets were drawn last frame (window units), for --bench and tests.

    Raises
    ------
    WindowError
        When GLFW cannot start or make an OpenGL 3.3 core window (no display, old driver).
    """

    def __init__(self, source=None, *, settings=None, size=(1280, 720), visible=True, vsync=True,
                 title="aarecovery view"):
        self.window, self.context = open_window(size, visible=visible, vsync=vsync, title=title)
        self._imgui_context = imgui.create_context()
        imgui.get_io().set_ini_filename(None)  # no imgui.ini in the user's folder
        scale = max(glfw.get_window_content_scale(self.window))
        imgui.get_style().font_scale_dpi = scale
        self.panel_base_width = ui.PANEL_WIDTH * scale
        self.renderer = ImGuiRenderer(self.context)
        self.image_view = ImageView(self.context)
        self.engine = aarecovery.Engine(backend="gl", context=self.context)

        self.messages = MessageLog()
        self.view = ViewState()
        self.comparison = Comparison()
        self.panel = PanelState()
        self.dialogs = NativeFileDialogs()
        self.recovery = LiveRecovery(self.engine, self.messages, lambda: self.comparison.needs_maps, settings)
        self.opener = PairOpener(self.panel, self.recovery, self.view, self.messages,
                                 lambda: self.image_area()[0][2:])
        self.saving = SaveActions(self.panel, self.recovery, self.messages, imgui.set_clipboard_text)
        self.platform = GlfwPlatform(self.window, on_drop=self.opener.handle_drop)
        self.input = ViewInput()
        self.widget_rects = {}

        self._seen_input = -1
        self._seen_messages = 0
        self._busy_frames = _SETTLE_FRAMES
        self.frame_count = 0
        self.frame_seconds = None
        self.last_screenshot = None
        self.should_close = False

        if source is not None:
            self.opener.open(source)

    # ================================================================== layout
    @property
    def panel_width(self):
        """Width of the side panel in window units (0 when hidden)."""
        return self.panel_base_width if self.panel.visible else 0.0

    def image_area(self):
        """The image area in framebuffer pixels ``(x, y_bottom_up, width, height)`` and the scale."""
        fb_width, fb_height = self.platform.framebuffer_size
        scale = self.platform.framebuffer_scale
        left = int(round(self.panel_width * scale))
        return (left, 0, max(1, fb_width - left), max(1, fb_height)), scale

    # ================================================================== frames
    def step(self, capture=False):
        """Poll input and render one frame.

        Parameters
        ----------
        capture : bool
            Also read the finished frame into :attr:`last_screenshot` (RGB uint8, row 0 at
            the top) before it is presented.

        Returns
        -------
        bool
            False once the window should close.
        """
        start = time.perf_counter()
        glfw.poll_events()
        self.dialogs.poll(self.panel)
        now = time.perf_counter()
        self.messages.expire(now)
        self.comparison.tick(now)
        self.recovery.refresh_summary(now)

        self.platform.new_frame()
        imgui.new_frame()
        area, scale = self.image_area()
        self.view.set_view_size(area[2], area[3])
        ui.draw_ui(self)
        self.input.handle_mouse(self.view, self.comparison, area, scale)
        self.input.handle_keys(self, area)
        area, scale = self.image_area()  # Tab may have hidden the panel
        self.view.set_view_size(area[2], area[3])
        self.recovery.update()
        ui.draw_divider(self, area, scale)
        self.platform.update_cursor()
        imgui.render()

        screen = self.context.screen
        screen.use()
        self.context.viewport = (0, 0, *self.platform.framebuffer_size)
        self.context.clear(*_BACKGROUND)
        if self.recovery.pair is not None:
            self.image_view.draw(area, self.view, *self.comparison.layers(self.engine.texture,
                                                                          self.recovery.settings))
        self.renderer.render(imgui.get_draw_data(), screen)
        if capture:
            self.last_screenshot = self.screenshot()
        glfw.swap_buffers(self.window)
        self.frame_count += 1
        self.frame_seconds = time.perf_counter() - start
        return not (self.should_close or glfw.window_should_close(self.window))

    def screenshot(self):
        """The window's current back buffer as RGB uint8 ``(H, W, 3)``, row 0 at the top."""
        width, height = self.platform.framebuffer_size
        data = self.context.screen.read(viewport=(0, 0, width, height), components=3, alignment=1)
        return np.frombuffer(data, np.uint8).reshape(height, width, 3)[::-1].copy()

    def _idle(self):
        """True when nothing would change on screen without new input."""
        if (self.platform.input_serial, self.messages.serial) != (self._seen_input, self._seen_messages):
            self._seen_input, self._seen_messages = self.platform.input_serial, self.messages.serial
            self._busy_frames = _SETTLE_FRAMES
        if self._busy_frames > 0:
            self._busy_frames -= 1
            return False
        return not (self.comparison.auto_flicker or self.input.drag is not None)

    def run(self):
        """Show the window until it is closed; sleeps while nothing changes."""
        while True:
            if self._idle():
                wait = self.comparison.flicker_period if self.comparison.auto_flicker else _IDLE_WAIT
                glfw.wait_events_timeout(wait if (self.dialogs.is_open or self.messages) else 1.0)
            if not self.step():
                break

    def close(self):
        """Free the engine, GL objects, ImGui and the window."""
        self.engine.release()
        self.image_view.release()
        self.renderer.release()
        self.platform.release()
        imgui.destroy_context(self._imgui_context)
        close_window(self.window, self.context)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
