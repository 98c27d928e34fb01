"""The viewer's ImGui widgets: the side panel, messages, the help overlay, dialogs, the divider.

Each function draws one part for one frame and changes the app only through its parts'
methods and plain attributes (``app.panel``, ``app.recovery.settings``, ``app.comparison``,
``app.opener``, ``app.saving``), so that the same actions are reachable from keys, widgets
and tests.
"""

import os

from imgui_bundle import imgui

import aarecovery

from .keys import KEY_HELP, VIEW_MODES
from .settings import RecoverySettings
from .sources import filter_names, filter_parameters
from .status import status_lines

__all__ = ["draw_ui", "draw_divider", "PANEL_WIDTH"]

#: Width of the side panel in window units (scaled with the content scale).
PANEL_WIDTH = 330.0

_ERROR = imgui.ImVec4(1.0, 0.45, 0.4, 1.0)
_INFO = imgui.ImVec4(0.6, 0.85, 1.0, 1.0)
_DIM = imgui.ImVec4(0.65, 0.65, 0.65, 1.0)
#: Range of the flicker period slider, in seconds.
FLICKER_PERIODS = (0.1, 2.0)
#: Range of the heat-map gain slider.
HEAT_MAP_GAINS = (1.0, 64.0)
# Slider values: three significant digits suit logarithmic ranges (ImGui rounds to them too).
_FLOAT_FORMAT = "%.3g"
# The value column of a slider is as wide as this text (the widest %.3g of the parameters'
# ranges, 0.000123), or as the value if that is wider.
_VALUE_COLUMN = "0.000000"
_FIXED = (imgui.WindowFlags_.no_move | imgui.WindowFlags_.no_resize | imgui.WindowFlags_.no_collapse
          | imgui.WindowFlags_.no_saved_settings)


def _record(app, name):
    """Remember where the last widget's frame is (window coordinates), for --bench and tests.

    The item rectangle includes the label to the right; the frame (a slider's track) is the
    item width from the left edge.
    """
    low, high = imgui.get_item_rect_min(), imgui.get_item_rect_max()
    app.widget_rects[name] = (low.x, low.y, min(high.x, low.x + imgui.calc_item_width()), high.y)


def draw_ui(app):
    """Draw every window of one frame."""
    if app.panel.visible:
        _panel(app)
    _messages(app)
    if app.panel.help_visible:
        _help(app)
    _dialogs(app)


# ---------------------------------------------------------------------------------- panel
def _panel(app):
    io = imgui.get_io()
    imgui.set_next_window_pos(imgui.ImVec2(0, 0))
    imgui.set_next_window_size(imgui.ImVec2(app.panel_width, io.display_size.y))
    imgui.begin("aarecovery", None, _FIXED)
    _files_section(app)
    _parameters_section(app)
    _view_section(app)
    _actions_section(app)
    _status_section(app)
    imgui.end()


def _path_row(app, label, attribute, browse_role):
    changed, value = imgui.input_text(f"##{attribute}", getattr(app.panel, attribute))
    _record(app, attribute)
    if changed:
        setattr(app.panel, attribute, value)
    imgui.same_line()
    if app.dialogs.available and imgui.button(f"...##{attribute}"):
        app.dialogs.browse(browse_role, app.panel)
    imgui.same_line()
    imgui.text(label)


def _files_section(app):
    if not imgui.collapsing_header("Images", imgui.TreeNodeFlags_.default_open):
        return
    panel = app.panel
    _path_row(app, "ORIGINAL", "original_path", "original")
    names = filter_names()
    if names:
        if imgui.radio_button("FILTERED file", not panel.use_builtin_filter):
            panel.use_builtin_filter = False
        imgui.same_line()
        if imgui.radio_button("built-in filter", panel.use_builtin_filter):
            panel.use_builtin_filter = True
    if panel.use_builtin_filter and names:
        index = names.index(panel.filter_name) if panel.filter_name in names else 0
        changed, index = imgui.combo("filter", index, names)
        if changed:
            app.opener.choose_filter(names[index])
        for name, default, help_text, is_int in filter_parameters(panel.filter_name):
            value = panel.filter_params.get(name, default)
            if is_int:
                _, value = imgui.input_int(name, int(value))
            else:
                _, value = imgui.input_float(name, float(value), 0.0, 0.0, "%.4g")
            if imgui.is_item_hovered():
                imgui.set_tooltip(help_text)
            panel.filter_params[name] = value
            if imgui.is_item_deactivated_after_edit():
                app.opener.open_fields()
    else:
        _path_row(app, "FILTERED", "filtered_path", "filtered")
    if imgui.button("Open (Ctrl+O)"):
        app.opener.open_fields()
    _record(app, "open")
    imgui.same_line()
    imgui.text_colored(_DIM, "or drop files on the window")


