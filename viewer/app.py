"""The viewer application: one GLFW window, one GL context shared by the engine and the UI.

:meth:`ViewerApp.step` renders one frame: it polls GLFW (whose callbacks feed ImGui), builds
the UI, applies mouse and keys to the view, re-runs the recovery when a parameter changed,
and draws the engine's textures and the widgets. :meth:`ViewerApp.run` repeats it, sleeping
while nothing happens.
"""

import os
import shutil
import sys
import time
import warnings
from dataclasses import dataclass

import glfw  # before imgui_bundle: see glfw_platform
import moderngl
import numpy as np
from imgui_bundle import imgui

import aarecovery

from . import ui
from .glfw_platform import GlfwPlatform
from .image_view import ImageView, Layer
from .imgui_renderer import ImGuiRenderer
from .keys import VIEW_MODES
from .saving import default_output_path, overwrite_question, save_result
from .settings import RecoverySettings, command_line
from .sources import SAMPLE_FILTER, PairSource, filter_names, filter_parameters, load_pair, sample_path
from .view_state import ViewState

__all__ = ["ViewerApp", "WindowError", "Message"]

# Frames drawn after the last input event before the loop sleeps: ImGui settles hover and
# click states over a couple of frames.
_SETTLE_FRAMES = 3
# Longest sleep between frames while idle (a native dialog or a fading message is polled).
_IDLE_WAIT = 0.25
# Information messages disappear after this many seconds; errors stay until dismissed.
_INFO_SECONDS = 5.0
# How close to the divider (window units) a press grabs it instead of panning.
_DIVIDER_GRAB = 6.0
_MAP_VIEWS = ("alpha", "beta", "edge_strength", "residual")


class WindowError(RuntimeError):
    """No window with an OpenGL 3.3 core context could be opened."""


@dataclass(frozen=True)
class Message:
    """A line shown over the image: an error (red, stays) or information (fades)."""

    text: str
    error: bool
    shown_at: float


def _glfw_error_text():
    code, description = glfw.get_error()
    if not code:
        return "no reason given"
    return description.decode("utf-8", "replace") if isinstance(description, bytes) else str(description)


