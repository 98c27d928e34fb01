"""Tiled recovery equals untiled recovery, on every backend."""

import numpy as np
import pytest

import aarecovery
from aarecovery.tiling import halo_for, tiles
from scenes import shapes


@pytest.mark.parametrize("iterations", [1, 3, 4])
def test_many_small_tiles_equal_one_tile(backend, iterations):
    original = shapes(90, seed=4, noise=0.02)[:, :77]
    filtered = np.where(original > 100, 255, 0).astype(np.uint8)
    whole = aarecovery.recover(original, filtered, backend=backend, iterations=iterations, mode="paper")
    tiled = aarecovery.recover(original, filtered, backend=backend, iterations=iterations, mode="paper",
                               tile_size=2 * halo_for(iterations) + 7)
    np.testing.assert_array_equal(tiled, whole)


def test_tiled_maps_equal_untiled(backend):
    original = shapes(50, seed=6)
    filtered = 255 - original
    _, whole = aarecovery.recover(original, filtered, backend=backend, return_maps=True, mode="paper")
    _, tiled = aarecovery.recover(original, filtered, backend=backend, return_maps=True, mode="paper",
                                  tile_size=19)
    for name in aarecovery.RecoveryMaps.NAMES:
        np.testing.assert_array_equal(getattr(tiled, name), getattr(whole, name))


def test_tiles_cover_the_image_once():
    covered = np.zeros((53, 71), int)
    for inner, outer in tiles(53, 71, tile=20, halo=3):
        covered[inner] += 1
        assert outer[0].start <= inner[0].start and outer[0].stop >= inner[0].stop
    assert (covered == 1).all()


def test_too_small_a_tile_is_refused():
    image = np.zeros((40, 40), np.uint8)
    with pytest.raises(aarecovery.InputError, match="tile"):
        aarecovery.recover(image, image, backend="numpy", tile_size=5)