def _slider(app, key, label, value, minimum, maximum, display_format, flags=0, help_text=None, indent=0.0):
    """A slider with its value beside the track, where the grab cannot cover it.

    ImGui draws a slider's value centred on the track, under which the grab passes and hid
    digits. Here the frame draws nothing (ImGui shows no text after ``##``; ctrl+click
    editing and the rounding of dragged values still use the format after it) and the value
    is a text item between the track and the label, whose column fits the widest value.
    `indent` is what an item before it on the same line took (the strength's "auto" box):
    the track is that much shorter, so that the label ends where the others do.

    Returns
    -------
    The new value (int when `minimum` is an int).
    """
    style = imgui.get_style()
    start_x = imgui.get_cursor_pos_x()
    width = imgui.calc_item_width() - indent
    spacing = style.item_inner_spacing.x
    column = max(imgui.calc_text_size(_VALUE_COLUMN).x, imgui.calc_text_size(display_format % value).x)
    imgui.set_next_item_width(max(1.0, width - column - spacing))
    slide = imgui.slider_int if isinstance(minimum, int) else imgui.slider_float
    _, value = slide(f"##{key}", value, minimum, maximum, "##" + display_format, flags)
    _record(app, key)
    hovered = imgui.is_item_hovered()
    imgui.same_line(0, spacing)
    imgui.text(display_format % value)
    low, high = imgui.get_item_rect_min(), imgui.get_item_rect_max()
    app.widget_rects[f"{key} value"] = (low.x, low.y, high.x, high.y)
    imgui.same_line(max(start_x + width + spacing, imgui.get_cursor_pos_x()))
    imgui.text(label)
    low, high = imgui.get_item_rect_min(), imgui.get_item_rect_max()
    app.widget_rects[f"{key} label"] = (low.x, low.y, high.x, high.y)
    if help_text and (hovered or imgui.is_item_hovered()):
        imgui.set_tooltip(help_text)
    return value


def _parameter_slider(app, spec, value):
    """A slider over one parameter's valid range, with its label and help from ``PARAMETERS``.

    A parameter the safe default may choose (``spec.automatic``, the strength) has an
    "auto" box first: ticked, the value is None and the status line says what was chosen;
    unticked, the slider starts at what the last run used.
    """
    indent = 0.0
    if spec.automatic:
        line_start = imgui.get_cursor_pos_x()
        automatic = value is None
        changed, automatic = imgui.checkbox(f"auto##{spec.name}", automatic)
        _record(app, f"{spec.name} auto")
        if imgui.is_item_hovered():
            imgui.set_tooltip(f"ticked: {spec.automatic}")
        imgui.same_line()
        if automatic:
            imgui.text_colored(_DIM, spec.label)
            return None
        if value is None:
            plan = app.recovery.engine.last_plan if app.recovery.engine is not None else None
            value = plan.strength if plan is not None else spec.maximum
        indent = imgui.get_cursor_pos_x() - line_start
    flags = imgui.SliderFlags_.always_clamp
    if spec.logarithmic:
        flags |= imgui.SliderFlags_.logarithmic
    return _slider(app, spec.name, spec.label, value, spec.minimum, spec.maximum,
                   "%d" if spec.kind is int else _FLOAT_FORMAT, flags, spec.help, indent)


def _parameters_section(app):
    if not imgui.collapsing_header("Recovery", imgui.TreeNodeFlags_.default_open):
        return
    settings = app.recovery.settings
    values = {name: _parameter_slider(app, spec, getattr(settings, name))
              for name, spec in aarecovery.PARAMETERS.items()}
    modes = list(aarecovery.MODES)
    _, index = imgui.combo("mode", modes.index(settings.mode), modes)
    _record(app, "mode")
    app.recovery.settings = settings.with_values(mode=modes[index], **values)
    if imgui.button("Paper defaults"):
        app.recovery.settings = RecoverySettings.defaults()
    imgui.same_line()
    imgui.text_colored(_DIM, "ctrl+click a slider to type")


