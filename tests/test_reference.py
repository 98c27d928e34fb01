"""Properties of the recovery (the NumPy specification, and the GL backend through `backend`)."""

import numpy as np
import pytest

import aarecovery
from aarecovery.colour import linear_to_srgb, srgb_to_linear
from scenes import box_downsample, luminance, shapes, to_uint8, two_colour_edge


def recover(original, filtered, backend, **options):
    return aarecovery.recover(original, filtered, backend=backend, **options)


@pytest.mark.parametrize("mode", ["paper", "safe"])
def test_identity_filter_gives_f_back(backend, mode):
    original = shapes(64, seed=3)
    result = recover(original, original.copy(), backend, mode=mode)
    # The two-colour model reproduces antialiased pixels, but not texture off the colour line.
    difference = np.abs(result.astype(int) - original)
    assert difference.mean() < 0.2 and np.percentile(difference, 99) <= 2


@pytest.mark.parametrize("mode", ["paper", "safe"])
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.float32])
def test_a_flat_image_is_unchanged(backend, mode, dtype):
    original = np.full((17, 23, 3), 0.3, np.float32)
    filtered = np.full((17, 23, 3), 0.8, np.float32)
    if dtype != np.float32:
        scale = np.iinfo(dtype).max
        original, filtered = (np.rint(x * scale).astype(dtype) for x in (original, filtered))
    result = recover(original, filtered, backend, mode=mode)
    assert result.dtype == dtype
    np.testing.assert_array_equal(result, filtered)


@pytest.mark.parametrize("angle", [0, 10, 30, 45, 63, 80, 90, 135])
def test_thresholded_edge_is_restored_to_the_supersampled_reference(backend, angle):
    colour_a, colour_b = (0.95, 0.75, 0.2), (0.1, 0.15, 0.45)
    original, mask = two_colour_edge(32, angle, colour_a, colour_b)
    threshold = luminance(np.array([colour_a, colour_b], np.float32)).mean()
    filtered = to_uint8(np.repeat((luminance(original / np.float32(255)) > threshold)[..., None], 3, -1))
    # The same threshold applied to the 16x scene, then box-filtered in linear light.
    reference = to_uint8(linear_to_srgb(box_downsample(np.repeat(mask[..., None], 3, -1).astype(np.float32), 16)))
    result = recover(original, filtered, backend, mode="paper")
    edge = np.abs(reference.astype(int) - filtered).max(-1) > 0
    assert edge.sum() >= 16
    error_before = np.abs(filtered.astype(float) - reference)[edge].mean()
    error_after = np.abs(result.astype(float) - reference)[edge].mean()
    assert error_after < 2.0, (error_before, error_after)
    assert error_after < error_before / 10


def test_alpha_mask_is_repaired_without_colour_bleeding(backend):
    coverage, _ = two_colour_edge(32, 30, (1, 1, 1), (0, 0, 0))
    alpha = coverage[..., 0]
    original = np.zeros((32, 32, 4), np.uint8)
    original[..., :3] = (20, 200, 40)
    original[alpha == 0, :3] = (255, 0, 0)      # hidden colour behind full transparency
    original[..., 3] = alpha
    filtered = original.copy()
    filtered[..., 3] = np.where(alpha >= 128, 255, 0)
    result = recover(original, filtered, backend, mode="paper")
    visible = result[..., 3] > 0
    assert np.abs(result[visible, :3].astype(int) - (20, 200, 40)).max() <= 1
    partial = (alpha > 20) & (alpha < 235)
    assert np.abs(result[partial, 3].astype(int) - alpha[partial]).mean() < \
        np.abs(filtered[partial, 3].astype(int) - alpha[partial]).mean() / 4
    np.testing.assert_array_equal(result[~visible, :3], filtered[~visible, :3])


@pytest.mark.parametrize("shape", [(20, 24), (20, 24, 1), (20, 24, 2), (20, 24, 3), (20, 24, 4)])
def test_result_keeps_the_filtered_layout(backend, shape):
    rng = np.random.default_rng(0)
    original = (rng.random(shape) * 255).astype(np.uint8)
    filtered = 255 - original
    result = recover(original, filtered, backend)
    assert result.shape == shape and result.dtype == np.uint8


def test_colour_original_with_grey_filtered(backend):
    original = shapes(48, seed=5)
    filtered = to_uint8(luminance(original / np.float32(255)) ** 0.5)
    result = recover(original, filtered, backend, mode="paper")
    assert result.shape == filtered.shape
    assert np.abs(result.astype(int) - filtered).max() > 0


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.float32])
def test_zero_iterations_returns_filtered_exactly(backend, dtype):
    rng = np.random.default_rng(1)
    if dtype == np.float32:
        original, filtered = rng.random((2, 12, 14, 4), dtype=np.float32)
    else:
        original, filtered = (rng.random((2, 12, 14, 4)) * np.iinfo(dtype).max).astype(dtype)
    result = recover(original, filtered, backend, iterations=0, mode="paper")
    np.testing.assert_array_equal(result, filtered)


def test_linear_input_matches_encoded_input(backend):
    original = shapes(40, seed=8)
    filtered = np.where(original > 120, 255, 0).astype(np.uint8)
    encoded = recover(original, filtered, backend, mode="paper")
    lin_o, lin_f = (srgb_to_linear(x / np.float32(255)) for x in (original, filtered))
    linear = recover(lin_o, lin_f, backend, mode="paper", linear=True)
    assert np.abs(to_uint8(linear_to_srgb(linear)).astype(int) - encoded).max() <= 1


def test_a_coverage_no_output_can_show_keeps_fs_colour():
    # Coverage 1e-6 is the rounding of a transparent pixel's blend with an opaque neighbour
    # (model alpha 1 - 4e-6 on an H100, exactly 1 in NumPy): its colour, the neighbour's, is a
    # ratio of rounding errors. Such a pixel comes back transparent in F's colour.
    from aarecovery.spec import from_working_space
    from aarecovery.spec.working_space import VISIBLE_COVERAGE
    filtered = np.array([[[0.0, 0.667, 0.0, 0.0], [0.2, 0.4, 0.6, 1.0]]], np.float32)
    work = np.array([[[0.667e-6, 0.667e-6, 1e-6, 1e-6], [0.2, 0.4, 0.6, 1.0]]], np.float32)
    result = from_working_space(work, filtered, blend_space="srgb")
    np.testing.assert_array_equal(result[0, 0], filtered[0, 0])
    np.testing.assert_allclose(result[0, 1], filtered[0, 1], atol=1e-7)
    work[0, 0] = (0.0, 0.5 * 2 * VISIBLE_COVERAGE, 0.0, 2 * VISIBLE_COVERAGE)
    visible = from_working_space(work, filtered, blend_space="srgb")[0, 0]
    np.testing.assert_allclose(visible, (0.0, 0.5, 0.0, 2 * VISIBLE_COVERAGE), atol=1e-6)
