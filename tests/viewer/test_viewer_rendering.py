"""The image view's and the ImGui renderer's pixels, in a standalone EGL context."""

import numpy as np
import pytest

from conftest import require_viewer_extra
from aarecovery.viewer.image_view import ImageSource, ImageView, Layer
from aarecovery.viewer.view_state import ViewState

VIEW = (240, 160)


def texture(context, pixels):
    """An RGBA8 texture holding a uint8 (H, W, 4) array, row 0 first."""
    pixels = np.ascontiguousarray(pixels, np.uint8)
    return context.texture((pixels.shape[1], pixels.shape[0]), 4, pixels.tobytes())


def random_image(seed, height=20, width=30):
    pixels = np.random.default_rng(seed).integers(0, 256, (height, width, 4), dtype=np.uint8)
    pixels[..., 3] = 255
    return pixels


def render(context, view, left, right=None):
    """Draw the layers into a fresh framebuffer; return RGB uint8, row 0 at the top."""
    framebuffer = context.simple_framebuffer(VIEW)
    framebuffer.use()
    framebuffer.clear(0, 0, 0, 1)
    image_view = ImageView(context)
    try:
        image_view.draw((0, 0, *VIEW), view, left, right)
        data = framebuffer.read(components=3, alignment=1)
    finally:
        image_view.release()
        framebuffer.release()
    return np.frombuffer(data, np.uint8).reshape(VIEW[1], VIEW[0], 3)[::-1]


def view_of(width, height, zoom):
    state = ViewState(view_width=VIEW[0], view_height=VIEW[1])
    state.set_image_size(width, height)
    state.zoom_at(0, 0, zoom)
    state.offset_x, state.offset_y = 0, 0
    return state