def _view_section(app):
    if not imgui.collapsing_header("View", imgui.TreeNodeFlags_.default_open):
        return
    comparison = app.comparison
    labels = [label for _, label, _ in VIEW_MODES]
    keys = [key for key, _, _ in VIEW_MODES]
    index = keys.index(comparison.view_mode)
    changed, index = imgui.combo("view", index, [f"{i + 1}  {label}" for i, label in enumerate(labels)])
    _record(app, "view")
    if changed:
        comparison.set_view_mode(keys[index])
    if imgui.radio_button("compare with F", comparison.compare_with == "filtered"):
        comparison.compare_with = "filtered"
    imgui.same_line()
    if imgui.radio_button("with O", comparison.compare_with == "original"):
        comparison.compare_with = "original"
    _, comparison.auto_flicker = imgui.checkbox("flicker (K)", comparison.auto_flicker)
    comparison.flicker_period = _slider(app, "flicker_period", "flicker period", comparison.flicker_period,
                                        *FLICKER_PERIODS, "%.2f s")
    comparison.difference_gain = _slider(app, "difference_gain", "heat-map gain", comparison.difference_gain,
                                         *HEAT_MAP_GAINS, "x%.1f", imgui.SliderFlags_.logarithmic)
    if imgui.button("Fit (F)"):
        app.view.fit()
    imgui.same_line()
    if imgui.button("1:1 (Z)"):
        app.view.one_to_one()
    imgui.same_line()
    imgui.text(f"zoom {app.view.zoom * 100:.4g}%")


def _actions_section(app):
    if not imgui.collapsing_header("Result", imgui.TreeNodeFlags_.default_open):
        return
    if imgui.button("Save R... (Ctrl+S)"):
        app.saving.start()
    _record(app, "save")
    imgui.same_line()
    if imgui.button("Copy command line"):
        app.saving.copy_command_line()
    _record(app, "copy")


def _status_section(app):
    imgui.separator()
    imgui.push_text_wrap_pos(0.0)  # long lines wrap at the panel's edge
    for line in status_lines(app):
        imgui.text_colored(_DIM, line.text)
        if line.detail and imgui.is_item_hovered() and imgui.begin_tooltip():
            imgui.push_text_wrap_pos(imgui.get_font_size() * 35)
            imgui.text_unformatted(line.detail)
            imgui.pop_text_wrap_pos()
            imgui.end_tooltip()
    imgui.pop_text_wrap_pos()
    imgui.text_colored(_DIM, "H or F1: keys")


# ---------------------------------------------------------------------------------- overlays
def _messages(app):
    if not app.messages:
        return
    io = imgui.get_io()
    width = min(560.0, io.display_size.x - app.panel_width - 20)
    imgui.set_next_window_pos(imgui.ImVec2(app.panel_width + 10, 10))
    imgui.set_next_window_size(imgui.ImVec2(max(200.0, width), 0))
    imgui.begin("##messages", None, _FIXED | imgui.WindowFlags_.no_title_bar
                | imgui.WindowFlags_.always_auto_resize)
    for index, message in enumerate(app.messages):
        imgui.push_text_wrap_pos(imgui.get_cursor_pos_x() + width - 60)
        imgui.text_colored(_ERROR if message.error else _INFO, message.text)
        imgui.pop_text_wrap_pos()
        imgui.same_line()
        if imgui.small_button(f"x##message{index}"):
            app.messages.dismiss(message)
    imgui.end()


def _help(app):
    io = imgui.get_io()
    imgui.set_next_window_pos(imgui.ImVec2(io.display_size.x / 2, io.display_size.y / 2),
                              imgui.Cond_.always, imgui.ImVec2(0.5, 0.5))
    expanded, still_open = imgui.begin("Keys", True, imgui.WindowFlags_.always_auto_resize
                                       | imgui.WindowFlags_.no_collapse | imgui.WindowFlags_.no_saved_settings)
    if expanded:
        if imgui.begin_table("keys", 2):
            for keys, action in KEY_HELP:
                imgui.table_next_row()
                imgui.table_next_column()
                imgui.text_colored(_INFO, keys)
                imgui.table_next_column()
                imgui.text(action)
            imgui.end_table()
    imgui.end()
    if not still_open:
        app.panel.help_visible = False


