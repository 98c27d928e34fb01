"""Gradient maps of a colour image's Rec. 601 grey (OpenCV, Pillow) and curves of its YCbCr luma
with the chroma kept (their histogram equalization of a colour image) are point-wise filters."""

from importlib import resources

import numpy as np
import pytest
from PIL import Image, ImageOps

import aarecovery
from aarecovery.plan.calibration import EDGE_GRADIENT
from aarecovery.plan.pointwise import POINTWISE_SHARE, fit_pointwise, key_of
from aarecovery.spec.pure_colours import SHIFT_KEYS
from aarecovery.plan.resample import box_downsample
from aarecovery.spec.sobel import gradient_magnitude


def photo(name="photo_coffee.jpg", side=384):
    """A colour photo from the package data, box-downsampled by 4 as the real-tools suite does: uint8."""
    path = resources.files("aarecovery") / "data" / name
    image = np.asarray(Image.open(path).convert("RGB"), np.float32)[:side, :side] / 255
    return np.rint(np.clip(box_downsample(image, 4, "linear"), 0, 1) * 255).astype(np.uint8)


def rainbow(levels):
    """A steep, non-monotone colour ramp of 8-bit grey levels (a TURBO-like map), uint8 (N, 3)."""
    x = levels / 255.0
    ramp = np.stack([0.5 + 0.5 * np.sin(6 * x), 0.5 + 0.5 * np.sin(6 * x + 2), 0.5 + 0.5 * np.sin(6 * x + 4)], -1)
    return np.rint(ramp * 255).astype(np.uint8)


def test_luma601_key_is_the_8_bit_grey_at_its_bin_centre():
    colour = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]], np.float32)
    expected = (np.rint(np.array([0.299, 0.587, 0.114, 1.0]) * 255) + 0.5) / 256
    np.testing.assert_allclose(key_of(colour, "luma601"), expected, atol=1e-7)


def test_a_map_of_the_rec601_grey_is_fitted_point_wise():
    original = photo()
    grey = np.rint(original.astype(np.float64) @ [0.299, 0.587, 0.114]).astype(np.int64)
    filtered = rainbow(np.arange(256))[grey]
    o, f = original.astype(np.float32) / 255, filtered.astype(np.float32) / 255
    transfer = fit_pointwise(o, f, gradient_magnitude(o) >= EDGE_GRADIENT)
    assert transfer.key == "luma601" and transfer.consistency >= POINTWISE_SHARE
    # Rec. 709 luma, the only luma key before, explains far fewer edge pixels.
    assert next(t for t in transfer.alternatives if t.key == "luma").consistency < 0.8


def test_pillow_colorize_of_a_photo_is_repaired_not_kept():
    # Pillow's own gradient map (ImageOps.colorize of convert("L")), on a colour photo: the
    # plan used to call it a neighbourhood filter on a textured image and keep F.
    original = photo()
    grey = Image.fromarray(original).convert("L")
    filtered = np.asarray(ImageOps.colorize(grey, black="navy", white="yellow", mid="red").convert("RGB"))
    engine = aarecovery.Engine("numpy")
    engine.set_images(original, filtered)
    plan = engine.plan()
    assert plan.decision == aarecovery.Decision.POINTWISE_CALIBRATED, plan.reason
    assert plan.strength > 0


def _pillow_ycbcr_equalize(rgb):
    luma, blue, red = Image.fromarray(rgb).convert("YCbCr").split()
    return np.asarray(Image.merge("YCbCr", (ImageOps.equalize(luma), blue, red)).convert("RGB"))


def _opencv_ycrcb_equalize(rgb):
    cv2 = pytest.importorskip("cv2", reason="opencv-python-headless (extra 'test') runs OpenCV's equalization")
    ycrcb = cv2.cvtColor(rgb, cv2.COLOR_RGB2YCrCb)
    ycrcb[..., 0] = cv2.equalizeHist(np.ascontiguousarray(ycrcb[..., 0]))
    return cv2.cvtColor(ycrcb, cv2.COLOR_YCrCb2RGB)


@pytest.mark.parametrize("tool, key", [(_pillow_ycbcr_equalize, "luma601_floor_shift"),
                                       (_opencv_ycrcb_equalize, "luma601_shift")])
