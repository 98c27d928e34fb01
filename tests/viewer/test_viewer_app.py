"""The whole viewer in a real window under Xvfb, driven by input events between frames.

Events go through the GLFW callbacks the app registered, the functions GLFW itself calls
from glfw.poll_events(): from there on scripted input takes the path real input takes.
"""

import numpy as np
import pytest

from conftest import require_viewer_extra

pytestmark = pytest.mark.usefixtures("xvfb_display")

WINDOW = (900, 560)


@pytest.fixture
def app():
    require_viewer_extra()
    from aarecovery.viewer.app import ViewerApp
    viewer = ViewerApp(None, size=WINDOW, vsync=False)
    yield viewer
    viewer.close()


def frames(app, count=2):
    for _ in range(count):
        assert app.step()


def key(app, glfw_key, mods=0):
    import glfw
    app.platform.key_callback(app.window, glfw_key, 0, glfw.PRESS, mods)
    frames(app, 1)
    app.platform.key_callback(app.window, glfw_key, 0, glfw.RELEASE, mods)
    frames(app, 1)


def move(app, x, y):
    app.platform.cursor_pos_callback(app.window, x, y)


def press(app, x, y):
    import glfw
    move(app, x, y)
    app.platform.mouse_button_callback(app.window, glfw.MOUSE_BUTTON_LEFT, glfw.PRESS, 0)


def release(app, x, y):
    import glfw
    move(app, x, y)
    app.platform.mouse_button_callback(app.window, glfw.MOUSE_BUTTON_LEFT, glfw.RELEASE, 0)


def drag(app, start, end, steps=4):
    press(app, *start)
    frames(app, 2)
    for i in range(1, steps + 1):
        move(app, start[0] + (end[0] - start[0]) * i / steps, start[1] + (end[1] - start[1]) * i / steps)
        frames(app, 1)
    release(app, *end)
    frames(app, 2)


def centre(rect):
    return (rect[0] + rect[2]) / 2, (rect[1] + rect[3]) / 2


