"""GLFW to Dear ImGui: the window's input events become ImGui IO events.

Every input the viewer reacts to arrives through the callbacks here, which GLFW calls from
``glfw.poll_events()``; the viewer then reads mouse and keys from ImGui's IO during the frame.
Tests drive the app by calling these same callbacks, so scripted and real input share one path.

``glfw`` must be imported before ``imgui_bundle``: imgui-bundle points the ``glfw`` package at
its own GLFW library when it is imported first, and the viewer uses the ``glfw`` package's.
"""

import time

import glfw
from imgui_bundle import imgui

__all__ = ["GlfwPlatform", "KEY_MAP"]


def _key_map():
    keys = {glfw.KEY_A + i: getattr(imgui.Key, chr(ord("a") + i)) for i in range(26)}
    keys.update({glfw.KEY_0 + i: getattr(imgui.Key, f"_{i}") for i in range(10)})
    keys.update({glfw.KEY_KP_0 + i: getattr(imgui.Key, f"keypad{i}") for i in range(10)})
    keys.update({glfw.KEY_F1 + i: getattr(imgui.Key, f"f{i + 1}") for i in range(12)})
    named = {
        "TAB": "tab", "BACKSPACE": "backspace", "ENTER": "enter", "ESCAPE": "escape",
        "INSERT": "insert", "DELETE": "delete", "SPACE": "space", "LEFT": "left_arrow",
        "RIGHT": "right_arrow", "UP": "up_arrow", "DOWN": "down_arrow", "PAGE_UP": "page_up",
        "PAGE_DOWN": "page_down", "HOME": "home", "END": "end", "KP_ENTER": "keypad_enter",
        "KP_DECIMAL": "keypad_decimal", "KP_DIVIDE": "keypad_divide", "KP_MULTIPLY": "keypad_multiply",
        "KP_SUBTRACT": "keypad_subtract", "KP_ADD": "keypad_add", "KP_EQUAL": "keypad_equal",
        "LEFT_CONTROL": "left_ctrl", "RIGHT_CONTROL": "right_ctrl", "LEFT_SHIFT": "left_shift",
        "RIGHT_SHIFT": "right_shift", "LEFT_ALT": "left_alt", "RIGHT_ALT": "right_alt",
        "LEFT_SUPER": "left_super", "RIGHT_SUPER": "right_super", "APOSTROPHE": "apostrophe",
        "COMMA": "comma", "MINUS": "minus", "PERIOD": "period", "SLASH": "slash",
        "SEMICOLON": "semicolon", "EQUAL": "equal", "LEFT_BRACKET": "left_bracket",
        "BACKSLASH": "backslash", "RIGHT_BRACKET": "right_bracket", "GRAVE_ACCENT": "grave_accent",
        "CAPS_LOCK": "caps_lock", "SCROLL_LOCK": "scroll_lock", "NUM_LOCK": "num_lock",
        "PRINT_SCREEN": "print_screen", "PAUSE": "pause", "MENU": "menu",
    }
    keys.update({getattr(glfw, f"KEY_{glfw_name}"): getattr(imgui.Key, imgui_name)
                 for glfw_name, imgui_name in named.items()})
    return keys


#: GLFW key code -> ImGui key.
KEY_MAP = _key_map()

_MODIFIERS = ((glfw.MOD_CONTROL, imgui.Key.mod_ctrl), (glfw.MOD_SHIFT, imgui.Key.mod_shift),
              (glfw.MOD_ALT, imgui.Key.mod_alt), (glfw.MOD_SUPER, imgui.Key.mod_super))
# ImGui's "no mouse" position: the cursor has left the window.
_NO_MOUSE = -3.4028235e38


