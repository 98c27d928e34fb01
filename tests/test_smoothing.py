"""A smoothing filter on hard-edged content: a lower strength, since it averages part of an
edge's damage away as the reference does; a sharpening filter keeps full strength."""

import numpy as np

import aarecovery
from aarecovery import Decision
from aarecovery.lab import scenes as _scenes
from aarecovery.lab.groundtruth import make_case
from aarecovery.lab.metrics import edge_band, error_reduction
from aarecovery.plan.calibration import EDGE_GRADIENT
from aarecovery.plan.smoothing import SMOOTHED_CONTRAST, SMOOTHED_STRENGTH, contrast_ratio
from aarecovery.spec.sobel import gradient_magnitude


def _shapes(filter_name):
    return make_case(_scenes.render("shapes", 64, 4), filter_name, 4, "linear")


def _ratio(case):
    edges = gradient_magnitude(case.original) >= EDGE_GRADIENT
    return contrast_ratio(case.original, case.filtered, edges)


def test_bilateral_smooths_and_unsharp_sharpens():
    assert _ratio(_shapes("bilateral")) < 1 < SMOOTHED_CONTRAST < _ratio(_shapes("unsharp"))
    flat = np.full((8, 8, 3), 0.5, np.float32)
    assert contrast_ratio(flat, flat, np.zeros((8, 8), bool)) == 1.0


def test_a_smoothed_drawing_is_repaired_at_the_smoothing_strength():
    case = _shapes("bilateral")
    with aarecovery.Engine("numpy") as engine:
        result = aarecovery.recover(case.original, case.filtered, engine=engine)
        plan = engine.last_plan
    assert plan.decision == Decision.NEIGHBOURHOOD_HARD_EDGED and plan.local is None, plan.reason
    assert plan.strength == SMOOTHED_STRENGTH, plan.reason
    band = edge_band(case.original, case.filtered, case.reference)
    assert error_reduction(result, case.filtered, case.reference, band) > 0.3


def test_a_sharpened_drawing_is_repaired_at_full_strength():
    case = _shapes("unsharp")
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(case.original, case.filtered)
        plan = engine.plan()
    assert plan.decision == Decision.NEIGHBOURHOOD_HARD_EDGED and plan.strength == 1, plan.reason


def test_a_smoothed_jpeg_drawing_is_repaired_at_a_lower_strength_and_not_made_worse():
    """Serif text saved as JPEG at quality 75, then OpenCV's edge-preserving smoothing (tuning
    half): at full strength R was 0.91 dB worse than F on the edges; the compression noise
    the filter spread over the edges takes the strength down to half, without pure colours."""
    from aarecovery.lab import realtools
    from aarecovery.plan.compression import COMPRESSED_SMOOTHED_STRENGTH
    from test_paper_grain import recover_no_worse_than_f
    suite = realtools.RealToolsSuite("jpeg-smoothing", ("serif",), ("cv-smoothing",), 96, {"serif": ("srgb",)},
                                     jpeg_qualities=(75,))
    (case,) = [c for c in realtools.build_cases(suite, "tune") if c.quality == 75]
    plan = recover_no_worse_than_f(case)
    assert plan.decision == Decision.NEIGHBOURHOOD_HARD_EDGED and plan.pure_colours is None, plan.reason
    assert plan.strength == COMPRESSED_SMOOTHED_STRENGTH, plan.reason
