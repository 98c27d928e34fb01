"""Neighbourhood filters that keep flat colours: thin features' pure colours with the identity table."""

import dataclasses

import numpy as np
import pytest

import aarecovery
from aarecovery.plan import analyse
from aarecovery.plan.flat_colours import (FLAT_KEPT_SHARE, LINE_MISS, colour_line_miss, flat_colour_prior,
                                          flat_kept_share)
from aarecovery.spec import to_working_space
from aarecovery.spec.passes import recover_working
from aarecovery.spec.pure_colours import PureColourPrior


def rgba(image):
    return np.concatenate([image, np.ones(image.shape[:2] + (1,), np.float32)], -1)


def thin_lines(height=40, width=40):
    """White paper, a dark-blue square, and thin lines straddling two pixels (no pure ink pixel)."""
    image = np.ones((height, width, 3), np.float32)
    image[4:16, 4:16] = (0.1, 0.2, 0.6)
    image[24, 4:36] = 0.45                # a horizontal black line, 0.7 px wide
    image[25, 4:36] = 0.85
    image[28:38, 30] = (0.55, 0.6, 0.8)   # a blue line
    image[28:38, 31] = (0.9, 0.92, 0.95)
    return image


def sharpened(image, amount=1.5):
    """A 3x3 unsharp mask, clipped: keeps flat areas, darkens thin lines, overshoots edges."""
    padded = np.pad(image, ((1, 1), (1, 1), (0, 0)), mode="edge")
    height, width = image.shape[:2]
    blurred = sum(padded[1 + dy:1 + dy + height, 1 + dx:1 + dx + width]
                  for dy in (-1, 0, 1) for dx in (-1, 0, 1)) / 9
    return np.clip(image + amount * (image - blurred), 0, 1).astype(np.float32)


def edges_of(image):
    return np.abs(np.diff(image, axis=0, append=image[-1:])).max(-1) + \
        np.abs(np.diff(image, axis=1, append=image[:, -1:])).max(-1) > 0.05


def test_flat_kept_share_counts_deep_flat_pixels_that_f_keeps():
    original = thin_lines()
    assert flat_kept_share(original, original) == 1.0
    assert flat_kept_share(original, sharpened(original)) > 0.9
    assert flat_kept_share(original, np.clip(original * 0.8, 0, 1)) < 0.1
    # Too few deep flat pixels decide nothing.
    noise = np.random.default_rng(1).random((20, 20, 3)).astype(np.float32)
    assert flat_kept_share(noise, noise) == 0.0


def bars_over_noise(height=40, width=40, seed=3):
    """Three dark bars 3 px tall over a photo's noise: no pixel is flat 2 px around it, the
    middle row of each bar is flat 1 px around it (90 pixels)."""
    rng = np.random.default_rng(seed)
    image = np.clip(0.6 + rng.normal(0, 0.05, (height, width, 3)), 0, 1).astype(np.float32)
    bars = np.zeros((height, width), bool)
    for top in (6, 18, 30):
        bars[top:top + 3, 4:36] = True
    image[bars] = (0.1, 0.1, 0.3)
    return image, bars


def test_small_text_over_a_photo_is_judged_by_its_3x3_flat_pixels():
    # The tuning half's 96 px poster has 19 pixels flat 2 px around them, 459 flat 1 px around.
    original, bars = bars_over_noise()
    near_bars = np.zeros_like(bars)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            near_bars |= np.roll(bars, (dy, dx), (0, 1))
    padded = np.pad(original, ((1, 1), (1, 1), (0, 0)), mode="edge")
    box = sum(padded[1 + dy:41 + dy, 1 + dx:41 + dx] for dy in (-1, 0, 1) for dx in (-1, 0, 1)) / 9
    smoothed = np.where(near_bars[..., None], original, box).astype(np.float32)  # edge-aware smoothing
    assert flat_kept_share(original, smoothed) == 1.0
    assert flat_kept_share(original, original[..., ::-1].copy()) == 0.0  # a colour change keeps none
    plain = np.clip(0.6 + np.random.default_rng(4).normal(0, 0.05, original.shape), 0, 1).astype(np.float32)
    assert flat_kept_share(plain, plain) == 0.0  # no flat pixel at all decides nothing


