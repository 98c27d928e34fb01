"""A smoothing filter on hard-edged content: a lower strength, since it averages part of an
edge's damage away as the reference does; a sharpening filter keeps full strength."""

import numpy as np
import pytest

import aarecovery
from aarecovery import Decision
from aarecovery.lab import scenes as _scenes
from aarecovery.lab.groundtruth import make_case
from aarecovery.lab.metrics import edge_band, error_reduction
from aarecovery.plan.calibration import EDGE_GRADIENT
from aarecovery.plan.smoothing import SMOOTHED_CONTRAST, SMOOTHED_STRENGTH, contrast_ratio
from aarecovery.spec.sobel import gradient_magnitude
from parity import assert_maps_agree, assert_results_agree


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
    # O's pixels carry the noise the filter smoothed away: no moving towards them.
    assert not plan.toward_original, plan.reason


def test_a_smoothing_filter_keeps_f_where_it_left_o_as_it_was():
    """Under a smoothing filter the confidence falls to 0 where F's pixel and its model's
    extremes are O's: a pair whose left half F left as O had it is repaired on its right half
    only, and the model's beta is the plain one where F changed by the span or more."""
    from aarecovery.plan.smoothing import UNTOUCHED_SPAN
    from aarecovery.spec import fit_blend_model, to_working_space
    case = _shapes("bilateral")
    filtered = case.filtered.copy()
    half = filtered.shape[1] // 2
    filtered[:, :half] = case.original[:, :half]
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(case.original, filtered)
        plan = engine.plan()
        assert plan.untouched_span == UNTOUCHED_SPAN, plan.reason
        engine.run(plan, maps=True)
        result, maps = engine.result(), engine.maps()
    assert (maps.beta[:, :half - 1] == 0).all() and (maps.beta[:, half:] > 0.1).any()
    np.testing.assert_array_equal(result[:, :half - 2], filtered[:, :half - 2])
    # Where F moved by the span or more the factor is 1: beta as without it.
    rgba = [to_working_space(np.concatenate([x, np.ones(x.shape[:2] + (1,), np.float32)], -1))
            for x in (case.original, case.filtered)]
    plain = fit_blend_model(*rgba, plan.sigma_d, plan.sigma_e, plan.strength)
    kept = fit_blend_model(*rgba, plan.sigma_d, plan.sigma_e, plan.strength, untouched_span=UNTOUCHED_SPAN)
    moved = np.abs(rgba[1] - rgba[0]).max(axis=-1) >= UNTOUCHED_SPAN
    np.testing.assert_array_equal(kept.beta[moved], plain.beta[moved])
    assert (kept.beta[~moved] < plain.beta[~moved]).any() and (kept.beta <= plain.beta).all()


def test_a_colour_swapped_beside_an_untouched_blend_is_still_repaired():
    """A colour replacement leaves the blend between a swapped colour and the paper as O had
    it, which is its damage: where F moved an extreme by more than UNTOUCHED_EXTREMES the
    factor is 1."""
    from aarecovery.spec.blend_model import UNTOUCHED_EXTREMES, untouched_factor
    original = np.ones((3, 3, 4), np.float32)
    original[:, 0, :3] = (0.8, 0.1, 0.1)
    original[:, 1, :3] = (0.9, 0.55, 0.55)
    left, right = np.full((3, 3), 2, np.uint8), np.full((3, 3), 3, np.uint8)  # NEIGHBOUR_OFFSETS
    swapped = original.copy()
    swapped[:, 0, :3] = (0.1, 0.1, 0.8)
    assert np.abs(swapped - original).max() > UNTOUCHED_EXTREMES
    assert untouched_factor(original, swapped, left, right, 6.0 / 255)[1, 1] == 1
    nudged = original.copy()
    nudged[:, 0, :3] += np.float32(0.05)
    assert untouched_factor(original, nudged, left, right, 6.0 / 255)[1, 1] == 0
    nudged[1, 1, 0] += np.float32(3.0 / 255)
    assert abs(untouched_factor(original, nudged, left, right, 6.0 / 255)[1, 1] - 0.5) < 1e-3  # halfway


def test_a_sharpening_filter_and_the_paper_take_no_untouched_span():
    case = _shapes("unsharp")
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(case.original, case.filtered)
        assert engine.plan().untouched_span == 0
        engine.set_images(case.original, _shapes("bilateral").filtered)
        assert engine.plan().untouched_span > 0
        assert engine.plan(mode="paper").untouched_span == 0
        assert engine.plan(strength=0.5).untouched_span == 0


