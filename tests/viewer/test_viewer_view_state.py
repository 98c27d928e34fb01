"""Zoom, pan and split arithmetic (pure Python)."""

import pytest

from aarecovery.viewer.view_state import MAX_ZOOM, ViewState


def make_view(image=(200, 100), view=(800, 600)):
    state = ViewState(view_width=view[0], view_height=view[1])
    state.set_image_size(*image)
    return state


def test_fit_magnifies_by_whole_numbers_and_centres():
    state = make_view((200, 100), (800, 600))
    assert state.zoom == 4  # 800/200 = 4 exactly, 600/100 = 6
    assert state.image_to_view(0, 0) == (0, 100)
    assert state.image_to_view(200, 100) == (800, 500)
    state.set_view_size(700, 600)
    state.fit()
    assert state.zoom == 3  # 3.5 rounds down so every texel is the same size


def test_fit_minifies_exactly():
    state = make_view((4000, 1000), (800, 600))
    assert state.zoom == pytest.approx(0.2)
    left, top = state.image_to_view(0, 0)
    right, bottom = state.image_to_view(4000, 1000)
    assert (left, right) == pytest.approx((0, 800))
    assert (top + bottom) / 2 == pytest.approx(300)


def test_zoom_at_keeps_the_point_under_the_cursor():
    state = make_view((200, 100), (800, 600))
    before = state.view_to_image(123, 321)
    state.zoom_at(123, 321, 16)
    assert state.zoom == 16
    assert state.view_to_image(123, 321) == pytest.approx(before, abs=0.5 / 16)


def test_wheel_steps_stop_at_32x():
    state = make_view((200, 100), (800, 600))
    for _ in range(20):
        state.step_zoom_at(400, 300, 1)
    assert state.zoom == MAX_ZOOM == 32
    state.step_zoom_at(400, 300, -1)
    assert state.zoom == 24


def test_magnified_offsets_are_whole_pixels():
    state = make_view((201, 99), (797, 601))
    state.zoom_at(333.3, 222.7, 8)
    assert state.offset_x == int(state.offset_x) and state.offset_y == int(state.offset_y)


def test_one_to_one_and_pixel_lookup():
    state = make_view((200, 100), (800, 600))
    state.one_to_one()
    assert state.zoom == 1
    x, y = state.image_to_view(17, 42)
    assert state.pixel_at(x + 0.5, y + 0.5) == (17, 42)
    assert state.pixel_at(-1000, -1000) is None


def test_pan_cannot_lose_the_image():
    state = make_view((200, 100), (800, 600))
    state.pan(100000, 100000)
    left, top = state.image_to_view(0, 0)
    assert left <= 800 - 48 and top <= 600 - 48
    state.pan(-1e6, -1e6)
    right, bottom = state.image_to_view(200, 100)
    assert right >= 48 and bottom >= 48


def test_split_divider():
    state = make_view()
    state.set_split_at(200)
    assert state.split == pytest.approx(0.25) and state.split_x == pytest.approx(200)
    assert state.near_divider(204, 6) and not state.near_divider(210, 6)
    state.set_split_at(-5)
    assert state.split == 0


def test_resize_keeps_the_centre():
    state = make_view((200, 100), (800, 600))
    state.zoom_at(400, 300, 8)
    centre = state.view_to_image(400, 300)
    state.set_view_size(1000, 700)
    assert state.view_to_image(500, 350) == pytest.approx(centre, abs=1 / 8)
