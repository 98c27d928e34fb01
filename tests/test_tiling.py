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


@pytest.mark.parametrize("mode", ["paper", "safe"])
def test_tiles_equal_untiled_on_each_gl_path(gl_path, mode):
    # Equal-sized tiles of several sizes (a backend keeps its textures between them), with the
    # pure colours of the safe default on thin features too.
    from aarecovery.lab import scenes
    from aarecovery.lab.groundtruth import make_case
    case = make_case(scenes.render("lines", 60, 4), "posterize", 4, "srgb")
    thin = [np.rint(image * 255).astype(np.uint8) for image in (case.original, case.filtered)]
    shaped = shapes(90, seed=4, noise=0.02)[:, :77]
    for original, filtered in (thin, (shaped, np.where(shaped > 100, 255, 0).astype(np.uint8))):
        with aarecovery.Engine(backend="gl", gl_path=gl_path) as engine:
            whole = aarecovery.recover(original, filtered, engine=engine, mode=mode)
            for tile_size in (11, 19, 40):
                tiled = aarecovery.recover(original, filtered, engine=engine, mode=mode, tile_size=tile_size)
                np.testing.assert_array_equal(tiled, whole)


@pytest.mark.parametrize("height, width, tile, halo", [(53, 71, 20, 3), (4096, 4096, 1024, 4), (100, 30, 20, 4),
                                                       (12, 12, 11, 5), (7, 300, 40, 2)])
def test_tiles_cover_the_image_once_in_windows_of_one_shape(height, width, tile, halo):
    covered = np.zeros((height, width), int)
    shapes_seen = set()
    for inner, outer in tiles(height, width, tile=tile, halo=halo):
        covered[inner] += 1
        for part, window, length in zip(inner, outer, (height, width)):
            assert 0 <= window.start <= max(0, part.start - halo)
            assert min(length, part.stop + halo) <= window.stop <= length
            assert window.stop - window.start <= tile
        shapes_seen.add(tuple(window.stop - window.start for window in outer))
    assert (covered == 1).all()
    assert len(shapes_seen) == 1


def test_too_small_a_tile_is_refused():
    image = np.zeros((40, 40), np.uint8)
    with pytest.raises(aarecovery.InputError, match="tile"):
        aarecovery.recover(image, image, backend="numpy", tile_size=5)
