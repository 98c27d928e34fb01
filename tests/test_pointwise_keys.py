"""Gradient maps of a colour image's Rec. 601 grey (OpenCV, Pillow) are point-wise filters."""

from importlib import resources

import numpy as np
from PIL import Image, ImageOps

import aarecovery
from aarecovery.plan.calibration import EDGE_GRADIENT
from aarecovery.plan.pointwise import POINTWISE_SHARE, fit_pointwise, key_of
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
