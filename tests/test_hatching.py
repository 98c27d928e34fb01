"""Hatching and screentone under edge-aware smoothing: texture, not edges to blend.

A drawing whose shading is hatching (thin parallel strokes a few pixels apart) or screentone
(a grid of dots) is smoothed by a bilateral filter. The paper's model reads every stroke as
an antialiased edge and blends O's extremes there, which the filter averaged away; the safe
default repairs the flat regions of a hatched O at full strength and the hatched ones at a
lower strength.
"""

import numpy as np
import pytest

import aarecovery
from aarecovery import Decision
from aarecovery.lab import scenes as _scenes
from aarecovery.lab.groundtruth import make_case
from aarecovery.lab.metrics import edge_band, error_reduction
from aarecovery.lab.realtools import render_family
from aarecovery.plan.calibration import EDGE_GRADIENT
from aarecovery.plan.hatching import HATCHED_SHARE, HATCHED_STRENGTH, hatched_share, is_screentone_drawing
from aarecovery.spec.sobel import gradient_magnitude

_K = 4
_SIDE = 96


def _hatched_scene():
    """A page (at 4 x O's size) shaded by hatching and screentone, with a solid disc and frame."""
    size = _SIDE * _K
    rows, cols = np.mgrid[0:size, 0:size].astype(np.float32) / _K
    scene = np.ones((size, size, 3), np.float32) * np.float32(0.95)
    # Diagonal hatching, strokes 1 px wide and 3 px apart (O's pixels), over the left half.
    hatch = ((rows + cols) % 3.0 < 1.0) & (cols < _SIDE / 2)
    # Screentone over the right half: dots of 0.7 px radius on a 2.5 px grid.
    dy, dx = (rows % 2.5) - 1.25, (cols % 2.5) - 1.25
    tone = (dy * dy + dx * dx < 0.49) & (cols >= _SIDE / 2)
    scene[hatch | tone] = 0.1
    # A solid disc and a frame on flat paper: hard edges the repair must keep repairing.
    disc = (rows - 70) ** 2 + (cols - 30) ** 2 < 12 ** 2
    scene[disc] = (0.8, 0.2, 0.1)
    scene[(rows > 60) & (rows < 88) & (cols > 55) & (cols < 90)] = 0.95
    frame = (rows > 60) & (rows < 88) & (cols > 55) & (cols < 90) & ~((rows > 62) & (rows < 86) & (cols > 57)
                                                                      & (cols < 88))
    scene[frame] = (0.1, 0.2, 0.6)
    return scene


@pytest.fixture(scope="module")
def hatched_case():
    return make_case(_hatched_scene(), "bilateral", _K, "srgb")


def _edges(image):
    return gradient_magnitude(image) >= EDGE_GRADIENT


def test_hatching_and_screentone_read_as_hatched_and_line_art_does_not(hatched_case):
    assert hatched_share(hatched_case.original, _edges(hatched_case.original)) >= HATCHED_SHARE
    shapes = make_case(_scenes.render("shapes", 64, _K), "bilateral", _K, "linear").original
    assert hatched_share(shapes, _edges(shapes)) < HATCHED_SHARE
    assert hatched_share(shapes, np.zeros(shapes.shape[:2], bool)) == 0.0


def test_a_hatched_drawing_is_repaired_only_in_its_flat_regions(hatched_case):
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(hatched_case.original, hatched_case.filtered)
        plan = engine.plan()
        assert plan.decision == Decision.NEIGHBOURHOOD_HARD_EDGED, plan.reason
        assert plan.local is not None and plan.local.textured == HATCHED_STRENGTH, plan.reason
        engine.run(plan, maps=True)
        result, maps = engine.result(), engine.maps()
    o, f, reference = hatched_case.original, hatched_case.filtered, hatched_case.reference
    band = edge_band(o, f, reference)
    # The hatching is repaired at the lower strength, the flat paper around the disc and frame at full.
    hatching, screentone = maps.strength[8:40, 8:40], maps.strength[8:40, 56:88]
    assert hatching.max() == screentone.max() == np.float32(HATCHED_STRENGTH)
    assert maps.strength[68:80, 64:80].min() == 1
    assert error_reduction(result, f, reference, band) >= 0
    summary = aarecovery.summarize_recovery(plan, o, f, result)
    assert f"hatching and screentone {1 - summary.hard_edged_share:.0%} at {HATCHED_STRENGTH:g}" in summary.line()


def test_a_sharpened_hatched_drawing_is_repaired_everywhere():
    """Sharpening keeps the strokes (it does not average them away): one strength everywhere."""
    case = make_case(_hatched_scene(), "unsharp", _K, "srgb")
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(case.original, case.filtered)
        plan = engine.plan()
    assert plan.decision == Decision.NEIGHBOURHOOD_HARD_EDGED and plan.local is None, plan.reason


@pytest.mark.filterwarnings("ignore::aarecovery.errors.TileSizeWarning")
def test_gl_keeps_f_in_the_hatching_as_numpy_does(hatched_case, gl_path):
    results = {}
    for backend in ("numpy", "gl"):
        with aarecovery.Engine(backend, gl_path=gl_path if backend == "gl" else "auto") as engine:
            results[backend] = aarecovery.recover(hatched_case.original, hatched_case.filtered, engine=engine,
                                                  return_maps=True)
    (numpy_result, numpy_maps), (gl_result, gl_maps) = results["numpy"], results["gl"]
    np.testing.assert_allclose(gl_maps.strength, numpy_maps.strength, atol=1e-6)
    assert numpy_maps.strength.min() == np.float32(HATCHED_STRENGTH) and numpy_maps.strength.max() == 1
    np.testing.assert_allclose(gl_result, numpy_result, atol=1e-5)


def test_a_screentone_comic_is_a_drawing_and_a_photo_is_not():
    """The manga's screentone reads as grain (a photo's, to the texture test); its flat paper and
    dense dots make it a drawing, which the neighbourhood branch repairs."""
    manga = make_case(render_family("manga", 64), "unsharp", 8, "srgb")
    photo = make_case(_scenes.render("astronaut", 64, _K), "unsharp", _K, "linear")
    assert is_screentone_drawing(manga.original, _edges(manga.original))
    assert not is_screentone_drawing(photo.original, _edges(photo.original))
    with aarecovery.Engine("numpy") as engine:
        result = aarecovery.recover(manga.original, manga.filtered, engine=engine)
        assert engine.last_plan.decision == Decision.NEIGHBOURHOOD_HARD_EDGED, engine.last_plan.reason
    band = edge_band(manga.original, manga.filtered, manga.reference)
    assert error_reduction(result, manga.filtered, manga.reference, band) > 0.2


@pytest.mark.parametrize("space", ["srgb", "linear"])
def test_a_screentone_comic_under_a_point_wise_filter_is_repaired_as_a_drawing(space):
    """Under a threshold the manga page was read as a photo (its dots as grain) and got the
    calibrated strength (0.57 and 0.35 of its edge error); as a drawing it gets full strength
    and pure colours of thin features (0.72 and 0.57)."""
    manga = make_case(render_family("manga", 96), "threshold", 8, space)
    with aarecovery.Engine("numpy") as engine:
        result = aarecovery.recover(manga.original, manga.filtered, engine=engine)
        plan = engine.last_plan
    assert plan.decision == Decision.POINTWISE_HARD_EDGED, plan.reason
    assert plan.strength == 1 and plan.local is None
    band = edge_band(manga.original, manga.filtered, manga.reference)
    assert error_reduction(result, manga.filtered, manga.reference, band) > 0.5
