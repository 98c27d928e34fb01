"""Mouse and keys: pan, zoom and the divider on the image area, and the keyboard shortcuts.

Both are read from ImGui's IO after the widgets are built, so that a widget under the mouse
or a focused text field gets first claim on the input.
"""

import time

from imgui_bundle import imgui

from .keys import VIEW_MODES

__all__ = ["ViewInput", "window_to_view"]

# How close to the divider (window units) a press grabs it instead of panning.
_DIVIDER_GRAB = 6.0


def window_to_view(window_x, window_y, area, scale):
    """View pixels (see ``view_state``) of a window position, for the image `area` and `scale`."""
    return window_x * scale - area[0], window_y * scale


class ViewInput:
    """The mouse's drag and wheel state between frames, and what mouse and keys do.

    Attributes
    ----------
    drag : {"pan", "divider"} or None
        What a held mouse button is moving.
    """

    def __init__(self):
        self.drag = None
        self._wheel = 0.0  # wheel distance not yet turned into zoom steps

    def handle_mouse(self, view, comparison, area, scale):
        """Pan, move the divider and zoom with the wheel.

        Parameters
        ----------
        view : ViewState
        comparison : Comparison
            The divider exists in its split view only.
        area : tuple
            The image area ``(x, y_bottom_up, width, height)`` in framebuffer pixels.
        scale : float
            Framebuffer pixels per window unit.
        """
        io = imgui.get_io()
        mouse = io.mouse_pos
        x, y = window_to_view(mouse.x, mouse.y, area, scale)
        inside = 0 <= x < area[2] and 0 <= y < area[3]
        if self.drag is not None:
            if not any(imgui.is_mouse_down(button) for button in range(3)):
                self.drag = None
            elif self.drag == "divider":
                view.set_split_at(x)
            else:
                view.pan(io.mouse_delta.x * scale, io.mouse_delta.y * scale)
        if io.want_capture_mouse or not inside:
            self._wheel = 0.0
            return
        near_divider = comparison.view_mode == "split" and view.near_divider(x, _DIVIDER_GRAB * scale)
        if near_divider or self.drag == "divider":
            imgui.set_mouse_cursor(imgui.MouseCursor_.resize_ew)
        if self.drag is None:
            if imgui.is_mouse_clicked(imgui.MouseButton_.left):
                self.drag = "divider" if near_divider else "pan"
            elif imgui.is_mouse_clicked(imgui.MouseButton_.right) or imgui.is_mouse_clicked(
                    imgui.MouseButton_.middle):
                self.drag = "pan"
        # Whole wheel notches step the zoom ladder; trackpads send fractions that add up.
        self._wheel += io.mouse_wheel
        steps = int(self._wheel)
        if steps:
            self._wheel -= steps
            view.step_zoom_at(x, y, steps)

    def handle_keys(self, app, area):
        """The keys of ``keys.KEY_HELP``, applied to the app's parts.

        Parameters
        ----------
        app : ViewerApp
        area : tuple
            The image area; + and - zoom around its centre.
        """
        io = imgui.get_io()
        ctrl = io.key_ctrl or io.key_super
        pressed = imgui.is_key_pressed
        if ctrl and pressed(imgui.Key.q, False):
            app.should_close = True
        if io.want_capture_keyboard:
            return
        if pressed(imgui.Key.escape, False):
            app.panel.help_visible = False
        if ctrl:
            if pressed(imgui.Key.s, False):
                app.saving.start()
            if pressed(imgui.Key.o, False):
                app.opener.open_fields()
            if io.key_shift and pressed(imgui.Key.c, False):
                app.saving.copy_command_line()
            return
        comparison, view = app.comparison, app.view
        for mode, _, key in VIEW_MODES:
            if pressed(getattr(imgui.Key, f"_{key}"), False) or pressed(getattr(imgui.Key, f"keypad{key}"), False):
                comparison.set_view_mode(mode)
        if pressed(imgui.Key.s, False):
            comparison.toggle_split()
        if pressed(imgui.Key.space, False):
            comparison.flicker()
        if pressed(imgui.Key.k, False):
            comparison.toggle_auto_flicker(time.perf_counter())
        if pressed(imgui.Key.c, False):
            comparison.toggle_compared_image()
        if pressed(imgui.Key.f, False):
            view.fit()
        if pressed(imgui.Key.z, False):
            view.one_to_one()
        centre = (area[2] / 2, area[3] / 2)
        if pressed(imgui.Key.equal) or pressed(imgui.Key.keypad_add):
            view.step_zoom_at(*centre, 1)
        if pressed(imgui.Key.minus) or pressed(imgui.Key.keypad_subtract):
            view.step_zoom_at(*centre, -1)
        if pressed(imgui.Key.tab, False):
            app.panel.visible = not app.panel.visible
        if pressed(imgui.Key.h, False) or pressed(imgui.Key.f1, False):
            app.panel.help_visible = not app.panel.help_visible
