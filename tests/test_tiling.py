"""Tiled recovery equals untiled recovery, on every backend."""

import warnings

import numpy as np
import pytest

import aarecovery
from aarecovery.tiling import halo_for, tiles
from scenes import shapes


# Small tiles on purpose: they put tile borders everywhere in a small image.
@pytest.mark.filterwarnings("ignore::aarecovery.errors.TileSizeWarning")
@pytest.mark.parametrize("iterations", [1, 3, 4])
def test_many_small_tiles_equal_one_tile(backend, iterations):
    original = shapes(90, seed=4, noise=0.02)[:, :77]
    filtered = np.where(original > 100, 255, 0).astype(np.uint8)
    whole = aarecovery.recover(original, filtered, backend=backend, iterations=iterations, mode="paper")
    tiled = aarecovery.recover(original, filtered, backend=backend, iterations=iterations, mode="paper",
                               tile_size=2 * halo_for(iterations) + 7)
    np.testing.assert_array_equal(tiled, whole)


# Small tiles on purpose: they put tile borders everywhere in a small image.
@pytest.mark.filterwarnings("ignore::aarecovery.errors.TileSizeWarning")
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


def test_small_tiles_warn_in_the_library_and_are_refused_on_the_command_line(tmp_path, capsys):
    from aarecovery.cli import main
    from aarecovery.errors import TileSizeWarning

    original = np.tile(np.linspace(0, 255, 100).astype(np.uint8), (80, 1))
    filtered = np.where(original > 127, 255, 0).astype(np.uint8)
    with warnings.catch_warnings():
        warnings.simplefilter("error", TileSizeWarning)  # stop there: the run itself would take a while
        with pytest.raises(TileSizeWarning, match="tile_size 9 is below 64"):
            aarecovery.recover(original, filtered, backend="numpy", tile_size=9)
        # Many iterations widen the halo, and the sensible side with it.
        with pytest.raises(TileSizeWarning, match="below 390"):
            aarecovery.recover(np.zeros((400, 400), np.uint8), np.zeros((400, 400), np.uint8), backend="numpy",
                               iterations=64, tile_size=200)
        # An image within one tile is not cut: nothing to warn about.
        aarecovery.recover(original[:9, :9], filtered[:9, :9], backend="numpy", tile_size=9)
    aarecovery.write_image(tmp_path / "o.png", original)
    aarecovery.write_image(tmp_path / "f.png", filtered)
    status = main(["recover", str(tmp_path / "o.png"), str(tmp_path / "f.png"), "-o", str(tmp_path / "r.png"),
                   "--tile-size", "9"])
    assert status == 1 and "at least 64" in capsys.readouterr().err