def test_split_shows_f_left_of_the_divider_and_r_right_of_it(egl_context):
    filtered, recovered = random_image(1), random_image(2)
    f_source = ImageSource(texture(egl_context, filtered), None, False)
    r_source = ImageSource(texture(egl_context, recovered), None, False)
    view = view_of(30, 20, 8)  # the image covers the whole 240x160 view
    view.set_split_at(100)     # mid-texel: texel column 12 is cut by the divider
    shot = render(egl_context, view, Layer.colour(f_source), Layer.colour(r_source))
    rows, columns = np.mgrid[0:VIEW[1], 0:VIEW[0]]
    texels_f = filtered[rows // 8, columns // 8, :3]
    texels_r = recovered[rows // 8, columns // 8, :3]
    np.testing.assert_array_equal(shot[:, :100], texels_f[:, :100])
    np.testing.assert_array_equal(shot[:, 100:], texels_r[:, 100:])


def test_heat_map_is_zero_where_r_equals_f(egl_context):
    filtered = random_image(3)
    recovered = filtered.copy()
    recovered[:, 15:, 0] ^= 0x80  # differ by 128 in red on the right half only
    f_source = ImageSource(texture(egl_context, filtered), None, False)
    r_source = ImageSource(texture(egl_context, recovered), None, False)
    shot = render(egl_context, view_of(30, 20, 8), Layer.difference(r_source, f_source, gain=1.0))
    assert not shot[:, :15 * 8].any(), "the heat-map must be exactly black where R = F"
    # |difference| = 128/255 ~ 0.502 -> heat = (1, 0.506, 0): full red, half green.
    right = shot[:, 15 * 8:].reshape(-1, 3)
    assert (right[:, 0] == 255).all() and (np.abs(right[:, 1].astype(int) - 129) <= 2).all()
    assert not right[:, 2].any()


@pytest.mark.parametrize("zoom", [2, 5, 32])
def test_zoom_shows_whole_texels(egl_context, zoom):
    image = random_image(4, 10, 12)
    source = ImageSource(texture(egl_context, image), None, False)
    state = ViewState(view_width=VIEW[0], view_height=VIEW[1])
    state.set_image_size(12, 10)
    state.zoom_at(77.3, 51.8, zoom)  # around an arbitrary cursor, as the wheel does
    shot = render(egl_context, state, Layer.colour(source))
    ox, oy = int(state.offset_x), int(state.offset_y)
    for row in range(10):
        for column in range(12):
            top, left = oy + row * zoom, ox + column * zoom
            block = shot[max(top, 0):max(top + zoom, 0), max(left, 0):max(left + zoom, 0)]
            if block.size == 0:
                continue  # this texel is off screen at this zoom
            # Every screen pixel of the texel's block shows exactly that texel: no blending.
            assert (block == image[row, column, :3]).all(), (row, column)


def test_zoomed_out_view_averages_neighbouring_texels(egl_context):
    image = np.zeros((40, 60, 4), np.uint8)
    image[..., 3] = 255
    image[:, 1::2, :3] = 255  # one-pixel stripes: nearest minification would alias them
    source = ImageSource(texture(egl_context, image), None, False)
    state = view_of(60, 40, 0.5)
    shot = render(egl_context, state, Layer.colour(source))
    inside = shot[:20, :30].astype(int)
    assert (np.abs(inside - 128) <= 2).all()


def test_linear_textures_are_srgb_encoded_for_display(egl_context):
    linear = np.full((2, 2, 4), 0.5, np.float32)
    linear[..., 3] = 1
    tex = egl_context.texture((2, 2), 4, linear.tobytes(), dtype="f4")
    shot = render(egl_context, view_of(2, 2, 8), Layer.colour(ImageSource(tex, None, True)))
    # sRGB(0.5) = 0.7354 -> 187.5
    assert (np.abs(shot[:16, :16].astype(int) - 188) <= 1).all()


def test_map_channel_times_gain_is_grey(egl_context):
    pixels = np.zeros((4, 4, 4), np.float32)
    pixels[..., 2] = 0.1  # the map lives in channel 2
    pixels[..., 0] = 1.0  # other channels must not leak in
    tex = egl_context.texture((4, 4), 4, pixels.tobytes(), dtype="f4")
    shot = render(egl_context, view_of(4, 4, 8), Layer.map(ImageSource(tex, 2, False), gain=5.0))
    assert (np.abs(shot[:32, :32].astype(int) - 128) <= 1).all()


def test_transparent_pixels_show_a_checkerboard(egl_context):
    image = np.zeros((4, 4, 4), np.uint8)  # fully transparent
    shot = render(egl_context, view_of(4, 4, 8), Layer.colour(ImageSource(texture(egl_context, image), None, False)))
    values = set(np.unique(shot[:32, :32]))
    assert values == {102, 153}  # 0.4 and 0.6 grey


def test_imgui_renderer_draws_widgets_and_uploads_the_font(egl_context):
    require_viewer_extra()
    import glfw  # noqa: F401  (first, as the viewer does)
    from imgui_bundle import imgui

    from aarecovery.viewer.imgui_renderer import ImGuiRenderer
    imgui_context = imgui.create_context()
    framebuffer = egl_context.simple_framebuffer((320, 200))
    renderer = ImGuiRenderer(egl_context)
    try:
        io = imgui.get_io()
        io.set_ini_filename(None)
        io.display_size = imgui.ImVec2(320, 200)
        io.delta_time = 1 / 60
        for _ in range(2):
            imgui.new_frame()
            imgui.set_next_window_pos(imgui.ImVec2(20, 20))
            imgui.set_next_window_size(imgui.ImVec2(150, 100))
            imgui.begin("Test window")
            imgui.text("some text")
            imgui.end()
            imgui.render()
            framebuffer.use()
            framebuffer.clear(0, 0, 0, 1)
            renderer.render(imgui.get_draw_data(), framebuffer)
        shot = np.frombuffer(framebuffer.read(components=3, alignment=1), np.uint8).reshape(200, 320, 3)[::-1]
        assert not shot[:18].any() and not shot[:, :18].any(), "nothing is drawn outside the window"
        assert not shot[125:].any() and not shot[:, 175:].any(), "the scissor rectangle clips the window"
        window = shot[20:120, 20:170].astype(int)
        assert window.any(axis=-1).mean() > 0.9, "the window background is drawn"
        # Text is brighter than anything else in the default dark style: glyphs were rasterised
        # from the font texture ImGui asked the renderer to create.
        assert (window.min(axis=-1) > 200).sum() > 30
        assert all(data.status == imgui.ImTextureStatus.ok for data in imgui.get_platform_io().textures)
    finally:
        renderer.release()
        framebuffer.release()
        imgui.destroy_context(imgui_context)
