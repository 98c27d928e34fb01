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

    from aarecovery import read_image
    from aarecovery.viewer.sources import PairSource

    assert app.open(PairSource(*image_pair))
    frames(app, 3)
    assert app.recoveries == 1 and app.computed[0] == app.settings

    # Slider drag: sigma_e from 30% to 80% of its (logarithmic) track.
    left, top, right, bottom = app.widget_rects["sigma_e"]
    y = (top + bottom) / 2
    drag(app, (left + 0.3 * (right - left), y), (left + 0.8 * (right - left), y))
    # The track runs from 0.0005 to 0.5 logarithmically; its ends are inset by the grab's half width.
    assert 0.0005 * 1000 ** 0.7 < app.settings.sigma_e < 0.0005 * 1000 ** 0.9
    assert app.computed[0] == app.settings, "R is recomputed for the new value"
    recoveries = app.recoveries
    frames(app, 3)
    assert app.recoveries == recoveries, "nothing is recomputed while nothing changes"

    # Keys: split view, 1:1 zoom.
    key(app, glfw.KEY_4)
    assert app.view_mode == "split"
    key(app, glfw.KEY_Z)
    assert app.view.zoom == 1

    # Divider drag to a quarter of the image area.
    area, scale = app._area()
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
    assert app.side_names() == ("R", "F")
    key(app, glfw.KEY_5)
    assert app.view_mode == "difference"
    key(app, glfw.KEY_7)
    assert app.view_mode == "beta" and app.computed[1], "map views compute the maps"

    # Help overlay and the copied command line.
    key(app, glfw.KEY_H)
    assert app.help_visible
    key(app, glfw.KEY_ESCAPE)
    assert not app.help_visible
    key(app, glfw.KEY_C, glfw.MOD_CONTROL | glfw.MOD_SHIFT)
    copied = glfw.get_clipboard_string(None).decode()
    assert copied.startswith("aarecovery recover ") and f"--sigma-e {app.settings.sigma_e:g}" in copied



def test_saving_never_replaces_an_input_unless_confirmed(app, image_pair, tmp_path):
    from aarecovery import read_image
    from aarecovery.viewer.sources import PairSource

    assert app.open(PairSource(*image_pair))
    frames(app, 2)
    before = open(image_pair[1], "rb").read()
    assert not app.request_save(image_pair[1])
    assert app.pending_overwrite is not None and "FILTERED input" in app.pending_overwrite[1]
    frames(app, 2)
    assert open(image_pair[1], "rb").read() == before, "nothing is written before the confirmation"
    assert app.confirm_overwrite()
    np.testing.assert_array_equal(read_image(image_pair[1]), app.engine.result())

    fresh = tmp_path / "fresh.png"
    assert app.request_save(str(fresh))
    np.testing.assert_array_equal(read_image(fresh), app.engine.result())


def _error_pixels(shot):
    # The error text colour (255, 115, 102); glyph edges blend towards the background.
    red = shot.astype(int)
    return ((red[..., 0] > 200) & (red[..., 1] < 150) & (red[..., 2] < 140)).sum()


def test_bad_input_shows_a_message_and_keeps_running(app, image_pair, tmp_path):
    from aarecovery import write_image
    from aarecovery.viewer.sources import PairSource

    assert app.open(PairSource(*image_pair))
    frames(app, 2)
    shown = app.pair

    garbage = tmp_path / "garbage.png"
    garbage.write_bytes(b"\x89PNG\r\n\x1a\n this is not a PNG")
    app.platform.drop_callback(app.window, [str(garbage), image_pair[1]])
    frames(app, 3)
    assert app.messages and app.messages[-1].error and "garbage.png" in app.messages[-1].text
    assert app.pair is shown
    app.step(capture=True)
    assert _error_pixels(app.last_screenshot) > 50, "the error is shown in the window"

    small = tmp_path / "small.png"
    write_image(small, np.zeros((10, 12, 3), np.uint8))
    app.platform.drop_callback(app.window, [image_pair[0], str(small)])
    frames(app, 2)
    assert "pixel for pixel" in app.messages[-1].text
    assert app.pair is shown and app.step(), "the app keeps running and showing the last good pair"
    assert app.computed is not None and app.computed[0] == app.settings

    # A single dropped file asks what it is; used as FILTERED it is checked like the others.
    app.platform.drop_callback(app.window, [str(small)])
    frames(app, 2)
    assert app.pending_drop == str(small)
    assert not app.use_dropped_as("filtered")
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