@pytest.mark.gl
@pytest.mark.filterwarnings("ignore::aarecovery.errors.TileSizeWarning")  # small tiles on purpose
def test_gl_keeps_f_where_a_smoothing_filter_left_o_as_numpy_does(gl_path):
    case = _shapes("bilateral")
    filtered = case.filtered.copy()
    filtered[:, :filtered.shape[1] // 2] = case.original[:, :filtered.shape[1] // 2]
    results = {}
    for backend in ("numpy", "gl"):
        with aarecovery.Engine(backend, gl_path=gl_path if backend == "gl" else "auto") as engine:
            results[backend] = aarecovery.recover(case.original, filtered, engine=engine, return_maps=True)
            assert engine.last_plan.untouched_span > 0, engine.last_plan.reason
    (numpy_result, numpy_maps), (gl_result, gl_maps) = results["numpy"], results["gl"]
    assert_maps_agree(gl_maps, numpy_maps)
    assert_results_agree(gl_result, numpy_result)
    # The factor reads the model's own 3 x 3 neighbourhood only: tiles need no more halo.
    for backend in ("numpy", "gl"):
        tiled = aarecovery.recover(case.original, filtered, backend=backend, tile_size=40,
                                   gl_path=gl_path if backend == "gl" else "auto")
        assert_results_agree(tiled, numpy_result, backend)


def _serif_under(filter_name, space="srgb", width=64, family="serif"):
    import dataclasses
    from aarecovery.lab import realtools
    from test_realtools import require_tool
    require_tool(realtools.TOOL_FILTERS[filter_name].tool)
    suite = dataclasses.replace(realtools.REAL_FULL, families=(family,), filters=(filter_name,),
                                spaces={family: (space,)}, width=width)
    (case,) = realtools.build_cases(suite, "tune", jpeg=False)
    return case


def test_a_smoothed_drawing_moves_towards_o_where_the_filter_kept_its_colours():
    """OpenCV's bilateral filter on serif text keeps the flat ink and paper and softens the
    edges between them, and its reference keeps them as O has them: towards O the edge band
    loses nearly all of F's error (0.93 at 64 px, 0.95 at 96 px), where the model alone,
    whose two colours miss the pixels a serif's three-colour corners mix, left 0.23 of it."""
    import dataclasses
    case = _serif_under("cv-bilateral")
    band = edge_band(case.original, case.filtered, case.reference)
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(case.original, case.filtered)
        plan = engine.plan()
        assert plan.toward_original and plan.untouched_span > 0, plan.reason
        assert "moved towards O" in plan.reason, plan.reason
        engine.run(plan)
        towards = error_reduction(engine.result(), case.filtered, case.reference, band)
        engine.run(dataclasses.replace(plan, toward_original=False))
        without = error_reduction(engine.result(), case.filtered, case.reference, band)
    assert towards > 0.88 and towards > without + 0.1, (towards, without)


def test_a_smoothed_drawing_moves_towards_o_below_the_repair_ratio():
    """The map in sRGB under OpenCV's bilateral filter: the model's repairs are no larger than
    its own error there (a repair-to-error ratio below MIN_REPAIR_TO_ERROR, which keeps F),
    but the filter kept O's colours, so the drawn edges move towards O, which needs no model:
    most of F's edge error goes (0.955 at 96 px)."""
    from aarecovery.plan.model_error import MIN_REPAIR_TO_ERROR
    case = _serif_under("cv-bilateral", width=96, family="maps")
    band = edge_band(case.original, case.filtered, case.reference)
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(case.original, case.filtered)
        plan = engine.plan()
        assert plan.toward_original and f"< {MIN_REPAIR_TO_ERROR:g})" in plan.reason, plan.reason
        engine.run(plan)
        reduction = error_reduction(engine.result(), case.filtered, case.reference, band)
    assert reduction > 0.9, reduction


def test_towards_o_leaves_a_changed_colour_to_the_model():
    """Where F moved an extreme off O's colour line between the extremes by more than
    KEPT_EXTREMES (a colour replacement, which the smoothing test reads as smoothing too) the
    weight of O is 0: O's pixel would bring the old colour back. Where F kept both extremes,
    or moved one along that line (a smoothing filter mixing a thin line with its
    surroundings), it is the given weight, and beta shrinks by it; where F is O the step
    gives F exactly."""
    from aarecovery.spec import fit_blend_model, jacobi_step
    from aarecovery.spec.blend_model import KEPT_EXTREMES
    width = 9
    ramp = np.clip(np.arange(width, dtype=np.float32) - 3.5, 0, 1)  # an edge between columns 3 and 5
    original = np.ones((5, width, 4), np.float32)
    original[..., :3] = (1 - ramp)[None, :, None] * np.float32(0.1) + ramp[None, :, None] * np.float32(0.9)
    softened = original.copy()
    softened[:, 4, :3] = 0.5  # the edge pixel softened, the flat colours kept
    swapped = softened.copy()
    swapped[:, :4, 0] += 2 * KEPT_EXTREMES  # the dark colour replaced
    mixed = softened.copy()
    mixed[:, 3, :3] += 3 * KEPT_EXTREMES  # the dark side mixed towards the light one, along the line
    weight = np.full((5, width), 0.75, np.float32)
    for filtered, expected in ((softened, 0.75), (swapped, 0.0), (mixed, 0.75)):
        plain = fit_blend_model(original, filtered, 0.1, 0.01)
        model = fit_blend_model(original, filtered, 0.1, 0.01, toward=weight)
        assert model.edge[2, 4] > 0 and model.toward[2, 4] == pytest.approx(expected), expected
        assert model.beta[2, 4] == pytest.approx((1 - expected) * plain.beta[2, 4])
    model = fit_blend_model(original, original, 0.1, 0.01, toward=weight)
    np.testing.assert_array_equal(jacobi_step(original, original, model), original)


def test_towards_o_takes_the_largest_gate_around_the_pixel():
    """The blended pixels between a drawing's flat colours recur nowhere, and the gate reads
    them as less drawn than the colours beside them: the weight towards O is the largest gate
    over the pixel's 3 x 3 neighbourhood, borders replicated, so the edge pixel beside a
    drawn colour moves to O's pixel."""
    from aarecovery.spec import fit_blend_model, jacobi_step
    from aarecovery.spec.blend_model import toward_weight
    gate = np.zeros((5, 6), np.float32)
    gate[2, 3], gate[0, 0] = 0.8, 0.3
    expected = np.zeros((5, 6), np.float32)
    expected[:2, :2] = 0.3
    expected[1:4, 2:5] = 0.8
    np.testing.assert_array_equal(toward_weight(gate), expected)

    width = 9
    ramp = np.clip(np.arange(width, dtype=np.float32) - 3.5, 0, 1)
    original = np.ones((5, width, 4), np.float32)
    original[..., :3] = (1 - ramp)[None, :, None] * np.float32(0.1) + ramp[None, :, None] * np.float32(0.9)
    softened = original.copy()
    softened[:, 4, :3] = 0.5  # the edge pixel softened, the flat colours kept
    drawn = np.zeros((5, width), np.float32)
    drawn[:, 3] = drawn[:, 5] = 1  # the flat colours beside the edge read as drawn, the blend not
    model = fit_blend_model(original, softened, 0.1, 0.01, toward=toward_weight(drawn))
    assert model.edge[2, 4] > 0 and model.toward[2, 4] == 1 and model.beta[2, 4] == 0
    np.testing.assert_allclose(jacobi_step(softened, softened, model)[2, 4], original[2, 4], atol=1e-6)


@pytest.mark.gl
def test_towards_o_is_the_same_on_gl_tiled_and_whole(gl_path):
    """The gate comes from the local plan's passes also for a plan without a local plan (a
    factor of exactly 1): GL equals NumPy, whole and in tiles that cut the text, with the
    pure colours of thin features and without them (the paper's passes and a Jacobi
    constant of their own)."""
    import dataclasses
    case = _serif_under("cv-bilateral", "linear")
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(case.original, case.filtered)
        plan = engine.plan()
    assert plan.toward_original and plan.local is None and plan.reach > 0, plan.reason
    assert plan.pure_colours is not None, plan.reason
    for each in (plan, dataclasses.replace(plan, pure_colours=None)):
        with aarecovery.Engine("numpy") as engine:
            engine.set_images(case.original, case.filtered)
            engine.run(each, maps=True)
            expected, expected_maps = engine.result(), engine.maps()
        message = f"{gl_path}, pure colours {each.pure_colours is not None}"
        with aarecovery.Engine("gl", gl_path=gl_path) as engine:
            engine.set_images(case.original, case.filtered)
            engine.run(each, maps=True)
            assert_results_agree(engine.result(), expected, message)
            assert_maps_agree(engine.maps(), expected_maps, message=message)
            engine.run(each)  # the factor over the listed blocks only
            assert_results_agree(engine.result(), expected, f"{message}, listed blocks")
        tiled = aarecovery.recover(case.original, case.filtered, backend="gl", gl_path=gl_path, plan=each,
                                   tile_size=64)
        assert_results_agree(tiled, expected, f"{message}, tiled")


def test_an_asked_strength_does_not_move_towards_o():
    case = _serif_under("cv-bilateral")
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(case.original, case.filtered)
        assert engine.plan().toward_original
        assert not engine.plan(strength=1.0).toward_original


def test_a_filter_that_moves_a_flat_colour_does_not_move_towards_o():
    """A colour map that the contrast test reads as smoothing (a hue change of a legend's
    swatch) moves a flat colour of O, and towards O would bring the old colour back: one
    flat pixel moved by more than FLAT_COLOUR_MOVE turns it off; a smoothing filter's few
    levels beside the edges do not."""
    from aarecovery.plan.smoothing import FLAT_COLOUR_MOVE, keeps_flat_colours
    from aarecovery.spec.local_plan import flat_pixels
    case = _serif_under("cv-bilateral")
    original, filtered = case.original, case.filtered.copy()
    assert keeps_flat_colours(original, filtered)
    rows, cols = np.nonzero(flat_pixels(original))
    colour = original[rows[0], cols[0]]
    towards_middle = np.where(colour > 0.5, -1, 1).astype(np.float32)  # never clipped
    nudged = filtered.copy()
    nudged[rows[0], cols[0]] = colour + towards_middle * FLAT_COLOUR_MOVE / 2
    assert keeps_flat_colours(original, nudged)
    filtered[rows[0], cols[0]] = colour + towards_middle * 2 * FLAT_COLOUR_MOVE
    assert not keeps_flat_colours(original, filtered)
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(original, filtered)
        plan = engine.plan()
    assert plan.untouched_span > 0 and not plan.toward_original, plan.reason


def test_a_colour_map_that_moves_a_flat_colour_a_little_does_not_move_towards_o():
    """A hue change moves a greyish flat colour by less than FLAT_COLOUR_MOVE, but all of it
    to one new colour: that turns towards O off; a smoothing filter's moves, which vary with
    the distance to an edge, do not."""
    from aarecovery.plan.smoothing import FLAT_COLOUR_MAP_MOVE, FLAT_COLOUR_MOVE, keeps_flat_colours
    from aarecovery.spec.local_plan import flat_pixels
    case = _serif_under("cv-bilateral")
    original, filtered = case.original, case.filtered.copy()
    assert keeps_flat_colours(original, filtered)
    flat = flat_pixels(original)
    levels = np.rint(original * 255).astype(int)
    colours, counts = np.unique(levels[flat], axis=0, return_counts=True)
    colour = colours[np.argmax(counts)]
    of_colour = np.flatnonzero(flat & (levels == colour).all(-1))
    assert of_colour.size >= 16
    shift = np.where(colour > 127, -1, 1).astype(np.float32) * 2 * FLAT_COLOUR_MAP_MOVE
    assert 2 * FLAT_COLOUR_MAP_MOVE < FLAT_COLOUR_MOVE
    moved = filtered.reshape(-1, 3).copy()
    moved[of_colour[:of_colour.size // 3]] = colour / 255 + shift  # a third: beside edges
    assert keeps_flat_colours(original, moved.reshape(filtered.shape))
    by_distance = np.linspace(0.25, 1.5, of_colour.size, dtype=np.float32)[:, None]
    moved[of_colour] = colour / 255 + shift * by_distance  # all of it, by varying amounts
    assert keeps_flat_colours(original, moved.reshape(filtered.shape))
    moved[of_colour] = colour / 255 + shift  # the whole colour to one new colour
    assert not keeps_flat_colours(original, moved.reshape(filtered.shape))


def test_a_hue_change_on_a_screenshot_keeps_its_title_bar():
    """GEGL's hue-chroma on the screenshot (sRGB) reads as smoothing over a textured image
    with drawn regions; it moved the blue-grey title bar by 18/255 and towards O brought the
    old colour back (0.98 of the text's edge error added)."""
    import dataclasses

    from aarecovery.lab import realtools
    from test_realtools import require_tool
    require_tool("gegl")
    suite = dataclasses.replace(realtools.REAL_FULL, families=("screenshot",), filters=("gegl-hue-chroma",),
                                spaces={"screenshot": ("srgb",)})
    (case,) = realtools.build_cases(suite, "tune", jpeg=False)
    band = edge_band(case.original, case.filtered, case.reference)
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(case.original, case.filtered)
        plan = engine.plan()
        assert not plan.toward_original, plan.reason
        engine.run(plan)
        assert error_reduction(engine.result(), case.filtered, case.reference, band) > -0.05, plan.reason


def test_dense_line_work_moves_towards_o_by_its_drawn_ink():
    """The star burst's spokes leave few flat regions, but their ink recurs exactly: the
    weight of O is the drawn ink's there too (OpenCV's bilateral in sRGB at 64 px: 0.81,
    0.55 without moving towards O; at 96 px 0.72 with the regions' weight alone, 0.92 with
    the ink)."""
    import dataclasses
    case = _serif_under("cv-bilateral", family="starburst")
    band = edge_band(case.original, case.filtered, case.reference)
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(case.original, case.filtered)
        plan = engine.plan()
        assert plan.toward_original, plan.reason
        engine.run(plan)
        towards = error_reduction(engine.result(), case.filtered, case.reference, band)
        engine.run(dataclasses.replace(plan, toward_original=False))
        without = error_reduction(engine.result(), case.filtered, case.reference, band)
    assert towards > 0.75 and towards > without + 0.15, (towards, without)


@pytest.mark.parametrize("filter_name, least", [("colourtogrey", 0.8), ("replacecolour", 0.9)])
def test_a_colour_map_on_lines_is_no_smoothing_filter(filter_name, least):
    """The built-in colour to grey and colour replacement on thin lines read as smoothing
    filters (the lines' colours are never flat, so no flat pixel moved): 0.57 and 0.73 of the
    edge error at strength 0.75 with F kept where it left O's pixel. Their 3-D colour map
    explains F on 0.98 of the edges, so they are point-wise colour maps on hard-edged
    content: full strength, no smoothing rule, no move towards O (measured 0.85 and 0.98)."""
    case = make_case(_scenes.render("lines", 80, 4), filter_name, 4, "srgb")
    band = edge_band(case.original, case.filtered, case.reference)
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(case.original, case.filtered)
        plan = engine.plan()
        engine.run(plan)
        repaired = engine.result()
    assert plan.decision == Decision.COLOUR_MAP_HARD_EDGED, plan.reason
    assert plan.untouched_span == 0 and not plan.toward_original and plan.strength == 1, plan.reason
    assert error_reduction(repaired, case.filtered, case.reference, band) > least


def test_kept_contrast_is_f_span_over_o_span_smoothed():
    """How fully F kept O's contrast: the smoothstep of F's 3 x 3 span over O's (largest
    channel), full from KEPT_CONTRAST_HIGH, none up to KEPT_CONTRAST_LOW, 0 where O is flat."""
    from aarecovery.spec.local_plan import KEPT_CONTRAST_HIGH, KEPT_CONTRAST_LOW, kept_contrast
    original = np.zeros((3, 4, 3), np.float32)
    original[:, 2:] = 0.8
    original[..., 0] = 0.5  # a channel that does not change: the largest span decides
    for scale, expected in ((1.0, (1 - KEPT_CONTRAST_LOW) / (KEPT_CONTRAST_HIGH - KEPT_CONTRAST_LOW)),
                            (0.5, 0.0), (KEPT_CONTRAST_HIGH, 1.0)):
        filtered = original.copy()
        filtered[..., 1:] *= np.float32(scale)
        kept = kept_contrast(original, filtered)
        t = np.float32(expected)
        np.testing.assert_allclose(kept[1, 1:3], t * t * (3 - 2 * t), atol=1e-6)
    flat = np.full((3, 4, 3), 0.5, np.float32)
    np.testing.assert_array_equal(kept_contrast(flat, original), 0)


def test_every_pixel_moves_towards_o_where_f_steepened_its_contrast():
    """Beside the drawn ink, the kept ink towards O is how far F steepened O's 3 x 3 span:
    full at STEEPENED_CONTRAST_HIGH times it, a quarter where F kept it, none where F
    flattened it (a smoothed photo's texture); no drawn ink here (a photo's grain)."""
    from aarecovery.spec.local_plan import (KEPT_CONTRAST_LOW, STEEPENED_CONTRAST_HIGH, LocalStrength, ink_weight)
    rng = np.random.default_rng(6)
    original = np.clip(0.5 + rng.normal(0, 0.05, (9, 9, 3)), 0, 1).astype(np.float32)
    assert ink_weight(original).max() == 0 and LocalStrength.gate(original, True).max() == 0
    mean = original.mean(axis=(0, 1), keepdims=True)
    expected = {}
    for scale in (STEEPENED_CONTRAST_HIGH, 1.0, 0.5):
        filtered = (mean + np.float32(scale) * (original - mean)).astype(np.float32)
        t = np.clip((scale - KEPT_CONTRAST_LOW) / (STEEPENED_CONTRAST_HIGH - KEPT_CONTRAST_LOW), 0, 1)
        expected[scale] = t * t * (3 - 2 * t)
        np.testing.assert_allclose(LocalStrength.kept_ink(original, filtered), expected[scale], atol=1e-4)
    assert expected[STEEPENED_CONTRAST_HIGH] == 1 and 0.2 < expected[1.0] < 0.3 and expected[0.5] == 0


def _poster_under(filter_name):
    return _serif_under(filter_name, "linear", 96, family="poster")


def test_text_over_a_smoothed_photo_moves_towards_o_where_f_kept_its_contrast():
    """A cafe poster's text over its photo under OpenCV's bilateral filter (tuning half): the
    pure colours' gate reads the flat regions only, but the text's drawn ink moves towards O
    too where the filter kept the edge's contrast (LocalStrength.kept_ink), which it does for
    the text and not for the photo's weaker edges: text and graphics 0.27 -> 0.55 of their
    edge error removed, the photo region no worse than F."""
    case = _poster_under("cv-bilateral")
    with aarecovery.Engine("numpy") as engine:
        result = aarecovery.recover(case.original, case.filtered, engine=engine)
        plan = engine.last_plan
    assert plan.decision == Decision.NEIGHBOURHOOD_MIXED and plan.toward_original, plan.reason
    assert plan.pure_colours.drawn_only and not plan.pure_colours.ink_gate, plan.reason
    band = edge_band(case.original, case.filtered, case.reference)
    text, photo = band & case.regions["text/graphics"], band & case.regions["photo"]
    assert error_reduction(result, case.filtered, case.reference, text) > 0.5
    assert error_reduction(result, case.filtered, case.reference, photo) >= 0


@pytest.mark.gl
def test_the_kept_ink_is_the_same_on_gl_tiled_and_whole(gl_path):
    """The kept ink (the local plan's third channel on GL) equals NumPy's, with maps (the
    factor over the whole image), over the listed blocks only, and in tiles."""
    case = _poster_under("cv-bilateral")
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(case.original, case.filtered)
        plan = engine.plan()
        engine.run(plan, maps=True)
        expected, expected_maps = engine.result(), engine.maps()
    assert plan.toward_original and plan.pure_colours.drawn_only and not plan.pure_colours.ink_gate, plan.reason
    with aarecovery.Engine("gl", gl_path=gl_path) as engine:
        engine.set_images(case.original, case.filtered)
        engine.run(plan, maps=True)
        assert_results_agree(engine.result(), expected, gl_path)
        assert_maps_agree(engine.maps(), expected_maps, message=gl_path)
        engine.run(plan)
        assert_results_agree(engine.result(), expected, f"{gl_path}, listed blocks")
    tiled = aarecovery.recover(case.original, case.filtered, backend="gl", gl_path=gl_path, plan=plan, tile_size=64)
    assert_results_agree(tiled, expected, f"{gl_path}, tiled")


def test_a_smoothed_photo_under_text_moves_towards_o_where_f_steepened_it(monkeypatch):
    """The tuning half's screenshot made in sRGB values under OpenCV's edge-preserving
    smoothing: with F's steepened blends moved towards O, its photo regions had 0.44 of their
    edge error removed, 0.12 without (the kept ink alone), its text and graphics 0.64 and
    0.61."""
    from aarecovery.spec import local_plan
    from test_realtools import real_case
    case, text, photo = real_case("screenshot", "cv-smoothing", "srgb")
    gains = []
    for high in (local_plan.STEEPENED_CONTRAST_HIGH, 1e9):
        monkeypatch.setattr(local_plan, "STEEPENED_CONTRAST_HIGH", high)
        with aarecovery.Engine("numpy") as engine:
            result = aarecovery.recover(case.original, case.filtered, engine=engine)
            assert engine.last_plan.toward_original and engine.last_plan.decision == Decision.NEIGHBOURHOOD_MIXED
        gains.append([error_reduction(result, case.filtered, case.reference, region) for region in (text, photo)])
    (text_steepened, photo_steepened), (text_kept, photo_kept) = gains
    assert photo_steepened > 0.35 and photo_kept < 0.2, gains
    assert text_steepened > text_kept, gains