def test_scripted_session(app, image_pair):
    import glfw

    import aarecovery
    from aarecovery import read_image
    from aarecovery.viewer.sources import PairSource

    assert app.opener.open(PairSource(*image_pair))
    frames(app, 3)
    assert app.recovery.recoveries == 1 and app.recovery.computed[0] == app.recovery.settings
    from aarecovery.viewer.status import plan_line, status_lines
    # On a slow (shared) machine three frames can outlast SUMMARY_DELAY, so the status line may
    # already carry the summary: compare with the line for whatever summary is shown.
    shown = plan_line(app.engine, app.recovery.summary)
    assert shown.text.startswith("safe: ") and shown in status_lines(app)

    # Slider drag: sigma_e from 30% to 80% of its (logarithmic) track.
    left, top, right, bottom = app.widget_rects["sigma_e"]
    y = (top + bottom) / 2
    drag(app, (left + 0.3 * (right - left), y), (left + 0.8 * (right - left), y))
    # The track spans sigma_e's valid range logarithmically; its ends are inset by the grab's half width.
    spec = aarecovery.PARAMETERS["sigma_e"]
    ratio = spec.maximum / spec.minimum
    assert spec.minimum * ratio ** 0.7 < app.recovery.settings.sigma_e < spec.minimum * ratio ** 0.9
    assert app.recovery.computed[0] == app.recovery.settings, "R is recomputed for the new value"
    recoveries = app.recovery.recoveries
    frames(app, 3)
    assert app.recovery.recoveries == recoveries, "nothing is recomputed while nothing changes"

    # Keys: split view, 1:1 zoom.
    key(app, glfw.KEY_4)
    assert app.comparison.view_mode == "split"
    key(app, glfw.KEY_Z)
    assert app.view.zoom == 1

    # Divider drag to a quarter of the image area.
    area, scale = app.image_area()
    divider_x = (area[0] + app.view.split_x) / scale
    target_x = (area[0] + 0.25 * area[2]) / scale
    drag(app, (divider_x, 300), (target_x, 300))
    assert app.view.split == pytest.approx(0.25, abs=0.01)

    # Pan by dragging elsewhere, then zoom with the wheel around the cursor.
    offset = (app.view.offset_x, app.view.offset_y)
    drag(app, (area[0] / scale + 0.6 * area[2] / scale, 200), (area[0] / scale + 0.6 * area[2] / scale + 30, 220))
    assert (app.view.offset_x - offset[0], app.view.offset_y - offset[1]) == pytest.approx((30, 20))
    cursor = (area[0] / scale + 0.5 * area[2] / scale, 280)
    move(app, *cursor)
    frames(app, 1)
    under_cursor = app.view.view_to_image(cursor[0] * scale - area[0], cursor[1] * scale)
    app.platform.scroll_callback(app.window, 0, 2)  # two notches: 1x -> 2x -> 3x
    frames(app, 2)
    assert app.view.zoom == 3
    assert app.view.view_to_image(cursor[0] * scale - area[0], cursor[1] * scale) == pytest.approx(
        under_cursor, abs=0.5)

    # Back to 1:1 and screenshot: F left of the divider, R right of it, pixel for pixel.
    key(app, glfw.KEY_Z)
    frames(app, 1)
    app.step(capture=True)
    shot = app.screenshot() if app.last_screenshot is None else app.last_screenshot
    filtered = read_image(image_pair[1])
    recovered = app.engine.result()
    assert not np.array_equal(filtered, recovered), "the test pair must be changed by recovery"
    ox, oy = int(app.view.offset_x) + area[0], int(app.view.offset_y)
    split = area[0] + int(app.view.split_x)
    height, width = filtered.shape[:2]
    region = shot[oy:oy + height, ox:ox + width]
    columns = np.arange(width) + ox
    left_of, right_of = columns < split - 3, columns > split + 3  # the divider line is drawn on top
    np.testing.assert_array_equal(region[:, left_of], filtered[:, left_of])
    np.testing.assert_array_equal(region[:, right_of], recovered[:, right_of])

    # Flicker swaps the sides; the heat-map shows |R - F|.
    key(app, glfw.KEY_SPACE)
    assert app.comparison.side_names() == ("R", "F")
    key(app, glfw.KEY_5)
    assert app.comparison.view_mode == "difference"
    key(app, glfw.KEY_7)
    assert app.comparison.view_mode == "beta" and app.recovery.computed[1], "map views compute the maps"

    # Help overlay and the copied command line.
    key(app, glfw.KEY_H)
    assert app.panel.help_visible
    key(app, glfw.KEY_ESCAPE)
    assert not app.panel.help_visible
    key(app, glfw.KEY_C, glfw.MOD_CONTROL | glfw.MOD_SHIFT)
    copied = glfw.get_clipboard_string(None).decode()
    assert copied.startswith("aarecovery recover ") and f"--sigma-e {app.recovery.settings.sigma_e:g}" in copied


def test_copied_command_line_reproduces_the_shown_result(app, image_pair, tmp_path):
    import shlex

    import glfw

    import aarecovery
    from aarecovery.cli import build_parser, main
    from aarecovery.viewer.sources import PairSource

    assert app.opener.open(PairSource(*image_pair))
    frames(app, 3)
    left, top, right, bottom = app.widget_rects["sigma_e"]
    y = (top + bottom) / 2
    drag(app, (left + 0.5 * (right - left), y), (left + 0.63 * (right - left), y))
    assert app.recovery.settings.sigma_e != aarecovery.PARAMETERS["sigma_e"].default
    for mode in aarecovery.MODES:
        app.recovery.settings = app.recovery.settings.with_values(mode=mode)
        app.panel.save_path = str(tmp_path / f"r-{mode}.png")
        frames(app, 2)
        assert app.recovery.computed[0].mode == mode
        key(app, glfw.KEY_C, glfw.MOD_CONTROL | glfw.MOD_SHIFT)
        words = shlex.split(glfw.get_clipboard_string(None).decode())
        assert words[0] == "aarecovery"
        build_parser().parse_args(words[1:])  # the real parser accepts it (exits otherwise)
        assert main(words[1:]) == 0
        np.testing.assert_array_equal(aarecovery.read_image(app.panel.save_path), app.engine.result(),
                                      err_msg=f"mode {mode}")


