"""Tiled recovery equals untiled recovery, on every backend."""

import warnings
from types import SimpleNamespace

import numpy as np
import pytest

import aarecovery
from aarecovery.tiling import aligned_tiles, halo_for, tiles
from parity import assert_maps_agree, assert_results_agree
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


@pytest.mark.parametrize("height, width, step, halo", [(53, 71, 16, 3), (140, 290, 64, 4), (30, 30, 64, 4),
                                                       (70, 33, 32, 2)])
def test_aligned_tiles_sit_on_the_grid_and_cover_the_image_once(height, width, step, halo):
    # A streamed TIFF is written in its own grid's tiles: each part is one of them, whole.
    covered = np.zeros((height, width), int)
    shapes_seen = set()
    for inner, outer in aligned_tiles(height, width, step, halo):
        covered[inner] += 1
        for part, window, length in zip(inner, outer, (height, width)):
            assert part.start % step == 0 and part.stop == min(part.start + step, length)
            assert 0 <= window.start <= max(0, part.start - halo)
            assert min(length, part.stop + halo) <= window.stop <= length
        shapes_seen.add(tuple(window.stop - window.start for window in outer))
    assert (covered == 1).all()
    assert len(shapes_seen) == 1


def test_too_small_a_tile_is_refused():
    image = np.zeros((40, 40), np.uint8)
    with pytest.raises(aarecovery.InputError, match="tile"):
        aarecovery.recover(image, image, backend="numpy", tile_size=5)


# ---- strips, tiles and backends against the whole-image specification -----------------------
# Thin coloured lines under point-wise filters get the safe default's pure colours, whose
# model reads O two pixels away: the case where a halo one pixel too narrow showed (NumPy's
# row strips once used iterations + 1 rows, 1 for maps alone, and beta differed by up to 1.0
# on the rows beside each strip seam).

def _thin_lines():
    from aarecovery.lab.scenes import render
    from aarecovery.plan.resample import box_downsample
    return np.rint(box_downsample(render("lines", 160, 4), 4, "linear")[:150] * 255).astype(np.uint8)


THIN_LINES_FILTERS = {
    "per-channel threshold": lambda o: np.where(o >= 128, 255, 0).astype(np.uint8),
    "power curve": lambda o: np.rint(255 * (o / 255.0) ** 3).astype(np.uint8),
}


def _whole_image_specification(original, filtered, plan):
    """R and the model from the NumPy passes on the whole image at once (no strips, no tiles)."""
    from aarecovery.contract import from_rgba_float, layout_of, to_rgba_float
    from aarecovery.spec import from_working_space, recover_working, to_working_space
    f_layout = layout_of(filtered, "filtered")
    filtered_rgba = to_rgba_float(filtered, f_layout, "filtered")
    work_o = to_working_space(to_rgba_float(original, layout_of(original, "original"), "original"),
                              blend_space=plan.blend_space)
    work_f = to_working_space(filtered_rgba, blend_space=plan.blend_space)
    recovered, model = recover_working(work_o, work_f, plan.sigma_d, plan.sigma_e, plan.iterations, plan.strength,
                                       plan.pure_colours, plan.blend_space, best_pair=plan.best_pair)
    result = from_working_space(recovered, filtered_rgba, blend_space=plan.blend_space, filtered_work=work_f)
    return from_rgba_float(result, f_layout), model


@pytest.mark.filterwarnings("ignore::aarecovery.errors.TileSizeWarning")  # small tiles on purpose
@pytest.mark.parametrize("mode", aarecovery.MODES)
@pytest.mark.parametrize("filter_name", sorted(THIN_LINES_FILTERS))
@pytest.mark.parametrize("iterations", [0, 1, 3])
def test_strips_tiles_and_backends_equal_the_whole_image(backend, mode, filter_name, iterations):
    from aarecovery.params import Parameters
    from aarecovery.plan import make_plan
    original = _thin_lines()
    filtered = THIN_LINES_FILTERS[filter_name](original)
    plan = make_plan(original, filtered, Parameters(iterations=iterations), mode=mode)
    assert mode == "paper" or plan.pure_colours is not None, plan.reason
    expected, model = _whole_image_specification(original, filtered, plan)
    expected_maps = {"alpha": model.alpha, "beta": model.beta, "edge_strength": model.edge, "residual": model.residual}
    # GL computes in float32 with other rounding than NumPy: within tests/parity.py's table
    # (maps measured: 2.4e-6 at most on these scenes).
    exact = backend == "numpy"
    for tile_size in (None, 2 * halo_for(iterations) + 24):
        result, maps = aarecovery.recover(original, filtered, iterations=iterations, mode=mode, backend=backend,
                                          tile_size=tile_size, return_maps=True)
        alone = aarecovery.recover(original, filtered, iterations=iterations, mode=mode, backend=backend,
                                   tile_size=tile_size)
        np.testing.assert_array_equal(alone, result)
        if exact:
            np.testing.assert_array_equal(result, expected)
            for name, values in expected_maps.items():
                np.testing.assert_array_equal(getattr(maps, name), values, err_msg=f"{name}, tile {tile_size}")
        else:
            assert_results_agree(result, expected)
            assert_maps_agree(maps, SimpleNamespace(**expected_maps), message=f"tile {tile_size}")


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