class ViewerApp:
    """The viewer window.

    Parameters
    ----------
    source : PairSource, optional
        The pair to open; None opens an empty window (files can be opened from it).
    settings : RecoverySettings, optional
        Initial parameters; the paper's by default.
    size : tuple of int
        Window size in screen units.
    visible : bool
        False for an off-screen window (still a real window and framebuffer).
    vsync : bool
        Wait for the display's refresh on each swap (off for --bench).

    Raises
    ------
    WindowError
        When GLFW cannot start or make an OpenGL 3.3 core window (no display, old driver).
    """

    def __init__(self, source=None, *, settings=None, size=(1280, 720), visible=True, vsync=True,
                 title="aarecovery view"):
        with warnings.catch_warnings():
            # GLFW's own warning repeats the reason that the one-line error below gives.
            warnings.simplefilter("ignore", glfw.GLFWError)
            started = glfw.init()
        if not started:
            raise WindowError(f"cannot start GLFW ({_glfw_error_text()}); "
                              "is there a display (DISPLAY or WAYLAND_DISPLAY)?")
        glfw.window_hint(glfw.CONTEXT_VERSION_MAJOR, 3)
        glfw.window_hint(glfw.CONTEXT_VERSION_MINOR, 3)
        glfw.window_hint(glfw.OPENGL_PROFILE, glfw.OPENGL_CORE_PROFILE)
        glfw.window_hint(glfw.OPENGL_FORWARD_COMPAT, True)  # required for 3.3 core on macOS
        glfw.window_hint(glfw.SCALE_TO_MONITOR, True)
        glfw.window_hint(glfw.VISIBLE, bool(visible))
        self.window = glfw.create_window(int(size[0]), int(size[1]), title, None, None)
        if not self.window:
            reason = _glfw_error_text()
            glfw.terminate()
            raise WindowError(f"cannot open a window with OpenGL 3.3 core ({reason})")
        glfw.make_context_current(self.window)
        glfw.swap_interval(1 if vsync else 0)
        self.context = moderngl.create_context(require=330)

        self._imgui_context = imgui.create_context()
        io = imgui.get_io()
        io.set_ini_filename(None)  # no imgui.ini in the user's folder
        scale = max(glfw.get_window_content_scale(self.window))
        imgui.get_style().font_scale_dpi = scale
        self.panel_base_width = ui.PANEL_WIDTH * scale
        self.platform = GlfwPlatform(self.window, on_drop=self.handle_drop)
        self.renderer = ImGuiRenderer(self.context)
        self.image_view = ImageView(self.context)
        self.engine = aarecovery.Engine(backend="gl", context=self.context)

        self.view = ViewState()
        self.settings = settings or RecoverySettings.defaults()
        self.computed = None          # (settings, with maps) of the R in the engine's textures
        self.pair = None              # LoadedPair shown
        self.order = None             # aarecovery.check_order's verdict on the pair shown
        self.view_mode = "result"
        self.compare_with = "filtered"
        self.swapped = False          # flicker state: show the comparison image instead of R
        self.auto_flicker = False
        self.flicker_period = 0.5
        self._flicker_time = time.perf_counter()
        self.difference_gain = 4.0
        self.panel_visible = True
        self.help_visible = False
        self.messages = []
        self.widget_rects = {}

        self.original_field = ""
        self.filtered_field = ""
        self.use_builtin_filter = False
        self.filter_field = SAMPLE_FILTER if SAMPLE_FILTER in filter_names() else (filter_names() or [None])[0]
        self.filter_params_field = {}
        self.save_field = ""
        self.open_save_dialog = False
        self.pending_overwrite = None  # (path, question) awaiting confirmation
        self.pending_drop = None       # a single dropped path awaiting "use as"
        self.native_dialogs = _native_dialogs_available()
        self._dialog = None            # (role, portable_file_dialogs object)

        self._drag = None              # "pan" or "divider" while a mouse button drags
        self._wheel = 0.0              # wheel distance not yet turned into zoom steps
        self._seen_input = -1
        self._busy_frames = _SETTLE_FRAMES
        self.frame_count = 0
        self.frame_seconds = None
        self.recoveries = 0
        self.last_screenshot = None
        self.should_close = False

        if source is not None:
            self.open(source)

    # ================================================================== images
    @property
    def panel_width(self):
        """Width of the side panel in window units (0 when hidden)."""
        return self.panel_base_width if self.panel_visible else 0.0

    def open(self, source):
        """Load a pair; on bad input show the message and keep what was shown.

        Returns
        -------
        bool
            True when the pair was loaded.
        """
        try:
            pair = load_pair(source)
            self.engine.set_images(pair.original, pair.filtered)
        except (aarecovery.InputError, OSError) as error:
            self.show_error(str(error))
            if self.pair is not None:
                # The engine may have dropped its images on the way; put the shown pair back.
                self._reload_shown_pair()
            return False
        self.pair = pair
        self.computed = None
        area, _ = self._area()
        self.view.set_view_size(area[2], area[3])
        self.view.set_image_size(*pair.size)
        self.original_field = source.original
        self.filtered_field = source.filtered or ""
        self.use_builtin_filter = not source.filtered
        if not source.filtered:
            self.filter_field = source.filter_name
            self.filter_params_field = dict(source.filter_params)
        self.save_field = default_output_path(source)
        self.messages = [m for m in self.messages if not m.error]
        self.show_info(f"opened {os.path.basename(source.original)} and {source.describe_filtered()} "
                       f"({pair.size[0]}x{pair.size[1]})")
        self.order = aarecovery.check_order(pair.original, pair.filtered)
        if self.order.looks_reversed:
            self.show_error(self.order.reason)
        return True

    def _reload_shown_pair(self):
        try:
            self.engine.set_images(self.pair.original, self.pair.filtered)
        except aarecovery.InputError as error:  # the pair loaded before, so this is unexpected
            self.show_error(f"could not restore the previous images: {error}")
            self.pair = None
        self.computed = None

    def open_fields(self):
        """Open what the panel's fields name (the Open button, Ctrl+O)."""
        original = self.original_field.strip()
        if not original:
            self.show_error("type the ORIGINAL image's path in the panel (or drop files on the window)")
            return False
        if self.use_builtin_filter:
            source = PairSource(original, None, self.filter_field, self._filter_params())
        else:
            filtered = self.filtered_field.strip()
            if not filtered:
                self.show_error("type the FILTERED image's path, or choose a built-in filter")
                return False
            source = PairSource(original, filtered)
        return self.open(source)

    def _filter_params(self):
        known = {name for name, *_ in filter_parameters(self.filter_field)}
        return {key: value for key, value in self.filter_params_field.items() if key in known}

    def choose_filter(self, name):
        """Pick a built-in filter for F (its parameters start at their defaults)."""
        self.filter_field = name
        self.filter_params_field = {}
        if self.original_field.strip():
            self.open_fields()

    def handle_drop(self, paths):
        """Files dropped on the window: two are ORIGINAL and FILTERED, one asks which it is."""
        if len(paths) >= 2:
            if len(paths) > 2:
                self.show_info(f"{len(paths)} files dropped; using the first two as ORIGINAL and FILTERED")
            self.open(PairSource(paths[0], paths[1]))
        elif paths:
            self.pending_drop = paths[0]

    def use_dropped_as(self, role):
        """Use the single dropped file as the ``"original"`` or the ``"filtered"`` image."""
        path, self.pending_drop = self.pending_drop, None
        if path is None:
            return False
        if role == "original":
            self.original_field = path
            if not self.use_builtin_filter and not self.filtered_field:
                self.use_builtin_filter = bool(filter_names())
        else:
            self.filtered_field = path
            self.use_builtin_filter = False
        if self.original_field and (self.use_builtin_filter or self.filtered_field):
            return self.open_fields()
        return False

    # ================================================================== messages
    def show_error(self, text):
        """Show an error over the image (it stays until dismissed or a pair opens)."""
        self.messages.append(Message(text, True, time.perf_counter()))
        self._busy_frames = _SETTLE_FRAMES

    def show_info(self, text):
        """Show a passing note over the image."""
        self.messages.append(Message(text, False, time.perf_counter()))
        self._busy_frames = _SETTLE_FRAMES

    def dismiss_message(self, message):
        """Remove one message."""
        if message in self.messages:
            self.messages.remove(message)

    def _expire_messages(self, now):
        self.messages = [m for m in self.messages if m.error or now - m.shown_at < _INFO_SECONDS]

    # ================================================================== actions
    def set_view_mode(self, mode):
        """Show one of :data:`~aarecovery.viewer.keys.VIEW_MODES` (by name)."""
        self.view_mode = mode
        self.swapped = False

    def flicker(self):
        """Swap R and the comparison image in place (split view: swap the sides)."""
        self.swapped = not self.swapped

    def start_save(self):
        """Open the save dialog (Ctrl+S)."""
        if self.pair is None:
            self.show_error("nothing to save: open an image pair first")
            return
        self.open_save_dialog = True

    def request_save(self, path):
        """Save R to `path`, first asking if that replaces a file (an input most of all)."""
        path = os.path.expanduser(path.strip())
        if not path:
            self.show_error("give a file name to save R to")
            return False
        question = overwrite_question(path, self.pair.source if self.pair else None)
        if question is not None:
            self.pending_overwrite = (path, question)
            return False
        return self._save(path, overwrite=False)

    def confirm_overwrite(self):
        """The user confirmed replacing the file of the pending save."""
        if self.pending_overwrite is None:
            return False
        path, self.pending_overwrite = self.pending_overwrite[0], None
        return self._save(path, overwrite=True)

    def _save(self, path, overwrite):
        try:
            self._recompute_if_needed()
            save_result(self.engine, path, overwrite=overwrite)
        except (aarecovery.InputError, OSError) as error:
            self.show_error(f"not saved: {error}")
            return False
        self.show_info(f"saved R to {path}")
        return True

    def command_line(self):
        """The shell command that reproduces the shown R, or None without a pair."""
        if self.pair is None:
            return None
        output = self.save_field.strip() or default_output_path(self.pair.source)
        return command_line(self.pair.source, self.settings, output)

    def copy_command_line(self):
        """Put :meth:`command_line` on the clipboard."""
        text = self.command_line()
        if text is None:
            self.show_error("open an image pair first")
            return
        imgui.set_clipboard_text(text)
        self.show_info("command line copied to the clipboard")

    def browse(self, role):
        """Open a native file dialog for ``"original"``, ``"filtered"`` or ``"save"``."""
        from imgui_bundle import portable_file_dialogs as pfd
        if self._dialog is not None:
            return
        images = ["Images", "*.png *.tif *.tiff *.jpg *.jpeg *.webp *.bmp *.npy", "All files", "*"]
        if role == "save":
            dialog = pfd.save_file("Save R", self.save_field, images)
        else:
            start = self.original_field or os.getcwd()
            dialog = pfd.open_file(f"Open {role.upper()}", os.path.dirname(start) or ".", images)
        self._dialog = (role, dialog)

    def _poll_dialog(self):
        if self._dialog is None or not self._dialog[1].ready(0):
            return
        role, dialog = self._dialog
        self._dialog = None
        result = dialog.result()
        chosen = result[0] if isinstance(result, list) and result else result if isinstance(result, str) else ""
        if not chosen:
            return
        if role == "save":
            self.save_field = chosen
        elif role == "original":
            self.original_field = chosen
        else:
            self.filtered_field = chosen
            self.use_builtin_filter = False

    # ================================================================== recovery
    def _needs_maps(self):
        return self.view_mode in _MAP_VIEWS

    def _recompute_if_needed(self):
        """Run the recovery if the parameters (or the need for maps) changed since the last run."""
        if self.pair is None:
            return False
        maps = self._needs_maps()
        if self.computed is not None and self.computed[0] == self.settings and (self.computed[1] or not maps):
            return False
        try:
            self.engine.compute(maps=maps, **self.settings.compute_arguments())
        except aarecovery.InputError as error:
            self.show_error(str(error))
            self.settings = self.computed[0] if self.computed else RecoverySettings.defaults()
            return False
        self.computed = (self.settings, maps)
        self.recoveries += 1
        return True

    def _layers(self):
        """The layers the view draws now: ``(left, right or None)``."""
        texture = self.engine.texture
        result = texture("result")
        compare = texture(self.compare_with)
        mode = self.view_mode
        if mode == "result":
            return Layer.colour(compare if self.swapped else result), None
        if mode in ("filtered", "original"):
            return Layer.colour(result if self.swapped else texture(mode)), None
        if mode == "split":
            left, right = (result, compare) if self.swapped else (compare, result)
            return Layer.colour(left), Layer.colour(right)
        if mode == "difference":
            return Layer.difference(result, texture("filtered"), self.difference_gain), None
        gain = {"alpha": 1.0, "beta": 1.0, "edge_strength": 1.0 / (3.0 * self.settings.sigma_e),
                "residual": 1.0 / self.settings.sigma_d}[mode]
        return Layer.map(texture(mode), gain), None

    def side_names(self):
        """Names of the images shown left and right of the divider in split view."""
        names = {"filtered": "F", "original": "O"}
        compare = names[self.compare_with]
        return ("R", compare) if self.swapped else (compare, "R")

    # ================================================================== input
    def _area(self):
        """The image area in framebuffer pixels ``(x, y_bottom_up, width, height)`` and the scale."""
        fb_width, fb_height = self.platform.framebuffer_size
        scale = self.platform.framebuffer_scale
        left = int(round(self.panel_width * scale))
        return (left, 0, max(1, fb_width - left), max(1, fb_height)), scale

    def _view_position(self, window_x, window_y, area, scale):
        return window_x * scale - area[0], window_y * scale

    def _handle_view_mouse(self, area, scale):
        io = imgui.get_io()
        mouse = io.mouse_pos
        x, y = self._view_position(mouse.x, mouse.y, area, scale)
        inside = 0 <= x < area[2] and 0 <= y < area[3]
        if self._drag is not None:
            if not any(imgui.is_mouse_down(button) for button in range(3)):
                self._drag = None
            elif self._drag == "divider":
                self.view.set_split_at(x)
            else:
                self.view.pan(io.mouse_delta.x * scale, io.mouse_delta.y * scale)
        if io.want_capture_mouse or not inside:
            self._wheel = 0.0
            return
        near_divider = self.view_mode == "split" and self.view.near_divider(x, _DIVIDER_GRAB * scale)
        if near_divider or self._drag == "divider":
            imgui.set_mouse_cursor(imgui.MouseCursor_.resize_ew)
        if self._drag is None:
            if imgui.is_mouse_clicked(imgui.MouseButton_.left):
                self._drag = "divider" if near_divider else "pan"
            elif imgui.is_mouse_clicked(imgui.MouseButton_.right) or imgui.is_mouse_clicked(
                    imgui.MouseButton_.middle):
                self._drag = "pan"
        # Whole wheel notches step the zoom ladder; trackpads send fractions that add up.
        self._wheel += io.mouse_wheel
        steps = int(self._wheel)
        if steps:
            self._wheel -= steps
            self.view.step_zoom_at(x, y, steps)

    def _handle_keys(self, area, scale):
        io = imgui.get_io()
        ctrl = io.key_ctrl or io.key_super
        pressed = imgui.is_key_pressed
        if ctrl and pressed(imgui.Key.q, False):
            self.should_close = True
        if io.want_capture_keyboard:
            return
        if pressed(imgui.Key.escape, False):
            self.help_visible = False
        if ctrl:
            if pressed(imgui.Key.s, False):
                self.start_save()
            if pressed(imgui.Key.o, False):
                self.open_fields()
            if io.key_shift and pressed(imgui.Key.c, False):
                self.copy_command_line()
            return
        for index, (mode, _, _) in enumerate(VIEW_MODES):
            if pressed(getattr(imgui.Key, f"_{index + 1}"), False) or pressed(
                    getattr(imgui.Key, f"keypad{index + 1}"), False):
                self.set_view_mode(mode)
        if pressed(imgui.Key.s, False):
            self.set_view_mode("result" if self.view_mode == "split" else "split")
        if pressed(imgui.Key.space, False):
            self.flicker()
        if pressed(imgui.Key.k, False):
            self.auto_flicker = not self.auto_flicker
            self._flicker_time = time.perf_counter()
        if pressed(imgui.Key.c, False):
            self.compare_with = "original" if self.compare_with == "filtered" else "filtered"
        if pressed(imgui.Key.f, False):
            self.view.fit()
        if pressed(imgui.Key.z, False):
            self.view.one_to_one()
        centre = (area[2] / 2, area[3] / 2)
        if pressed(imgui.Key.equal) or pressed(imgui.Key.keypad_add):
            self.view.step_zoom_at(*centre, 1)
        if pressed(imgui.Key.minus) or pressed(imgui.Key.keypad_subtract):
            self.view.step_zoom_at(*centre, -1)
        if pressed(imgui.Key.tab, False):
            self.panel_visible = not self.panel_visible
        if pressed(imgui.Key.h, False) or pressed(imgui.Key.f1, False):
            self.help_visible = not self.help_visible

    def _draw_divider(self, area, scale):
        if self.view_mode != "split" or self.pair is None:
            return
        draw_list = imgui.get_background_draw_list()
        x = (area[0] + self.view.split_x) / scale
        height = area[3] / scale
        draw_list.add_line(imgui.ImVec2(x, 0), imgui.ImVec2(x, height), imgui.IM_COL32(0, 0, 0, 160), 3.0)
        draw_list.add_line(imgui.ImVec2(x, 0), imgui.ImVec2(x, height), imgui.IM_COL32(255, 255, 255, 230), 1.0)
        handle_y = height / 2
        draw_list.add_circle_filled(imgui.ImVec2(x, handle_y), 7.0, imgui.IM_COL32(255, 255, 255, 230))
        left, right = self.side_names()
        # Labels just below the handle, clear of the message strip at the top.
        for text, label_x in ((left, x - 22), (right, x + 14)):
            position = imgui.ImVec2(label_x, handle_y + 12)
            draw_list.add_rect_filled(imgui.ImVec2(position.x - 3, position.y - 2),
                                      imgui.ImVec2(position.x + 11, position.y + 15), imgui.IM_COL32(0, 0, 0, 160))
            draw_list.add_text(position, imgui.IM_COL32(255, 255, 255, 255), text)

    # ================================================================== status
    def status_lines(self):
        """The panel's status lines: size, backend, timings, zoom, pixel under the cursor."""
        lines = []
        if self.pair is not None:
            width, height = self.pair.size
            lines.append(f"{width} x {height}  {self.pair.filtered.dtype}  backend {self.engine.backend}")
            if self.order is not None and self.order.looks_reversed:
                lines.append("ORIGINAL and FILTERED look swapped")
            if self.engine.last_seconds is not None:
                lines.append(f"last recovery {self.engine.last_seconds * 1000:.1f} ms")
            area, scale = self._area()
            mouse = imgui.get_io().mouse_pos
            pixel = self.view.pixel_at(*self._view_position(mouse.x, mouse.y, area, scale))
            where = f"  pixel ({pixel[0]}, {pixel[1]})" if pixel else ""
            lines.append(f"zoom {self.view.zoom * 100:.4g}%{where}")
        else:
            lines.append(f"no images  backend {self.engine.backend}")
        if self.frame_seconds is not None:
            lines.append(f"frame {self.frame_seconds * 1000:.1f} ms")
        return lines

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
        self._poll_dialog()
        now = time.perf_counter()
        self._expire_messages(now)
        if self.auto_flicker and now - self._flicker_time >= self.flicker_period:
            self.flicker()
            self._flicker_time = now

        self.platform.new_frame()
        imgui.new_frame()
        area, scale = self._area()
        self.view.set_view_size(area[2], area[3])
        ui.draw_ui(self)
        self._handle_view_mouse(area, scale)
        self._handle_keys(area, scale)
        area, scale = self._area()  # Tab may have hidden the panel
        self.view.set_view_size(area[2], area[3])
        self._recompute_if_needed()
        self._draw_divider(area, scale)
        self.platform.update_cursor()
        imgui.render()

        screen = self.context.screen
        screen.use()
        self.context.viewport = (0, 0, *self.platform.framebuffer_size)
        self.context.clear(*ui_background())
        if self.pair is not None:
            self.image_view.draw(area, self.view, *self._layers())
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
        if self.platform.input_serial != self._seen_input:
            self._seen_input = self.platform.input_serial
            self._busy_frames = _SETTLE_FRAMES
        if self._busy_frames > 0:
            self._busy_frames -= 1
            return False
        return not (self.auto_flicker or self._drag is not None)

    def run(self):
        """Show the window until it is closed; sleeps while nothing changes."""
        while True:
            if self._idle():
                wait = self.flicker_period if self.auto_flicker else _IDLE_WAIT
                glfw.wait_events_timeout(wait if (self._dialog is not None or self.messages) else 1.0)
            if not self.step():
                break

    def close(self):
        """Free the engine, GL objects, ImGui and the window."""
        self.engine.release()
        self.image_view.release()
        self.renderer.release()
        self.platform.release()
        imgui.destroy_context(self._imgui_context)
        self.context.release()
        glfw.destroy_window(self.window)
        glfw.terminate()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def ui_background():
    """Clear colour of the window (RGBA), behind the panel and around the image."""
    return (0.11, 0.11, 0.12, 1.0)


def _native_dialogs_available():
    """Native file dialogs exist on Windows and macOS, and on Linux with zenity or kdialog."""
    if sys.platform in ("win32", "darwin"):
        return True
    return any(shutil.which(tool) for tool in ("zenity", "kdialog", "matedialog", "qarma"))


def sample_source():
    """The bundled sample and the sample filter, or None when the install has neither."""
    path = sample_path()
    if path is None or SAMPLE_FILTER not in filter_names():
        return None
    return PairSource(path, None, SAMPLE_FILTER, {})