def test_colour_line_miss_separates_sharpening_from_a_colour_change():
    # Blue shapes on white: a swap of red and blue keeps the white paper (the flat test
    # passes) and moves every blue edge off its line. The miss is a percentile over edge
    # pixels, so the coloured edges must be most of them, as they are here.
    original = np.ones((40, 40, 3), np.float32)
    for top in (4, 16, 28):
        original[top:top + 8, 4:36] = (0.1, 0.2, 0.6)
    edges = edges_of(original)
    # Clipping the overshoot per channel moves F off the line a little (38/255 here).
    assert colour_line_miss(original, sharpened(original), edges) < LINE_MISS
    assert colour_line_miss(original, original, edges) == 0
    swapped = original[..., ::-1].copy()
    assert flat_kept_share(original, swapped) > FLAT_KEPT_SHARE
    assert colour_line_miss(original, swapped, edges) > LINE_MISS
    assert colour_line_miss(original, original, np.zeros(edges.shape, bool)) == float("inf")


def test_prior_is_the_identity_where_the_filter_keeps_colours():
    original = thin_lines()
    edges = edges_of(original)
    prior, reason = flat_colour_prior(original, sharpened(original), edges)
    assert isinstance(prior, PureColourPrior) and prior.key == "channel" and prior.to_cube
    assert not prior.explain_filtered
    np.testing.assert_allclose(prior.table[:, 0], (np.arange(256) + 0.5) / 256)
    assert "flat colours kept on 1.00" in reason
    assert flat_colour_prior(original, np.clip(original * 0.8, 0, 1), edges)[0] is None


def test_thin_lines_darkened_by_sharpening_are_restored():
    # The half-covered lines have no pure ink pixel; sharpening pushes them to near black.
    # With the identity prior they are extended to the ink and blended back to half coverage.
    original = thin_lines()
    filtered = sharpened(original)
    analysis = analyse(rgba(original), rgba(filtered))
    assert analysis.decision == aarecovery.Decision.NEIGHBOURHOOD_HARD_EDGED
    assert analysis.pure_colours is not None and not analysis.pure_colours.explain_filtered
    recovered = aarecovery.recover(original, filtered, backend="numpy")
    paper = aarecovery.recover(original, filtered, backend="numpy", mode="paper")
    line = (slice(24, 26), slice(8, 32))
    # Sharpened: near black on the line; the paper's model keeps that (its extremes are the
    # line itself and the paper); recovered: back to O's coverage.
    assert np.abs(filtered[line] - original[line]).max() > 0.4
    assert np.abs(paper[line] - original[line]).max() > 0.4
    assert np.abs(recovered[line] - original[line]).max() < 0.05


def test_an_erased_or_recoloured_thin_feature_is_not_extended():
    # Edge-aware smoothing that erases a thin line meant to (its reference has it erased);
    # a hue change moves it off O's colour line. Neither is extended to the ink.
    original = thin_lines()
    filtered = sharpened(original)
    prior, _ = flat_colour_prior(original, filtered, edges_of(original))
    erased, recoloured = filtered.copy(), filtered.copy()
    erased[24:26, 4:36] = 0.97
    recoloured[24:26, 4:36] = (0.9, 0.1, 0.1)
    work_o = to_working_space(rgba(original))
    for changed in (erased, recoloured):
        _, model = recover_working(work_o, to_working_space(rgba(changed)), 0.1, 0.01, 3, 1.0, prior, "linear")
        assert not (model.pure_a[21:27, 8:28].any() or model.pure_b[21:27, 8:28].any())


