"""The 3-D colour-map fit (``aarecovery.plan.colour_map``): palette quantisers are found,
neighbourhood filters are not, and the table reproduces the map where O has samples."""

import dataclasses

import numpy as np

import aarecovery
from aarecovery import Decision
from aarecovery.plan.analysis import analyse
from aarecovery.plan.calibration import EDGE_GRADIENT
from aarecovery.plan.colour_map import COLOUR_MAP_SHARE, INDEXED_COLOURS, fit_colour_map, indexed_colour_prior
from aarecovery.spec.pure_colours import COLOUR_KEY, transfer_encoded
from aarecovery.spec.sobel import gradient_magnitude


def _photo_like(size=128, seed=0):
    """Smooth colour fields with soft-edged blobs and sensor grain: textured, many colours."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:size, 0:size] / size
    image = np.stack([0.2 + 0.6 * x, 0.3 + 0.4 * y, 0.5 + 0.3 * np.sin(6 * x + 3 * y)], axis=-1)
    for _ in range(12):
        cy, cx, radius = rng.uniform(0, 1, 2).tolist() + [rng.uniform(0.05, 0.2)]
        inside = np.clip((radius - np.hypot(y - cy, x - cx)) * size / 1.5, 0, 1)[..., None]
        image = image * (1 - inside) + rng.uniform(0, 1, 3) * inside
    image = image + rng.normal(0, 3 / 255, image.shape)
    return np.clip(np.round(image * 255) / 255, 0, 1).astype(np.float32)


def _quantise(image, palette):
    distance = ((image[..., None, :] - palette) ** 2).sum(axis=-1)
    return palette[np.argmin(distance, axis=-1)].astype(np.float32)


def _box3(image):
    padded = np.pad(image, ((1, 1), (1, 1), (0, 0)), mode="edge")
    height, width = image.shape[:2]
    return sum(padded[dy:dy + height, dx:dx + width] for dy in range(3) for dx in range(3)) / 9


PALETTE = np.array([[0.1, 0.1, 0.2], [0.8, 0.3, 0.2], [0.3, 0.7, 0.4], [0.9, 0.9, 0.7]], np.float32)


def test_a_palette_quantiser_is_a_colour_map():
    original = _photo_like()
    filtered = _quantise(original, PALETTE)
    edges = gradient_magnitude(original) >= EDGE_GRADIENT
    fitted = fit_colour_map(original, filtered, edges)
    assert fitted.consistency >= COLOUR_MAP_SHARE
    # Away from the palette's boundaries the table gives the quantiser's colour.
    distances = np.sort(((original[..., None, :] - PALETTE) ** 2).sum(axis=-1), axis=-1)
    clear = np.sqrt(distances[..., 1]) - np.sqrt(distances[..., 0]) > 0.2
    assert np.abs(fitted(original)[clear] - filtered[clear]).max() < 2 / 255


def test_neighbourhood_filters_are_not_colour_maps():
    original = _photo_like()
    edges = gradient_magnitude(original) >= EDGE_GRADIENT
    blurred = _box3(original)
    sharpened = np.clip(original + 1.5 * (original - blurred), 0, 1)
    for filtered in (blurred, sharpened):
        assert fit_colour_map(original, filtered.astype(np.float32), edges).consistency < COLOUR_MAP_SHARE


def test_one_pixel_per_bin_proves_nothing():
    """Each edge pixel is left out of its own bin: pixels alone in theirs are not counted."""
    rng = np.random.default_rng(1)
    original = rng.uniform(0, 1, (8, 8, 3)).astype(np.float32)
    filtered = rng.uniform(0, 1, (8, 8, 3)).astype(np.float32)
    assert fit_colour_map(original, filtered, np.ones((8, 8), bool)).consistency < COLOUR_MAP_SHARE


def test_empty_bins_take_their_neighbours_colour():
    original = np.full((16, 16, 3), 0.5, np.float32)
    filtered = np.full((16, 16, 3), 0.25, np.float32)
    fitted = fit_colour_map(original, filtered, np.ones((16, 16), bool))
    far = np.array([[0.0, 1.0, 0.0], [1.0, 1.0, 1.0]], np.float32)
    assert np.allclose(fitted(far), 0.25, atol=1e-6)


def test_safe_plan_calibrates_a_palette_quantiser_of_a_photo():
    original = _photo_like(seed=2)
    filtered = _quantise(original, PALETTE)
    opaque = np.ones(original.shape[:2] + (1,), np.float32)
    analysis = analyse(np.concatenate([original, opaque], -1), np.concatenate([filtered, opaque], -1))
    assert analysis.decision == Decision.COLOUR_MAP_CALIBRATED, analysis.reason


def _quantised_poster():
    """The tuning half's poster in linear light under Pillow's quantize, and its edge band's
    text and graphics and photo regions."""
    from test_realtools import real_case
    return real_case("poster", "pil-quantize", "linear")


def test_text_over_a_quantised_photo_gets_full_strength():
    """The tuning half's poster in linear light under Pillow's quantize: the calibration
    chooses 0.5 for the photo, and the text and graphics over it, read as hard-edged by the
    local plan, get full strength. One strength for the whole image left 0.43 of their edge
    error removed, the local plan 0.53; the photo regions keep theirs."""
    from aarecovery.lab.metrics import error_reduction
    case, text, photo = _quantised_poster()
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(case.original, case.filtered)
        plan = engine.plan()
        assert plan.decision == Decision.COLOUR_MAP_CALIBRATED and plan.local is not None, plan.reason
        assert plan.strength == 1 and 0 < plan.local.textured < 1, plan.reason
        gains = []
        for each in (plan, dataclasses.replace(plan, local=None, strength=plan.local.textured)):
            engine.run(each)
            recovered = engine.result()
            gains.append([error_reduction(recovered, case.filtered, case.reference, region)
                          for region in (text, photo)])
    (text_local, photo_local), (text_one, photo_one) = gains
    assert text_local > 0.5 and text_one < 0.45, gains
    assert abs(photo_local - photo_one) < 0.01 and photo_local > 0.3, gains


def test_a_quantised_photos_local_plan_agrees_on_gl(gl_path):
    case, _, _ = _quantised_poster()
    numpy_result = aarecovery.recover(case.original, case.filtered, backend="numpy")
    with aarecovery.Engine("gl", gl_path=gl_path) as engine:
        gl_result = aarecovery.recover(case.original, case.filtered, engine=engine)
        assert engine.last_plan.local is not None, engine.last_plan.reason
    np.testing.assert_allclose(gl_result, numpy_result, atol=1e-5)


def test_an_indexed_colour_drawing_is_repaired_as_a_point_wise_map(backend):
    """A map converted to indexed colour (Pillow's median cut to 6 colours, no dithering): no
    table of one key explains it, and its flat palette colours read as a smoothing filter
    that keeps flat colours, which lost 0.66 dB against F (-0.163 of the edge error). As a
    colour map on hard-edged content, full strength: 0.455 measured (NumPy); with its thin
    features' pure colours through the 3-D table, 0.777 on both backends."""
    plan, reduction = _quantised_drawing_repaired(backend, "maps")
    assert plan.decision == Decision.COLOUR_MAP_HARD_EDGED, plan.reason
    assert plan.pure_colours is not None and plan.pure_colours.key == COLOUR_KEY, plan.reason
    assert reduction > 0.75


def _quantised_drawing_repaired(backend, family):
    """The tuning half's `family` in linear light under Pillow's quantize: the plan and R's
    edge-band error reduction."""
    from aarecovery.lab import realtools
    from aarecovery.lab.metrics import edge_band, error_reduction
    suite = realtools.RealToolsSuite("indexed", (family,), ("pil-quantize",), 96, {family: ("linear",)})
    (case,) = realtools.build_cases(suite, "tune", jpeg=False)
    band = edge_band(case.original, case.filtered, case.reference)
    with aarecovery.Engine(backend) as engine:
        engine.set_images(case.original, case.filtered)
        plan = engine.plan()
        engine.run(plan)
        return plan, error_reduction(engine.result(), case.filtered, case.reference, band)


def test_a_bilateral_filter_on_flat_colours_is_no_colour_map():
    """OpenCV's bilateral filter keeps a drawing's flat colours, so its 3-D table matches most
    edge pixels (the icons: 0.87), but not the share a colour map on hard-edged content needs."""
    from aarecovery.lab import realtools
    from aarecovery.plan.colour_map import HARD_EDGED_COLOUR_MAP_SHARE
    suite = realtools.RealToolsSuite("smoothed", ("icons",), ("cv-bilateral",), 96, {"icons": ("linear",)})
    (case,) = realtools.build_cases(suite, "tune", jpeg=False)
    edges = gradient_magnitude(case.original) >= EDGE_GRADIENT
    share = fit_colour_map(case.original, case.filtered, edges).consistency
    assert COLOUR_MAP_SHARE < share < HARD_EDGED_COLOUR_MAP_SHARE
    opaque = np.ones(case.original.shape[:2] + (1,), np.float32)
    analysis = analyse(np.concatenate([case.original, opaque], -1), np.concatenate([case.filtered, opaque], -1))
    assert analysis.decision == Decision.NEIGHBOURHOOD_HARD_EDGED, analysis.reason


def test_only_indexed_colour_gets_pure_colours_through_the_table():
    """F with a palette's few colours is indexed; a smooth map of every colour (channels
    swapped and scaled, as a hue change keeps O's many colours) is not: its table's bins far
    from O's colours are guesses."""
    original = _photo_like(seed=4)
    edges = gradient_magnitude(original) >= EDGE_GRADIENT
    indexed = _quantise(original, PALETTE)
    prior = indexed_colour_prior(original, indexed, fit_colour_map(original, indexed, edges))
    assert prior is not None and prior.key == COLOUR_KEY and prior.table.shape == (32, 32, 32, 3)
    assert not prior.explain_filtered
    smooth = (original[..., ::-1] * 0.9).astype(np.float32)
    assert indexed_colour_prior(original, smooth, fit_colour_map(original, smooth, edges)) is None
    # Many colours kept, though fewer than INDEXED_COLOURS: the share decides.
    few = np.round(original * 5) / 5
    assert len(np.unique(few.reshape(-1, 3), axis=0)) <= INDEXED_COLOURS
    assert indexed_colour_prior(original, few.astype(np.float32), fit_colour_map(original, few, edges)) is not None
    assert indexed_colour_prior(few.astype(np.float32), few.astype(np.float32),
                                fit_colour_map(few, few, edges)) is None


def test_the_colour_key_reads_the_fitted_map():
    """The specification's f for the colour key (what the passes read, transfer_encoded) is the
    fitted 3-D table's trilinear reading."""
    original = _photo_like(seed=5)
    filtered = _quantise(original, PALETTE)
    fitted = fit_colour_map(original, filtered, gradient_magnitude(original) >= EDGE_GRADIENT)
    planes = np.ascontiguousarray(original.reshape(-1, 3).T)
    np.testing.assert_array_equal(transfer_encoded(planes, COLOUR_KEY, fitted.table).T, fitted(original.reshape(-1, 3)))


def test_gl_extends_thin_features_through_a_colour_map_as_numpy(gl_path):
    """TABLE_KEY 9 (a 3-D texture read trilinearly, transfer_table.glsl) gives the NumPy
    specification's result on both GL paths, tiled and whole: the sRGB map under Pillow's
    quantize to 6 colours."""
    from parity import assert_results_agree
    from aarecovery.lab import realtools
    suite = realtools.RealToolsSuite("indexed", ("maps",), ("pil-quantize",), 96, {"maps": ("srgb",)})
    (case,) = realtools.build_cases(suite, "tune", jpeg=False)
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(case.original, case.filtered)
        plan = engine.plan()
        assert plan.pure_colours is not None and plan.pure_colours.key == COLOUR_KEY, plan.reason
        engine.run(plan)
        expected = engine.result()
        engine.run(dataclasses.replace(plan, pure_colours=None))
        without = engine.result()
    assert np.abs(expected - without).max() > 0.1  # the extension acts
    with aarecovery.Engine("gl", gl_path=gl_path) as engine:
        for tile in (None, 64):
            assert_results_agree(aarecovery.recover(case.original, case.filtered, engine=engine, tile_size=tile),
                                 expected, f"{gl_path} tile {tile}")


def test_indexed_colour_that_no_extension_key_explains_takes_the_colour_map(backend):
    """Serif text in red and greys under Pillow's quantize: the channels' mean explains F, but
    it is no key the extension reads, so the thin features took no pure colours (0.535 of the
    edge error removed); as indexed colour they take them through the 3-D table (0.873), with
    no ramp lookup (the passes hold one table, the ramp's of one key)."""
    plan, reduction = _quantised_drawing_repaired(backend, "serif")
    assert plan.decision == Decision.POINTWISE_HARD_EDGED, plan.reason
    assert plan.pure_colours is not None and plan.pure_colours.key == COLOUR_KEY, plan.reason
    assert plan.ramp_table is None
    assert reduction > 0.85


def test_a_quantised_screenshot_gets_the_colour_map_in_its_drawn_regions_on_every_backend(gl_path):
    """The screenshot (text and interface chrome over a photo) from a JPEG at q 90 under
    Pillow's quantize reads as textured: calibrated, with the 3-D table's pure colours gated to
    the drawn regions (tuning half 0.370 -> 0.422 of the edge error, its photo region up
    too), and GL's gated passes with TABLE_KEY 9 give the NumPy specification's result."""
    from parity import assert_results_agree
    from aarecovery.lab import realtools
    suite = realtools.RealToolsSuite("indexed", ("screenshot",), ("pil-quantize",), 96, {"screenshot": ("linear",)},
                                     (90,))
    case = [case for case in realtools.build_cases(suite, "tune") if case.quality == 90][0]
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(case.original, case.filtered)
        plan = engine.plan()
        assert plan.decision == Decision.POINTWISE_CALIBRATED, plan.reason
        assert plan.pure_colours is not None and plan.pure_colours.key == COLOUR_KEY, plan.reason
        assert plan.pure_colours.drawn_only and plan.ramp_table is None
        engine.run(plan)
        expected = engine.result()
    with aarecovery.Engine("gl", gl_path=gl_path) as engine:
        assert_results_agree(aarecovery.recover(case.original, case.filtered, engine=engine), expected, gl_path)
