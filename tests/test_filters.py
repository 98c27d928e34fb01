"""Each filter against hand-checked values on tiny images."""

import numpy as np
import pytest

from aarecovery import InputError, filters


def pixels(*colours):
    """A 1 x N float32 RGB image of the given colours."""
    return np.asarray([colours], np.float32)


def test_threshold_splits_on_luma():
    image = pixels((0.49, 0.49, 0.49), (0.51, 0.51, 0.51), (1, 0, 0), (0, 1, 0))
    out = filters.threshold(image, level=0.5)
    # red has luma 0.2126 (dark), green 0.7152 (light)
    np.testing.assert_array_equal(out[0, :, 0], [0, 1, 0, 1])
    np.testing.assert_array_equal(out[0, :, 1], out[0, :, 0])


def test_levels_gamma_and_stretch():
    image = pixels((0.25, 0.5, 1.0))
    np.testing.assert_allclose(filters.levels(image, gamma=2.0)[0, 0], [0.5, 0.70710677, 1.0], rtol=1e-6)
    stretched = filters.levels(image, black=0.25, white=0.75, gamma=1.0)
    np.testing.assert_allclose(stretched[0, 0], [0.0, 0.5, 1.0], atol=1e-7)


def test_tone_map_reinhard_values():
    # sRGB 0.5 decodes to 0.21404; exposure 1 and white 1: L (1 + L) / (1 + L) = L, the identity.
    image = pixels((0.5, 0.5, 0.5))
    np.testing.assert_allclose(filters.tone_map(image, exposure=1.0, white=1.0), image, atol=1e-6)
    # Without the white term (huge white) grey 0.21404 maps to 0.21404 / 1.21404 = 0.17631 linear.
    out = filters.tone_map(image, exposure=1.0, white=1e6)
    expected = 1.055 * (0.21404114 / 1.21404114) ** (1 / 2.4) - 0.055
    np.testing.assert_allclose(out[0, 0], expected, atol=1e-5)


def test_posterize_rounds_to_levels():
    image = pixels((0.1, 0.2, 0.9), (0.5, 0.49, 0.84))
    out = filters.posterize(image, steps=3)
    np.testing.assert_allclose(out[0], [[0, 0, 1], [0.5, 0.5, 1]])


def test_equalization_curve_is_applied_to_another_image():
    source = np.zeros((2, 2, 3), np.float32)
    source[0, :] = 0.25  # half the pixels at luma 0.25, half at 0
    curve = filters.equalization_transfer(source, bins=4)
    # cumulative share at luma 0, 0.25, 0.5, 0.75, 1: the black half lies in bin [0, 0.25)
    np.testing.assert_allclose(curve, [0, 0.5, 1, 1, 1])
    other = pixels((0.125, 0.125, 0.125), (0.375, 0.375, 0.375))
    # luma 0.125 is halfway between curve points 0 (0) and 0.25 (0.5); 0.375 between 0.5 and 1
    np.testing.assert_allclose(filters.equalize_histogram(other, curve)[0], [[0.25] * 3, [0.75] * 3], atol=1e-6)


def test_gradient_map_interpolates_the_ramp():
    ramp = ((0, 0, 0), (1, 0, 0), (1, 1, 1))
    out = filters.gradient_map(pixels((0, 0, 0), (0.25, 0.25, 0.25), (1, 1, 1)), ramp)
    np.testing.assert_allclose(out[0], [[0, 0, 0], [0.5, 0, 0], [1, 1, 1]], atol=1e-6)


def test_replace_colour_swaps_only_the_selected_hue():
    image = pixels((1, 0, 0), (0, 1, 0), (0.6, 0.5, 0.5))
    out = filters.replace_colour(image, hue=0, width=40, new_hue=240, min_saturation=0.25)
    np.testing.assert_allclose(out[0, 0], [0, 0, 1], atol=1e-6)  # red becomes blue
    np.testing.assert_array_equal(out[0, 1], image[0, 1])  # green is outside the range
    np.testing.assert_array_equal(out[0, 2], image[0, 2])  # saturation 0.17 is below the minimum


def test_colour_to_grey_keeps_greys_and_lightens_the_bright_hue():
    greys = pixels((0.2, 0.2, 0.2), (0.7, 0.7, 0.7))
    np.testing.assert_allclose(filters.colour_to_grey(greys), greys, atol=2e-3)
    red, blue = filters.colour_to_grey(pixels((1, 0, 0), (0, 0, 1)), chroma_weight=0.6, bright_hue=30)[0]
    plain = filters.colour_to_grey(pixels((1, 0, 0)), chroma_weight=0.0)[0, 0]
    assert red[0] == red[1] == red[2]
    assert red[0] > plain[0] + 0.1  # red (hue ~40 degrees) is lifted well above its lightness
    assert red[0] > blue[0]


