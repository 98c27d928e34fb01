"""The best pair of neighbours where the principal colour line misses a pixel (the safe default).

``aarecovery.spec.blend_model.best_pair``: at a pixel beside a junction of three colours the
line through its nine colours passes between them, while the pixel is a blend of two of them.
"""

import dataclasses
import io

import numpy as np
import pytest

import aarecovery
from aarecovery.spec import blend_model

SIGMA_D = aarecovery.PARAMETERS["sigma_d"].default


def _columns(neighbourhood):
    """Nine RGBA colours (opaque), in NEIGHBOUR_OFFSETS order, as (4, 1) columns."""
    return [np.array([*colour, 1.0], np.float32)[:, None] for colour in neighbourhood]


def _junction():
    """A pixel half reddish, half greenish, beside those two and a bluish colour (at 0.15 from a
    grey): the line through the nine leans towards the blue and misses the pixel by 0.09."""
    red, green, blue = (0.65, 0.5, 0.5), (0.5, 0.65, 0.5), (0.5, 0.5, 0.65)
    centre = tuple(0.5 * r + 0.5 * g for r, g in zip(red, green))
    # centre, N, W, E, S, NW, NE, SW, SE
    return _columns([centre, red, blue, blue, green, red, blue, green, blue])


def test_a_pixel_beside_three_colours_takes_the_pair_it_blends():
    colours = _junction()
    line = blend_model.fit_extremes(colours, SIGMA_D)
    assert line[1][0] > blend_model.BEST_PAIR_MISS * SIGMA_D  # the line misses the pixel
    alpha, residual, index_a, index_b, colour_a, colour_b = blend_model.fit_extremes(colours, SIGMA_D, best=True)
    assert (index_a[0], index_b[0]) == (1, 4)  # N and S, the first of the equal pairs
    assert residual[0] == pytest.approx(0, abs=1e-6)
    assert alpha[0] == pytest.approx(0.5, abs=1e-6)
    np.testing.assert_array_equal(colour_a[:, 0], colours[1][:, 0])
    np.testing.assert_array_equal(colour_b[:, 0], colours[4][:, 0])


def test_a_pixel_the_line_explains_keeps_the_lines_model():
    # A two-colour edge: the line through the nine colours holds the pixel.
    dark, light = (0.1, 0.1, 0.2), (0.9, 0.8, 0.7)
    centre = tuple(0.3 * d + 0.7 * l for d, l in zip(dark, light))
    colours = _columns([centre, dark, dark, light, light, dark, dark, light, light])
    line = blend_model.fit_extremes(colours, SIGMA_D)
    best = blend_model.fit_extremes(colours, SIGMA_D, best=True)
    for got, want in zip(best, line):
        np.testing.assert_array_equal(got, want)


def _shapes_case(filter_name, space):
    from aarecovery.lab import scenes
    from aarecovery.lab.groundtruth import make_case
    return make_case(scenes.render("shapes", 64, 4), filter_name, 4, space)


def _edge_band_reduction(case, result):
    band = np.abs(case.reference - case.filtered).max(-1) > 1 / 255
    return 1 - ((result - case.reference)[band] ** 2).mean() / ((case.filtered - case.reference)[band] ** 2).mean()


@pytest.mark.parametrize("space", ["linear", "srgb"])
@pytest.mark.parametrize("filter_name", ["threshold", "posterize", "gamma"])
def test_overlapping_shapes_come_closer_to_the_supersampled_reference(filter_name, space):
    # Overlapping shapes in three and more colours, antialiased at 4x, filtered, against the
    # scene filtered before the box filter (measured: threshold 0.85-0.89 -> 0.90-0.96).
    case = _shapes_case(filter_name, space)
    engine = aarecovery.Engine(backend="numpy")
    engine.set_images(case.original, case.filtered)
    plan = engine.plan()
    assert plan.best_pair, plan.reason
    reductions = []
    for taken in (dataclasses.replace(plan, best_pair=False), plan):
        engine.run(taken)
        reductions.append(_edge_band_reduction(case, engine.result()))
    assert reductions[1] > reductions[0] + 0.01, reductions


def test_the_paper_and_a_jpeg_original_keep_the_lines_extremes():
    from PIL import Image
    case = _shapes_case("threshold", "srgb")
    original = np.rint(case.original * 255).astype(np.uint8)
    filtered = np.rint(case.filtered * 255).astype(np.uint8)
    engine = aarecovery.Engine(backend="numpy")
    engine.set_images(original, filtered)
    assert engine.plan().best_pair
    assert not engine.plan(mode="paper").best_pair
    # The same O saved as a JPEG: its noise is a third colour in every neighbourhood.
    buffer = io.BytesIO()
    Image.fromarray(original).save(buffer, "JPEG", quality=75)
    buffer.seek(0)
    jpeg = Image.open(buffer)
    tables = [list(table) for _, table in sorted(jpeg.quantization.items())]
    decoded = np.asarray(jpeg.convert("RGB"))
    engine.set_images(decoded, filtered, quantization=tables)
    assert not engine.plan().best_pair