def test_without_the_explain_test_the_extension_reaches_a_damaged_extreme():
    # The same prior with the point-wise rule (F must equal f(extreme)) extends nothing here,
    # since F at the thin line is its damage, not f of its colour.
    original = thin_lines()
    filtered = sharpened(original)
    prior, _ = flat_colour_prior(original, filtered, edges_of(original))
    work_o, work_f = to_working_space(rgba(original)), to_working_space(rgba(filtered))
    _, model = recover_working(work_o, work_f, 0.1, 0.01, 3, 1.0, prior, "linear")
    explained = dataclasses.replace(prior, explain_filtered=True)
    _, strict = recover_working(work_o, work_f, 0.1, 0.01, 3, 1.0, explained, "linear")
    assert model.pure_a[23:26, 8:32].any() or model.pure_b[23:26, 8:32].any()
    assert not (strict.pure_a[23:26, 8:32].any() or strict.pure_b[23:26, 8:32].any())


def test_gl_agrees_with_numpy_on_a_sharpened_thin_line(gl_path):
    # The GL fit pass's twin of the prior without the explain test (uniform explain_filtered).
    gl_engine = aarecovery.Engine(backend="gl", gl_path=gl_path)
    try:
        _gl_agrees(gl_engine)
    finally:
        gl_engine.release()


def _gl_agrees(gl_engine):
    original = np.rint(thin_lines() * 255).astype(np.uint8)
    filtered = np.rint(sharpened(thin_lines()) * 255).astype(np.uint8)
    actual = aarecovery.recover(original, filtered, engine=gl_engine)
    assert gl_engine.last_plan.pure_colours is not None
    assert not gl_engine.last_plan.pure_colours.explain_filtered
    expected = aarecovery.recover(original, filtered, backend="numpy")
    assert np.abs(actual.astype(np.int64) - expected).max() <= 1
    paper = aarecovery.recover(original, filtered, backend="numpy", mode="paper")
    assert np.abs(expected.astype(np.int64) - paper).max() > 64
    _, maps = aarecovery.recover(original, filtered, engine=gl_engine, return_maps=True)
    _, expected_maps = aarecovery.recover(original, filtered, backend="numpy", return_maps=True)
    np.testing.assert_allclose(maps.beta, expected_maps.beta, rtol=0, atol=1e-5)


@pytest.mark.parametrize("filter_name", ["im-unsharp", "gmic-bilateral"])
def test_real_tools_sharpening_and_smoothing_of_text(filter_name):
    # ImageMagick's -unsharp and G'MIC's -bilateral on serif text (tuning half): measured
    # 0.41 -> 0.93 and 0.49 -> 0.71 (linear), the paper's passes before.
    from aarecovery.lab import realtools
    from aarecovery.lab.metrics import edge_band, error_reduction
    from test_realtools import require_tool
    require_tool(realtools.TOOL_FILTERS[filter_name].tool)
    suite = dataclasses.replace(realtools.REAL_FULL, families=("serif",), filters=(filter_name,),
                                spaces={"serif": ("linear",)})
    (case,) = realtools.build_cases(suite, "tune", jpeg=False)
    engine = aarecovery.Engine("numpy")
    recovered = aarecovery.recover(case.original, case.filtered, engine=engine)
    plan = engine.last_plan
    assert plan.decision == aarecovery.Decision.NEIGHBOURHOOD_HARD_EDGED, plan.reason
    assert plan.pure_colours is not None and not plan.pure_colours.explain_filtered, plan.reason
    paper = aarecovery.recover(case.original, case.filtered, backend="numpy", mode="paper")
    band = edge_band(case.original, case.filtered, case.reference)
    gain = error_reduction(recovered, case.filtered, case.reference, band)
    assert gain > error_reduction(paper, case.filtered, case.reference, band) + 0.15
    assert gain > 0.65