class GlfwPlatform:
    """Feeds one GLFW window's events to the current ImGui context.

    Parameters
    ----------
    window : glfw window handle
    on_drop : callable, optional
        ``on_drop(paths)`` when files are dropped onto the window.

    Attributes
    ----------
    input_serial : int
        Counts input events; the app's idle loop sleeps while it does not change.
    """

    def __init__(self, window, on_drop=None):
        self.window = window
        self.on_drop = on_drop
        self.input_serial = 0
        self._last_time = None
        self.io = imgui.get_io()
        self.io.backend_flags |= imgui.BackendFlags_.has_mouse_cursors
        glfw.set_key_callback(window, self.key_callback)
        glfw.set_char_callback(window, self.char_callback)
        glfw.set_cursor_pos_callback(window, self.cursor_pos_callback)
        glfw.set_cursor_enter_callback(window, self.cursor_enter_callback)
        glfw.set_mouse_button_callback(window, self.mouse_button_callback)
        glfw.set_scroll_callback(window, self.scroll_callback)
        glfw.set_window_focus_callback(window, self.focus_callback)
        glfw.set_drop_callback(window, self.drop_callback)
        glfw.set_framebuffer_size_callback(window, self.framebuffer_size_callback)
        glfw.set_window_size_callback(window, self.window_size_callback)
        # Sizes are tracked through callbacks: asking the X server every frame costs round trips.
        self.window_size = glfw.get_window_size(window)
        self.framebuffer_size = glfw.get_framebuffer_size(window)
        platform_io = imgui.get_platform_io()
        platform_io.platform_get_clipboard_text_fn = self._get_clipboard
        platform_io.platform_set_clipboard_text_fn = self._set_clipboard
        self._cursors = {
            imgui.MouseCursor_.arrow: glfw.create_standard_cursor(glfw.ARROW_CURSOR),
            imgui.MouseCursor_.text_input: glfw.create_standard_cursor(glfw.IBEAM_CURSOR),
            imgui.MouseCursor_.resize_ew: glfw.create_standard_cursor(glfw.HRESIZE_CURSOR),
            imgui.MouseCursor_.resize_ns: glfw.create_standard_cursor(glfw.VRESIZE_CURSOR),
            imgui.MouseCursor_.hand: glfw.create_standard_cursor(glfw.HAND_CURSOR),
        }
        self._shown_cursor = None

    # -------------------------------------------------------------- GLFW callbacks
    def _touch(self):
        self.input_serial += 1

    def _update_modifiers(self, mods):
        for flag, key in _MODIFIERS:
            self.io.add_key_event(key, bool(mods & flag))

    def key_callback(self, window, key, scancode, action, mods):
        """GLFW key callback: press, repeat and release of a key."""
        self._touch()
        if action == glfw.REPEAT:
            return  # ImGui makes its own repeats from the held state
        # GLFW reports the modifier state before a modifier key's own change; fix it up.
        pressed = action == glfw.PRESS
        own = {glfw.KEY_LEFT_CONTROL: glfw.MOD_CONTROL, glfw.KEY_RIGHT_CONTROL: glfw.MOD_CONTROL,
               glfw.KEY_LEFT_SHIFT: glfw.MOD_SHIFT, glfw.KEY_RIGHT_SHIFT: glfw.MOD_SHIFT,
               glfw.KEY_LEFT_ALT: glfw.MOD_ALT, glfw.KEY_RIGHT_ALT: glfw.MOD_ALT,
               glfw.KEY_LEFT_SUPER: glfw.MOD_SUPER, glfw.KEY_RIGHT_SUPER: glfw.MOD_SUPER}.get(key, 0)
        mods = (mods | own) if pressed else (mods & ~own)
        self._update_modifiers(mods)
        imgui_key = KEY_MAP.get(key)
        if imgui_key is not None:
            self.io.add_key_event(imgui_key, pressed)

    def char_callback(self, window, codepoint):
        """GLFW character callback: text typed into a focused field."""
        self._touch()
        self.io.add_input_character(codepoint)

    def cursor_pos_callback(self, window, x, y):
        """GLFW cursor callback, in window coordinates."""
        self._touch()
        self.io.add_mouse_pos_event(float(x), float(y))

    def cursor_enter_callback(self, window, entered):
        """GLFW cursor-enter callback: forget the position when the cursor leaves."""
        self._touch()
        if not entered:
            self.io.add_mouse_pos_event(_NO_MOUSE, _NO_MOUSE)

    def mouse_button_callback(self, window, button, action, mods):
        """GLFW mouse-button callback."""
        self._touch()
        self._update_modifiers(mods)
        if 0 <= button < imgui.MouseButton_.count:
            self.io.add_mouse_button_event(button, action == glfw.PRESS)

    def scroll_callback(self, window, x_offset, y_offset):
        """GLFW scroll callback (wheel notches or trackpad distance)."""
        self._touch()
        self.io.add_mouse_wheel_event(float(x_offset), float(y_offset))

    def focus_callback(self, window, focused):
        """GLFW focus callback: ImGui releases held keys when focus is lost."""
        self._touch()
        self.io.add_focus_event(bool(focused))

    def drop_callback(self, window, paths):
        """GLFW drop callback: paths of files dropped onto the window."""
        self._touch()
        if self.on_drop is not None:
            self.on_drop(list(paths))

    def framebuffer_size_callback(self, window, width, height):
        """GLFW framebuffer-size callback, in pixels."""
        self._touch()
        self.framebuffer_size = (width, height)

    def window_size_callback(self, window, width, height):
        """GLFW window-size callback, in screen units."""
        self._touch()
        self.window_size = (width, height)

    @property
    def framebuffer_scale(self):
        """Framebuffer pixels per window unit (2 on a typical HiDPI screen)."""
        width = self.window_size[0]
        return self.framebuffer_size[0] / width if width else 1.0

    # -------------------------------------------------------------- clipboard
    def _get_clipboard(self, _context):
        # GLFW 3.3+ keeps one clipboard per process; the window argument is deprecated.
        text = glfw.get_clipboard_string(None)
        return text.decode("utf-8", "replace") if text else ""

    def _set_clipboard(self, _context, text):
        glfw.set_clipboard_string(None, text)

    # -------------------------------------------------------------- per frame
    def new_frame(self):
        """Tell ImGui the window size, framebuffer scale and time step; call before ``imgui.new_frame``."""
        width, height = self.window_size
        fb_width, fb_height = self.framebuffer_size
        self.io.display_size = imgui.ImVec2(float(width), float(height))
        if width > 0 and height > 0:
            self.io.display_framebuffer_scale = imgui.ImVec2(fb_width / width, fb_height / height)
        now = time.perf_counter()
        self.io.delta_time = max(1e-4, now - self._last_time) if self._last_time is not None else 1 / 60
        self._last_time = now

    def update_cursor(self):
        """Show the mouse cursor shape ImGui asked for this frame."""
        shape = imgui.get_mouse_cursor()
        if shape != self._shown_cursor:
            glfw.set_cursor(self.window, self._cursors.get(shape, self._cursors[imgui.MouseCursor_.arrow]))
            self._shown_cursor = shape

    def release(self):
        """Free the cursors; the window itself belongs to the caller."""
        for cursor in self._cursors.values():
            glfw.destroy_cursor(cursor)
        self._cursors.clear()