def test_view_refuses_parameters_out_of_range(capsys):
    require_viewer_extra()
    from aarecovery.cli import main
    assert main(["view", "--sigma-e", "5"]) == 1
    error = capsys.readouterr().err
    assert error.startswith("aarecovery: error: sigma_e must be") and error.count("\n") == 1


def _pixels_of_colour(shot, rgba):
    target = np.rint(np.array([rgba.x, rgba.y, rgba.z]) * 255).astype(int)
    return (np.abs(shot.astype(int) - target) <= 2).all(axis=-1)


def test_slider_grab_never_covers_the_value(app, image_pair):
    """Issue 13 item 8: the grab hid digits of the value drawn on the track."""
    from imgui_bundle import imgui

    import aarecovery
    from aarecovery.viewer import ui
    from aarecovery.viewer.sources import PairSource

    assert app.opener.open(PairSource(*image_pair))
    frames(app, 3)
    style = imgui.get_style()  # the app's ImGui context is the current one

    def set_parameter(name):
        return lambda value: setattr(app.recovery, "settings", app.recovery.settings.with_values(**{name: value}))
    sliders = {name: (spec.minimum, spec.maximum, spec.logarithmic, set_parameter(name))
               for name, spec in aarecovery.PARAMETERS.items()}
    sliders["flicker_period"] = (*ui.FLICKER_PERIODS, False, lambda v: setattr(app.comparison, "flicker_period", v))
    sliders["difference_gain"] = (*ui.HEAT_MAP_GAINS, True, lambda v: setattr(app.comparison, "difference_gain", v))
    for key, (low, high, logarithmic, set_value) in sliders.items():
        middle = (low * high) ** 0.5 if logarithmic else (low + high) / 2
        for value in (low, type(low)(middle), high):
            set_value(value)
            frames(app, 2)
            app.step(capture=True)
            track = [int(round(v)) for v in app.widget_rects[key]]
            number = [int(round(v)) for v in app.widget_rects[f"{key} value"]]
            band = app.last_screenshot[track[1]:track[3]]
            grab = _pixels_of_colour(band, style.color_(imgui.Col_.slider_grab))
            text = band.min(axis=-1) > 200  # ImGui's text is white; nothing else in the panel is
            grab_columns = np.nonzero(grab.any(axis=0))[0]
            where = f"{key} = {value}"
            assert grab_columns.size and track[0] <= grab_columns[0] and grab_columns[-1] < track[2], where
            assert not text[:, grab_columns[0]:grab_columns[-1] + 1].any(), f"text under the grab: {where}"
            # The value: beside the track, inside the panel's clip rectangle, all of it drawn.
            assert track[2] <= number[0] and number[2] <= app.panel_width - style.window_padding.x / 2, where
            assert not grab[:, number[0]:number[2]].any(), where
            drawn = np.nonzero(text[:, number[0]:number[2]].any(axis=0))[0]
            assert drawn.size and drawn[0] <= 1 and drawn[-1] >= number[2] - number[0] - 2, where