def test_gaussian_blur_spreads_a_dot_and_keeps_the_mean():
    image = np.zeros((9, 9, 3), np.float32)
    image[4, 4] = 1
    out = filters.gaussian_blur(image, sigma=1.0)
    assert out.sum() == pytest.approx(3.0, rel=1e-5)
    # separable 1-D weight at offset 0 for sigma 1 on a 7-tap kernel: 0.39905
    assert out[4, 4, 0] == pytest.approx(0.39905 ** 2, rel=1e-3)


def test_unsharp_mask_overshoots_and_clips_at_an_edge():
    image = np.full((5, 8, 3), 0.2, np.float32)
    image[:, 4:] = 0.8
    out = filters.unsharp_mask(image, radius=1.0, amount=1.0)
    assert out[2, 3, 0] < 0.2 and out[2, 4, 0] > 0.8  # the dark side darker, the light side lighter
    np.testing.assert_allclose(out[2, 0], 0.2, atol=1e-6)  # flat parts untouched
    assert out.min() >= 0 and out.max() <= 1


def test_bilateral_keeps_a_strong_edge_and_smooths_noise():
    rng = np.random.default_rng(0)
    image = np.full((24, 24, 3), 0.2, np.float32)
    image[:, 12:] = 0.9
    noisy = np.clip(image + rng.normal(0, 0.02, image.shape).astype(np.float32), 0, 1)
    out = filters.bilateral(noisy, sigma_spatial=2.0, sigma_range=0.1, iterations=2)
    assert out[:, 2:8].std() < noisy[:, 2:8].std() / 2
    assert out[:, :10].mean() == pytest.approx(0.2, abs=0.02)
    assert out[:, 14:].mean() == pytest.approx(0.9, abs=0.02)


def test_alpha_passes_through():
    image = np.zeros((3, 3, 4), np.float32)
    image[..., 3] = 0.5
    image[1, 1, :3] = 1
    for name in filters.FILTERS:
        out = filters.apply(name, image)
        assert out.shape == image.shape and out.dtype == np.float32
        np.testing.assert_array_equal(out[..., 3], 0.5)


def test_apply_converts_layouts_and_scales_spatial_parameters():
    grey = np.array([[0, 100, 200]], np.uint8)
    out = filters.apply("threshold", grey, level=0.5)
    assert out.dtype == np.uint8 and out.shape == grey.shape
    np.testing.assert_array_equal(out, [[0, 0, 255]])
    image = np.zeros((21, 21, 3), np.float32)
    image[10, 10] = 1
    np.testing.assert_allclose(filters.apply("blur", image, scale=2, sigma=1.0),
                               filters.gaussian_blur(image, sigma=2.0))


def test_errors_name_the_bad_value():
    with pytest.raises(InputError, match="'sharpen'"):
        filters.apply("sharpen", np.zeros((2, 2, 3), np.float32))
    with pytest.raises(InputError, match="'radius'"):
        filters.apply("threshold", np.zeros((2, 2, 3), np.float32), radius=2)
    with pytest.raises(InputError, match="steps"):
        filters.posterize(np.zeros((2, 2, 3), np.float32), steps=1)
    with pytest.raises(InputError, match="float32"):
        filters.threshold(np.zeros((2, 2, 3), np.uint8))


def test_filter_command_applies_and_recovers(tmp_path, capsys):
    from PIL import Image
    from aarecovery.cli import main
    source = tmp_path / "in.png"
    ramp = np.tile(np.linspace(0, 255, 32).astype(np.uint8), (16, 1))
    Image.fromarray(ramp).save(source)
    out = tmp_path / "out.png"
    assert main(["filter", "threshold", str(source), "-o", str(out), "--param", "level=0.5"]) == 0
    with Image.open(out) as image:
        values = np.asarray(image)
    assert set(np.unique(values)) == {0, 255}
    assert main(["filter", "threshold", str(source), "-o", str(out), "--recover", "--backend", "numpy"]) == 0
    assert main(["filter", "threshold", str(source), "-o", str(out), "--param", "lvl=1"]) == 1
    assert "'lvl'" in capsys.readouterr().err
    assert main(["filters"]) == 0
    listing = capsys.readouterr().out
    for name in filters.FILTERS:
        assert name in listing