def _dialogs(app):
    panel = app.panel
    if panel.save_dialog_requested:
        imgui.open_popup("Save result")
        panel.save_dialog_requested = False
    if panel.pending_overwrite is not None and not imgui.is_popup_open("Replace file?"):
        imgui.open_popup("Replace file?")
    if panel.pending_drop is not None and not imgui.is_popup_open("Dropped file"):
        imgui.open_popup("Dropped file")

    flags = imgui.WindowFlags_.always_auto_resize
    if imgui.begin_popup_modal("Save result", None, flags)[0]:
        imgui.text("Write the recovered image R to:")
        imgui.set_next_item_width(480)
        if imgui.is_window_appearing():
            imgui.set_keyboard_focus_here()
        _, panel.save_path = imgui.input_text("##save_path", panel.save_path)
        imgui.text_colored(_DIM, "the extension picks the format: .png .tif .npy .jpg .webp .bmp")
        if imgui.button("Save") or imgui.is_key_pressed(imgui.Key.enter):
            imgui.close_current_popup()
            app.saving.request(panel.save_path)
        imgui.same_line()
        if app.dialogs.available and imgui.button("Browse..."):
            app.dialogs.browse("save", panel)
        imgui.same_line()
        if imgui.button("Cancel") or imgui.is_key_pressed(imgui.Key.escape):
            imgui.close_current_popup()
        imgui.end_popup()

    if imgui.begin_popup_modal("Replace file?", None, flags)[0]:
        question = panel.pending_overwrite[1] if panel.pending_overwrite else ""
        imgui.text_colored(_ERROR, question)
        if imgui.button("Replace"):
            imgui.close_current_popup()
            app.saving.confirm_overwrite()
        imgui.same_line()
        if imgui.button("Cancel") or imgui.is_key_pressed(imgui.Key.escape):
            imgui.close_current_popup()
            panel.pending_overwrite = None
        imgui.end_popup()

    if imgui.begin_popup_modal("Dropped file", None, flags)[0]:
        name = os.path.basename(panel.pending_drop or "")
        imgui.text(f"Use {name} as:")
        if imgui.button("ORIGINAL"):
            imgui.close_current_popup()
            app.opener.use_dropped_as("original")
        imgui.same_line()
        if imgui.button("FILTERED"):
            imgui.close_current_popup()
            app.opener.use_dropped_as("filtered")
        imgui.same_line()
        if imgui.button("Cancel") or imgui.is_key_pressed(imgui.Key.escape):
            imgui.close_current_popup()
            panel.pending_drop = None
        imgui.end_popup()


# ---------------------------------------------------------------------------------- divider
def draw_divider(app, area, scale):
    """Draw the split view's divider, its handle and the names of the two sides."""
    if app.comparison.view_mode != "split" or app.recovery.pair is None:
        return
    draw_list = imgui.get_background_draw_list()
    x = (area[0] + app.view.split_x) / scale
    height = area[3] / scale
    draw_list.add_line(imgui.ImVec2(x, 0), imgui.ImVec2(x, height), imgui.IM_COL32(0, 0, 0, 160), 3.0)
    draw_list.add_line(imgui.ImVec2(x, 0), imgui.ImVec2(x, height), imgui.IM_COL32(255, 255, 255, 230), 1.0)
    handle_y = height / 2
    draw_list.add_circle_filled(imgui.ImVec2(x, handle_y), 7.0, imgui.IM_COL32(255, 255, 255, 230))
    left, right = app.comparison.side_names()
    # Labels just below the handle, clear of the message strip at the top.
    for text, label_x in ((left, x - 22), (right, x + 14)):
        position = imgui.ImVec2(label_x, handle_y + 12)
        draw_list.add_rect_filled(imgui.ImVec2(position.x - 3, position.y - 2),
                                  imgui.ImVec2(position.x + 11, position.y + 15), imgui.IM_COL32(0, 0, 0, 160))
        draw_list.add_text(position, imgui.IM_COL32(255, 255, 255, 255), text)