def test_ctrl_click_on_a_slider_types_its_value(app, image_pair):
    import glfw

    from aarecovery.viewer.sources import PairSource

    assert app.opener.open(PairSource(*image_pair))
    frames(app, 3)
    app.platform.key_callback(app.window, glfw.KEY_LEFT_CONTROL, 0, glfw.PRESS, 0)
    move(app, *centre(app.widget_rects["sigma_e"]))
    frames(app, 1)
    for action in (glfw.PRESS, glfw.RELEASE):
        app.platform.mouse_button_callback(app.window, glfw.MOUSE_BUTTON_LEFT, action, glfw.MOD_CONTROL)
        frames(app, 1)
    app.platform.key_callback(app.window, glfw.KEY_LEFT_CONTROL, 0, glfw.RELEASE, glfw.MOD_CONTROL)
    frames(app, 1)
    for character in "0.0437":  # replaces the selected text of the field
        app.platform.char_callback(app.window, ord(character))
        frames(app, 1)
    key(app, glfw.KEY_ENTER)
    assert app.recovery.settings.sigma_e == pytest.approx(0.0437)
    assert app.recovery.computed[0] == app.recovery.settings


def test_saving_never_replaces_an_input_unless_confirmed(app, image_pair, tmp_path):
    from aarecovery import read_image
    from aarecovery.viewer.sources import PairSource

    assert app.opener.open(PairSource(*image_pair))
    frames(app, 2)
    before = open(image_pair[1], "rb").read()
    assert not app.saving.request(image_pair[1])
    assert app.panel.pending_overwrite is not None and "FILTERED input" in app.panel.pending_overwrite[1]
    frames(app, 2)
    assert open(image_pair[1], "rb").read() == before, "nothing is written before the confirmation"
    assert app.saving.confirm_overwrite()
    np.testing.assert_array_equal(read_image(image_pair[1]), app.engine.result())

    fresh = tmp_path / "fresh.png"
    assert app.saving.request(str(fresh))
    np.testing.assert_array_equal(read_image(fresh), app.engine.result())


def _error_pixels(shot):
    # The error text colour (255, 115, 102); glyph edges blend towards the background.
    red = shot.astype(int)
    return ((red[..., 0] > 200) & (red[..., 1] < 150) & (red[..., 2] < 140)).sum()


def test_bad_input_shows_a_message_and_keeps_running(app, image_pair, tmp_path):
    from aarecovery import write_image
    from aarecovery.viewer.sources import PairSource

    assert app.opener.open(PairSource(*image_pair))
    frames(app, 2)
    shown = app.recovery.pair

    garbage = tmp_path / "garbage.png"
    garbage.write_bytes(b"\x89PNG\r\n\x1a\n this is not a PNG")
    app.platform.drop_callback(app.window, [str(garbage), image_pair[1]])
    frames(app, 3)
    assert app.messages and app.messages[-1].error and "garbage.png" in app.messages[-1].text
    assert app.recovery.pair is shown
    app.step(capture=True)
    assert _error_pixels(app.last_screenshot) > 50, "the error is shown in the window"

    small = tmp_path / "small.png"
    write_image(small, np.zeros((10, 12, 3), np.uint8))
    app.platform.drop_callback(app.window, [image_pair[0], str(small)])
    frames(app, 2)
    assert "pixel for pixel" in app.messages[-1].text
    assert app.recovery.pair is shown and app.step(), "the app keeps running and showing the last good pair"
    assert app.recovery.computed is not None and app.recovery.computed[0] == app.recovery.settings

    # A single dropped file asks what it is; used as FILTERED it is checked like the others.
    app.platform.drop_callback(app.window, [str(small)])
    frames(app, 2)
    assert app.panel.pending_drop == str(small)
    assert not app.opener.use_dropped_as("filtered")
    assert "pixel for pixel" in app.messages[-1].text and app.step()


def test_screenshot_command(xvfb_display, image_pair, tmp_path):
    require_viewer_extra()
    from aarecovery import read_image
    from aarecovery.cli import main

    shot = tmp_path / "shot.png"
    assert main(["view", *image_pair, "--size", "640x400", "--screenshot", str(shot)]) == 0
    image = read_image(shot)
    assert image.shape == (400, 640, 3) and image.std() > 10