def test_real_tools_smoothing_of_text_over_a_photo_takes_pure_colours():
    # OpenCV's edge-preserving smoothing on the 96 px poster (tuning half): too few pixels
    # flat 2 px around them to tell that it keeps colours; by its 3 x 3 flat pixels, the text
    # and graphics 0.221 -> 0.344 of their edge error, the photo regions within 0.001.
    from aarecovery.lab import realtools
    from aarecovery.lab.metrics import edge_band, error_reduction
    from test_realtools import require_tool
    require_tool(realtools.TOOL_FILTERS["cv-smoothing"].tool)
    suite = dataclasses.replace(realtools.REAL_FULL, families=("poster",), filters=("cv-smoothing",),
                                spaces={"poster": ("linear",)})
    (case,) = realtools.build_cases(suite, "tune", jpeg=False)
    engine = aarecovery.Engine("numpy")
    recovered = aarecovery.recover(case.original, case.filtered, engine=engine)
    plan = engine.last_plan
    assert plan.decision == aarecovery.Decision.NEIGHBOURHOOD_MIXED, plan.reason
    assert plan.pure_colours is not None, plan.reason
    band = edge_band(case.original, case.filtered, case.reference)
    text = error_reduction(recovered, case.filtered, case.reference, band & case.regions["text/graphics"])
    photo = error_reduction(recovered, case.filtered, case.reference, band & case.regions["photo"])
    assert text > 0.3
    assert photo > -0.005


def sharpened_wide(image, amount=1.5):
    """A 5 x 5 unsharp mask, clipped: its halos reach two pixels past an edge."""
    padded = np.pad(image, ((2, 2), (2, 2), (0, 0)), mode="edge")
    height, width = image.shape[:2]
    blurred = sum(padded[2 + dy:2 + dy + height, 2 + dx:2 + dx + width]
                  for dy in range(-2, 3) for dx in range(-2, 3)) / 25
    return np.clip(image + amount * (image - blurred), 0, 1).astype(np.float32)


def test_a_sharpening_filters_halos_over_small_text_leave_the_colour_line_to_decide():
    # The bars' only flat pixels (their middle rows) lie within the halos of a 5 x 5 mask:
    # none is kept, yet the filter keeps colours. Told it sharpens, the colour-line miss
    # alone decides, and a colour change still misses O's lines.
    original, _ = bars_over_noise()
    filtered = sharpened_wide(original)
    edges = edges_of(original)
    assert flat_kept_share(original, filtered) < FLAT_KEPT_SHARE
    assert flat_colour_prior(original, filtered, edges)[0] is None
    prior, reason = flat_colour_prior(original, filtered, edges, sharpened=True)
    assert isinstance(prior, PureColourPrior) and prior.key == "channel", reason
    swapped = filtered[..., ::-1].copy()
    assert colour_line_miss(original, swapped, edges) > LINE_MISS
    assert flat_colour_prior(original, swapped, edges, sharpened=True)[0] is None


def test_text_over_a_photo_under_an_unsharp_mask_gets_its_pure_colours(monkeypatch):
    """The tuning half's poster made in sRGB values under ImageMagick's unsharp mask: its
    text keeps 0.09 of its few flat pixels, all within the halos. Its text and graphics had
    0.16 of their edge error removed without pure colours, 0.48 with them; the photo regions
    keep theirs."""
    from aarecovery.lab.metrics import error_reduction
    from aarecovery.plan import analysis
    from test_realtools import real_case
    case, text, photo = real_case("poster", "im-unsharp", "srgb")

    def repaired():
        recovered = aarecovery.recover(case.original, case.filtered, engine=engine)
        return (engine.last_plan, error_reduction(recovered, case.filtered, case.reference, text),
                error_reduction(recovered, case.filtered, case.reference, photo))

    engine = aarecovery.Engine("numpy")
    plan, text_gain, photo_gain = repaired()
    assert plan.decision == aarecovery.Decision.NEIGHBOURHOOD_MIXED and plan.pure_colours is not None, plan.reason
    asked = analysis.flat_colour_prior
    monkeypatch.setattr(analysis, "flat_colour_prior",
                        lambda *args, **kwargs: asked(*args, **{**kwargs, "sharpened": False}))
    plan_before, text_before, photo_before = repaired()
    assert plan_before.pure_colours is None, plan_before.reason
    assert text_gain > 0.4 and text_before < 0.25, (text_gain, text_before)
    assert photo_gain >= photo_before - 1e-3 and photo_gain > 0, (photo_gain, photo_before)