def test_an_equalized_ycbcr_luma_is_a_luma_shift(tool, key):
    """F = clip(O + s(Y)): Pillow truncates its YCbCr luma, OpenCV rounds it; each is fitted by its
    own key, and no per-channel or luma table explains the steep curve as well."""
    original = photo()
    o, f = original.astype(np.float32) / 255, tool(original).astype(np.float32) / 255
    transfer = fit_pointwise(o, f, gradient_magnitude(o) >= EDGE_GRADIENT)
    assert transfer.key == key and transfer.consistency >= POINTWISE_SHARE, (transfer.key, transfer.consistency)
    assert all(t.consistency < POINTWISE_SHARE for t in transfer.alternatives if t.key not in SHIFT_KEYS)
    miss = np.abs(transfer(o) - f).max(axis=-1)
    assert np.mean(miss <= 3 / 255) >= POINTWISE_SHARE


def test_a_photo_under_an_equalized_ycbcr_luma_is_repaired_not_kept():
    # It was a neighbourhood filter on a textured image to every other key: F kept.
    original = photo()
    engine = aarecovery.Engine("numpy")
    engine.set_images(original, _pillow_ycbcr_equalize(original))
    plan = engine.plan()
    assert plan.decision == aarecovery.Decision.POINTWISE_CALIBRATED, plan.reason
    assert "luma601_floor_shift" in plan.reason and plan.strength > 0


def _drawing_pair(tool, space="srgb"):
    """The real-tools suite's serif page antialiased in `space` (hard-edged, coloured inks),
    8-bit, and `tool` of it."""
    from aarecovery.lab.realtools import FAMILIES, render_scene
    scene, _ = render_scene("serif", 64)
    original = np.rint(np.clip(box_downsample(scene, FAMILIES["serif"].k, space), 0, 1) * 255).astype(np.uint8)
    return original, tool(original)


@pytest.mark.parametrize("space", ["srgb", "linear"])
@pytest.mark.parametrize("tool, key", [(_pillow_ycbcr_equalize, "luma601_floor_shift"),
                                       (_opencv_ycrcb_equalize, "luma601_shift")])
def test_thin_features_under_a_luma_shift_get_pure_colours_on_every_backend(tool, key, space, gl_path):
    """A drawing under an equalized YCbCr luma: the shift key's table extends thin features to
    their pure colours (tuning half, Pillow's: maps 0.31-0.32 -> 0.61-0.64, serif 0.76 ->
    0.98), and the GL passes (TABLE_KEY 6 and 7) give the NumPy specification's result."""
    from parity import assert_results_agree
    original, filtered = _drawing_pair(tool, space)
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(original, filtered)
        plan = engine.plan()
        assert plan.decision == aarecovery.Decision.POINTWISE_HARD_EDGED, plan.reason
        assert plan.blend_space == space, plan.reason
        assert plan.pure_colours is not None and plan.pure_colours.key == key, plan.reason
        engine.run(plan)
        expected = engine.result()
    assert np.abs(expected.astype(int) - filtered).max() > 0
    with aarecovery.Engine("gl", gl_path=gl_path) as engine:
        engine.set_images(original, filtered)
        engine.run(plan)
        assert_results_agree(engine.result(), expected, f"{gl_path} {key}")


def test_a_shift_table_maps_8_bit_colours_as_its_transfer():
    """The specification's f (spec.pure_colours.filtered_colour, what the passes read) is the
    fitted transfer on O's own colours: the same grey level, the same offset."""
    from aarecovery.plan.pure_colours import pure_colour_prior
    from aarecovery.spec.pure_colours import filtered_colour
    original, filtered = _drawing_pair(_pillow_ycbcr_equalize)
    o, f = original.astype(np.float32) / 255, filtered.astype(np.float32) / 255
    edges = gradient_magnitude(o) >= EDGE_GRADIENT
    transfer = fit_pointwise(o, f, edges)
    prior = pure_colour_prior(o, transfer, "srgb", f, edges)
    colours = o.reshape(-1, 3).T
    planes = np.concatenate([colours, np.ones((1, colours.shape[1]), np.float32)])
    np.testing.assert_allclose(filtered_colour(planes, prior, "srgb")[:3].T, transfer(o).reshape(-1, 3), atol=1e-6)