def test_missing_extra_message(monkeypatch, capsys):
    import sys
    from aarecovery.cli import main
    monkeypatch.setitem(sys.modules, "imgui_bundle", None)  # as if the extra were not installed
    assert main(["view"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "needs the viewer extra" in err and "[viewer]'" in err


def click(app, point):
    press(app, *point)
    frames(app, 1)
    release(app, *point)
    frames(app, 2)


def test_strength_box_and_slider_override_the_safe_default(app, image_pair):
    from aarecovery.viewer.sources import PairSource
    from aarecovery.viewer.status import plan_line

    assert app.opener.open(PairSource(*image_pair))
    frames(app, 3)
    chosen = app.engine.last_plan.strength
    assert app.recovery.settings.strength is None and "strength" not in app.widget_rects
    # The summary waits until the result has rested, then the status line gives the share.
    app.recovery.refresh_summary(app.recovery._computed_at + 2 * app.recovery.SUMMARY_DELAY)
    assert app.recovery.summary is not None and app.recovery.summary.plan == app.engine.last_plan
    assert not app.recovery.refresh_summary(), "one summary per result"
    assert "edge pixels repaired" in plan_line(app.engine, app.recovery.summary).text

    click(app, centre(app.widget_rects["strength auto"]))
    assert app.recovery.settings.strength == chosen, "unticked, the slider starts at the chosen strength"
    left, top, right, bottom = app.widget_rects["strength"]
    drag(app, (left + 0.5 * (right - left), (top + bottom) / 2), (left + 0.2 * (right - left), (top + bottom) / 2))
    asked = app.recovery.settings.strength
    assert 0.05 < asked < 0.45
    assert app.engine.last_plan.strength == pytest.approx(asked) and "as asked" in app.engine.last_plan.reason
    from aarecovery.viewer.settings import command_line
    assert "--strength " + str(np.float32(asked)) in command_line(PairSource(*image_pair), app.recovery.settings, "r.png")

    click(app, centre(app.widget_rects["strength auto"]))
    assert app.recovery.settings.strength is None
    assert app.engine.last_plan.strength == chosen


def test_every_slider_label_is_drawn_whole_inside_the_panel(app, image_pair, tmp_path):
    """Issue 20 item 12: with its "auto" box unticked the strength slider took the full item
    width after the box, and its label was cut at the panel's edge to "streng"."""
    from imgui_bundle import imgui

    import aarecovery
    from aarecovery.viewer.sources import PairSource

    assert app.opener.open(PairSource(*image_pair))
    frames(app, 3)
    click(app, centre(app.widget_rects["strength auto"]))
    frames(app, 2)
    app.step(capture=True)
    aarecovery.write_image(tmp_path / "panel.png", app.last_screenshot[:, :int(app.panel_width)])
    style = imgui.get_style()
    for key in aarecovery.PARAMETERS:
        left, top, right, bottom = (int(round(v)) for v in app.widget_rects[f"{key} label"])
        assert right <= app.panel_width - style.window_padding.x / 2, (key, right, app.panel_width)
        text = app.last_screenshot[top:bottom, left:right].min(axis=-1) > 200
        drawn = np.nonzero(text.any(axis=0))[0]
        assert drawn.size and drawn[-1] >= right - left - 3, (key, drawn[-1:], right - left)


def test_the_window_asks_for_gl_4_3_first(monkeypatch):
    # NVIDIA's drivers make exactly the version asked for, and the engine in the window runs
    # its compute path only on 4.3: the window asks for it first (Mesa makes 4.5 either way).
    require_viewer_extra()
    import glfw
    from aarecovery.viewer import window as viewer_window
    asked = []
    real = glfw.window_hint

    def recording(hint, value):
        if hint in (glfw.CONTEXT_VERSION_MAJOR, glfw.CONTEXT_VERSION_MINOR):
            asked.append(value)
        return real(hint, value)

    monkeypatch.setattr(viewer_window.glfw, "window_hint", recording)
    handle, context = viewer_window.open_window((64, 48), visible=False)
    try:
        assert asked[:2] == [4, 3] and context.version_code >= 430
    finally:
        viewer_window.close_window(handle, context)
