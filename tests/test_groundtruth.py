"""Supersampled ground truth: box filtering in both spaces, and the identity's reference."""

import numpy as np
import pytest

from aarecovery import filters
from aarecovery.lab import scenes as _scenes
from aarecovery.lab.groundtruth import box_downsample, make_case
from aarecovery.colour import linear_to_srgb


def test_box_downsample_averages_in_the_requested_space():
    block = np.zeros((2, 2, 3), np.float32)
    block[0] = 1  # half white, half black
    np.testing.assert_allclose(box_downsample(block, 2, "srgb")[0, 0], 0.5)
    np.testing.assert_allclose(box_downsample(block, 2, "linear")[0, 0], linear_to_srgb(np.float32(0.5)), atol=1e-6)
    assert box_downsample(block, 2, "linear")[0, 0, 0] == pytest.approx(0.7354, abs=1e-3)


@pytest.mark.parametrize("space", ["linear", "srgb"])
def test_reference_of_an_identity_filter_is_the_original(space, monkeypatch):
    scene = _scenes.render("shapes", 24, 4)
    identity = filters.Filter("identity", lambda image: image.copy(), "no change")
    monkeypatch.setitem(filters.FILTERS, "identity", identity)
    case = make_case(scene, "identity", 4, space)
    np.testing.assert_allclose(case.reference, case.original, atol=1e-6)
    np.testing.assert_array_equal(case.filtered, case.original)


def test_pointwise_reference_differs_from_filtered_only_at_edges():
    scene = _scenes.render("shapes", 32, 4)
    case = make_case(scene, "threshold", 4, "linear")
    differs = np.abs(case.reference - case.filtered).max(axis=-1) > 1e-6
    flat = np.ptp(scene.reshape(32, 4, 32, 4, 3), axis=(1, 3)).max(axis=-1) == 0
    assert differs.any()
    assert not (differs & flat).any()


def test_spatial_filters_are_scaled_and_state_is_fitted_on_the_original():
    scene = _scenes.render("text", 24, 4)
    case = make_case(scene, "equalize", 4, "srgb")
    curve = filters.equalization_transfer(case.original)
    np.testing.assert_allclose(case.filtered, filters.equalize_histogram(case.original, curve))
    expected = box_downsample(filters.equalize_histogram(scene, curve), 4, "srgb")
    np.testing.assert_allclose(case.reference, expected)


def test_every_scene_renders_at_k_times_the_target():
    for name in _scenes.SCENES:
        image = _scenes.render(name, 20, 4)
        assert image.shape[1] == 80 and image.shape[0] % 4 == 0 and image.shape[2] == 3
        assert image.dtype == np.float32 and 0 <= image.min() and image.max() <= 1
        assert image.std() > 0.05, name
