"""The pure colours of thin features (safe default, point-wise filters on hard-edged content)."""

import numpy as np
import pytest

import aarecovery
from aarecovery.lab import scenes as _scenes
from aarecovery.lab.groundtruth import make_case
from aarecovery.lab.metrics import edge_band, error_reduction
from aarecovery.plan.pure_colours import inks_of, is_monotone, palette_of, turns_at_most_once
from aarecovery.spec.pure_colours import INK_COUNT
from aarecovery.tiling import halo_for
from aarecovery.spec import fit_blend_model, to_working_space
from aarecovery.plan import analyse
from aarecovery.plan.resample import box_downsample
from aarecovery.colour import linear_to_srgb
from aarecovery.spec.neighbourhood import neighbours, planes
from aarecovery.spec.sobel import ridge_magnitude, sobel_magnitude


def rgba(image):
    return np.concatenate([image, np.ones(image.shape[:2] + (1,), np.float32)], -1)


def thin_line_case():
    """Text of 7-16 px antialiased in linear light, thresholded: thin strokes lighter than the
    threshold vanish from F, and no pixel of them holds the pure ink."""
    return make_case(_scenes.render("text", 48, 4), "threshold", 4, "linear")


def test_palette_holds_flat_colours_only():
    case = thin_line_case()
    palette = palette_of(case.original)
    assert 4 <= len(palette) <= 32
    assert np.abs(palette - [1, 1, 1]).max(axis=1).min() < 1e-6  # the white paper
    assert np.abs(palette - [0, 0, 0]).max(axis=1).min() > 0.1   # black ink is never flat at 7 px


def test_inks_are_colours_on_the_cubes_faces_seen_four_times_or_more():
    image = np.full((8, 8, 3), 0.5, np.float32)       # a grey, on no face: never an ink
    image[0, :5] = (0, 89 / 255, 38 / 255)            # 5 times, red channel 0
    image[1, :6] = (253 / 255, 200 / 255, 10 / 255)   # 6 times, 2 levels from a face
    image[2, :3] = (1, 0, 0)                          # 3 times: too few
    image[3, :7] = (3 / 255, 100 / 255, 100 / 255)    # 7 times, 3 levels from a face
    inks = inks_of(image)
    # Most frequent first, then black and white, which O does not show (CORNER_INKS).
    np.testing.assert_array_equal(inks * 255, [[253, 200, 10], [0, 89, 38], [0, 0, 0], [255, 255, 255]])
    assert inks.dtype == np.float32
    image[4] = 1                                      # white seen: not twice
    np.testing.assert_array_equal(inks_of(image) * 255, [[255, 255, 255], [253, 200, 10], [0, 89, 38], [0, 0, 0]])
    many = np.zeros((4, 20 * 4, 3), np.float32)       # 20 saturated inks seen: the corners take the last places
    many[..., 0] = 1
    many[..., 1] = np.repeat(np.arange(20) * 10 + 5, 4)[None] / 255
    inks = inks_of(many)
    assert len(inks) == INK_COUNT
    np.testing.assert_array_equal(inks[-2:], [[0, 0, 0], [1, 1, 1]])


def test_thin_strokes_erased_by_threshold_are_restored():
    case = thin_line_case()
    plan = analyse(rgba(case.original), rgba(case.filtered))
    assert plan.pure_colours is not None and plan.pure_colours.key == "luma"
    band = edge_band(case.original, case.filtered, case.reference)
    safe = aarecovery.recover(case.original, case.filtered, backend="numpy")
    paper = aarecovery.recover(case.original, case.filtered, backend="numpy", mode="paper")
    # Measured: paper 0.45, safe 0.95.
    assert error_reduction(paper, case.filtered, case.reference, band) < 0.6
    assert error_reduction(safe, case.filtered, case.reference, band) > 0.85


#: A JET-like ramp for the project's gradient map: green and blue rise and fall again.
JET_RAMP = ((0, 0, 0.5), (0, 0.5, 1), (0.5, 1, 0.5), (1, 0.5, 0), (0.5, 0, 0))


def test_a_colour_maps_hump_is_a_table_and_a_zigzag_is_not():
    keys = np.linspace(0, 1, 256)[:, None]
    ramp = np.asarray(JET_RAMP)
    jet = np.stack([np.interp(keys[:, 0], np.linspace(0, 1, 5), ramp[:, c]) for c in range(3)], -1)
    assert not is_monotone(jet) and turns_at_most_once(jet)
    # Colours ranked by luma by chance: a colour to grey of a few hues zigzags.
    zigzag = np.repeat(np.asarray([0.2, 0.9, 0.1, 0.8, 0.3, 1.0, 0.0, 0.6]), 32)[:, None] * np.ones((1, 3))
    assert not turns_at_most_once(zigzag)
    assert turns_at_most_once(keys * np.ones((1, 3)))


def test_thin_strokes_under_a_jet_colour_map_get_their_pure_colours(backend):
    # A colour map of the grey value takes thin strokes through colours the filter's table
    # knows, though no column of it is monotone. Measured, both backends: 0.879, without the
    # pure colours (the rule before) 0.329, the paper's 0.329.
    case = make_case(_scenes.render("text", 48, 4), "gradientmap", 4, "linear", colours=JET_RAMP)
    plan = analyse(rgba(case.original), rgba(case.filtered))
    assert plan.pure_colours is not None and not is_monotone(plan.pure_colours.table)
    band = edge_band(case.original, case.filtered, case.reference)
    safe = aarecovery.recover(case.original, case.filtered, backend=backend)
    paper = aarecovery.recover(case.original, case.filtered, backend=backend, mode="paper")
    assert error_reduction(safe, case.filtered, case.reference, band) > 0.8
    assert error_reduction(paper, case.filtered, case.reference, band) < 0.5


def opencv_jet_of_grey(image):
    """OpenCV's recipe for a colour map of a colour image (cvtColor to grey, its fixed-point
    Rec. 601 weights, then applyColorMap), with :data:`JET_RAMP` as the map."""
    levels = np.rint(np.clip(image, 0, 1) * 255).astype(np.int64)
    grey = (4899 * levels[..., 0] + 9617 * levels[..., 1] + 1868 * levels[..., 2] + 8192) >> 14
    ramp = np.asarray(JET_RAMP)
    return np.stack([np.interp(grey, np.linspace(0, 255, len(ramp)), ramp[:, c]) for c in range(3)],
                    -1).astype(np.float32)


def test_a_colour_map_of_the_rec601_grey_reads_its_table_by_that_grey(backend):
    # Coloured strokes under a colour map of the 8-bit Rec. 601 grey: no other key explains
    # F, and the pure colours read the table by that grey ("luma601"). Measured, both
    # backends: 0.736, the paper's 0.447, without pure colours (before luma601 was a key of
    # the extension) 0.609.
    scene = _scenes.render("chart", 48, 4)
    original = box_downsample(scene, 4, "srgb")
    filtered = opencv_jet_of_grey(original)
    reference = box_downsample(opencv_jet_of_grey(scene), 4, "srgb")
    plan = analyse(rgba(original), rgba(filtered))
    assert plan.pure_colours is not None and plan.pure_colours.key == "luma601"
    band = edge_band(original, filtered, reference)
    safe = aarecovery.recover(original, filtered, backend=backend)
    paper = aarecovery.recover(original, filtered, backend=backend, mode="paper")
    assert error_reduction(safe, filtered, reference, band) > error_reduction(paper, filtered, reference, band) + 0.1


def test_small_shapes_cost_little():
    # Known cost: at 48 px some thin slivers of mid-colour shapes pass as thin features and
    # are extended to the colour cube (8 % of pixels); measured 0.85 against the paper's 0.93.
    case = make_case(_scenes.render("shapes", 48, 4), "gamma", 4, "linear")
    band = edge_band(case.original, case.filtered, case.reference)
    safe = aarecovery.recover(case.original, case.filtered, backend="numpy")
    paper = aarecovery.recover(case.original, case.filtered, backend="numpy", mode="paper")
    assert error_reduction(safe, case.filtered, case.reference, band) > \
        error_reduction(paper, case.filtered, case.reference, band) - 0.1


def test_without_prior_the_fit_is_the_papers():
    case = thin_line_case()
    work_o, work_f = to_working_space(rgba(case.original)), to_working_space(rgba(case.filtered))
    model = fit_blend_model(work_o, work_f, 0.1, 0.01)
    assert model.pure_a is None and model.fixed_a is None


# Small tiles on purpose: they put tile borders everywhere in a small image.
@pytest.mark.filterwarnings("ignore::aarecovery.errors.TileSizeWarning")
@pytest.mark.parametrize("iterations", [1, 3])
def test_tiled_equals_untiled(backend, iterations):
    scene = _scenes.render("text", 48, 4)
    case = make_case(scene, "threshold", 4, "linear")
    original = np.rint(case.original * 255).astype(np.uint8)
    filtered = np.rint(case.filtered * 255).astype(np.uint8)
    whole = aarecovery.recover(original, filtered, backend=backend, iterations=iterations)
    tiled = aarecovery.recover(original, filtered, backend=backend, iterations=iterations,
                               tile_size=2 * halo_for(iterations) + 7)
    np.testing.assert_array_equal(tiled, whole)


# Small tiles on purpose: they put tile borders everywhere in a small image.
@pytest.mark.filterwarnings("ignore::aarecovery.errors.TileSizeWarning")
def test_tiled_maps_equal_untiled(backend):
    case = thin_line_case()
    _, whole = aarecovery.recover(case.original, case.filtered, backend=backend, iterations=0, return_maps=True)
    _, tiled = aarecovery.recover(case.original, case.filtered, backend=backend, iterations=0, return_maps=True,
                                  tile_size=2 * halo_for(0) + 3)
    for name in aarecovery.RecoveryMaps.NAMES:
        np.testing.assert_array_equal(getattr(tiled, name), getattr(whole, name))


def test_table_ends_are_extrapolated_by_a_power_law():
    # A gamma curve seen only on [0.1, 1] reaches black at black (gamma on lines/sRGB: the
    # 0.7 px black lines never show a black pixel in O); a threshold's flat end stays flat.
    from aarecovery.plan.pure_colours import extrapolate_table
    centres = (np.arange(256) + 0.5) / 256
    filled = np.repeat((centres >= 0.1)[:, None], 3, axis=1)
    gamma = np.repeat(np.where(centres >= 0.1, centres, 0.1)[:, None] ** 0.5, 3, axis=1).astype(np.float32)
    table, low, high = extrapolate_table(gamma, filled)
    assert table[0, 0] < 0.08 and abs(low[0] - centres[filled[:, 0]][0]) < 1e-6 and high[0] == centres[-1]
    np.testing.assert_allclose(table[filled[:, 0]], gamma[filled[:, 0]])
    step = np.repeat(np.where(centres >= 0.5, 1.0, 0.0)[:, None], 3, axis=1).astype(np.float32)
    np.testing.assert_array_equal(extrapolate_table(step, filled)[0], step)


@pytest.mark.parametrize("filter_name", ["gamma", "equalize", "tonemap"])
def test_darkest_colour_between_thin_lines_is_pure(filter_name):
    # The dark paper between 0.5 px white lines (lines scene, lower right panel) is O's darkest
    # colour and no flat colour (the gaps are 1.1 px): a ridge, but not a partial colour. It
    # used to be extended to black, so that the whole paper was recovered as a blend of
    # f(black) and f(white) (equalize: 0.145 where F and the reference are 0.05).
    case = make_case(_scenes.render("lines", 80, 4), filter_name, 4, "srgb")
    o, f = case.original, case.filtered
    recovered = aarecovery.recover(o, f, backend="numpy")
    height, width = o.shape[:2]
    panel = (slice(height // 2 + 2, height - 2), slice(width // 2 + 2, width - 2))
    paper = np.abs(o[panel] - 0.1).max(axis=-1) < 0.5 / 255
    assert paper.sum() > 50
    assert np.abs(recovered[panel][paper] - f[panel][paper]).max() < 2 / 255


def test_a_smooth_gradient_keeps_f_and_a_one_ulp_change_of_o_changes_nothing(backend):
    """A gradient stepping by 1-2 levels under a per-channel threshold: F is flat there, and
    so must R be, on every backend and for an O that differs by one float32 ulp (what GIMP's
    own u8-to-float conversion gives). Before the extension required more than 8 levels of
    contrast, the gradient's quantisation noise was extended to pure colours: R showed
    (0, 13, 0) and (20, 20, 0) on black, at pixels that swapped under a 1-ulp change."""
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).parent))
    from scenes import disc_and_bar
    eight_bit = np.round(np.clip(disc_and_bar(), 0, 1) * 255) / 255
    original = eight_bit.astype(np.float32)
    filtered = original.copy()
    filtered[..., :3] = original[..., :3] >= 0.5
    nudged = np.nextafter(original, np.float32(2)).astype(np.float32)
    # The safe default calls this gradient a photo (its grain); the extension is tested here
    # on its own, with the prior the analysis builds for hard-edged content.
    import dataclasses
    from aarecovery.params import Parameters
    from aarecovery.plan import make_plan
    from aarecovery.plan.pointwise import fit_pointwise
    from aarecovery.plan.pure_colours import pure_colour_prior
    prior = pure_colour_prior(original[..., :3], fit_pointwise(original[..., :3], filtered[..., :3],
                                                               np.ones(original.shape[:2], bool)), "srgb")
    assert prior is not None
    results = []
    with aarecovery.Engine(backend) as engine:
        for o in (original, nudged):
            plan = dataclasses.replace(make_plan(o, filtered, Parameters(), mode="paper", blend_space="srgb"),
                                       pure_colours=prior)
            engine.set_images(o, filtered)
            engine.run(plan)
            results.append(engine.result())
    np.testing.assert_allclose(results[0], results[1], rtol=0, atol=1 / 255)
    # Where F and O are flat-ish (no threshold edge in F's 3x3, O's steps of 1-2 levels),
    # R keeps F.
    padded = np.pad(filtered, ((1, 1), (1, 1), (0, 0)), mode="edge")
    f_flat = np.all([np.all(padded[1 + dy:41 + dy, 1 + dx:57 + dx] == filtered, axis=-1)
                     for dy in (-1, 0, 1) for dx in (-1, 0, 1)], axis=0)
    padded_o = np.pad(original, ((1, 1), (1, 1), (0, 0)), mode="edge")
    o_smooth = np.all([np.abs(padded_o[1 + dy:41 + dy, 1 + dx:57 + dx] - original).max(axis=-1) <= 2.5 / 255
                       for dy in (-1, 0, 1) for dx in (-1, 0, 1)], axis=0)
    smooth = f_flat & o_smooth
    assert smooth.sum() > 500
    np.testing.assert_array_equal(results[0][smooth], filtered[smooth])


def test_thin_features_are_not_extended_to_the_cube_when_f_is_straight_in_the_key():
    """Colour to grey by luma is a straight function of the luma key: the cube extension's
    guessed inks could only add error. A threshold of the same luma bends: it extends."""
    from aarecovery.colour import luma
    from aarecovery.lab import realtools
    from aarecovery.plan.pointwise import fit_pointwise
    from aarecovery.plan.pure_colours import STRAIGHT_TABLE_MISS, affine_in_key_miss, clipped_share, pure_colour_prior
    from aarecovery.plan.resample import box_downsample
    from aarecovery.spec.sobel import gradient_magnitude
    scene = realtools.render_family("starburst", 64)
    original = np.rint(box_downsample(scene, realtools.FAMILIES["starburst"].k, "srgb") * 255) / np.float32(255)
    edges = gradient_magnitude(original) >= 0.02
    grey = np.repeat(luma(original)[..., None], 3, axis=-1).astype(np.float32)
    thresholded = np.repeat((luma(original) >= 0.5)[..., None], 3, axis=-1).astype(np.float32)
    assert affine_in_key_miss(original, grey, edges, "luma") < 1e-4
    assert affine_in_key_miss(original, thresholded, edges, "luma") > 5 * STRAIGHT_TABLE_MISS
    assert clipped_share(original, grey, edges, "luma") == 0
    priors = {}
    for name, filtered in (("grey", grey), ("threshold", thresholded)):
        transfer = fit_pointwise(original, filtered, edges)
        priors[name] = pure_colour_prior(original, transfer, "srgb", filtered, edges)
        assert priors[name] is not None and priors[name].key in ("luma", "luminance", "luminance_d50", "channel")
    assert not priors["grey"].to_cube
    assert priors["threshold"].to_cube


def test_an_affine_stretch_that_clips_inside_os_range_extends_thin_features_to_the_cube(backend):
    """Pillow's autocontrast (2% clipped at each end) is affine in each channel on most edge
    pixels, but clips the memo's ink: the table bends there as a threshold's does, and the
    sub-pixel strokes take the cube's ink past O's darkest extreme. Measured (NumPy): 0.681
    of the edge error, 0.214 with O's darkest extreme as the ink, the paper's method 0.533."""
    from aarecovery.lab import realtools
    from aarecovery.plan.pure_colours import (STRAIGHT_TABLE_CLIPPED, STRAIGHT_TABLE_MISS, affine_in_key_miss,
                                              clipped_share)
    from aarecovery.spec.sobel import gradient_magnitude
    suite = realtools.RealToolsSuite("stretch", ("memo",), ("pil-autocontrast",), 96, {"memo": ("srgb",)})
    (case,) = realtools.build_cases(suite, "tune", jpeg=False)
    original, filtered = case.original[..., :3], case.filtered[..., :3]
    edges = gradient_magnitude(original) >= 0.02
    assert affine_in_key_miss(original, filtered, edges, "channel") < STRAIGHT_TABLE_MISS
    assert clipped_share(original, filtered, edges, "channel") > 2 * STRAIGHT_TABLE_CLIPPED
    plan = analyse(rgba(original), rgba(filtered))
    assert plan.pure_colours is not None and plan.pure_colours.to_cube, plan.reason
    band = edge_band(case.original, case.filtered, case.reference)
    safe = aarecovery.recover(case.original, case.filtered, backend=backend)
    assert error_reduction(safe, case.filtered, case.reference, band) > 0.6


def test_a_jpegs_table_is_not_extrapolated_past_its_range():
    # The star burst saved as a JPEG at q 75 (subsampled chroma: its thin spokes lose their
    # colour) under OpenCV's gamma 2.2: extended to near white through the power law past the
    # top of O's range, the spokes lost 3.0 dB against F on the tuning half; with the table
    # flat past O's range, R gains.
    from test_safeguards import family_as_jpeg

    from aarecovery.lab.realtools import FAMILIES
    from aarecovery.plan.resample import box_downsample
    scene, clean, original = family_as_jpeg("starburst", 96, 75)
    gamma = np.rint((np.arange(256) / 255.0) ** 2.2 * 255).astype(np.uint8)
    filtered = gamma[original]
    reference = box_downsample(gamma[scene].astype(np.float32) / 255, FAMILIES["starburst"].k, "srgb")
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(original, filtered)
        plan = engine.plan()
        assert plan.decision == aarecovery.Decision.POINTWISE_HARD_EDGED_COMPRESSED, plan.reason
        assert plan.pure_colours is not None and plan.pure_colours.to_cube
        recovered = aarecovery.recover(original, filtered, engine=engine)
    band = edge_band(clean.astype(np.float32) / 255, gamma[clean].astype(np.float32) / 255, reference)
    assert error_reduction(recovered.astype(np.float32) / 255, filtered.astype(np.float32) / 255, reference, band) > 0


def test_ridges_of_compression_noise_are_not_thin_features(monkeypatch):
    # The star burst antialiased in linear light, saved as a JPEG at q 85, under a gamma
    # curve: the ringing between its sub-pixel spokes made ridges lower than the extreme by a
    # tenth of the span, and extended to the cube they cost 0.34 dB against F (tuning half).
    # Measured at 96 px, the luma purity off (it guards these spokes too, next test): error
    # reduction -0.083 with the span's tenth alone, +0.058 with the noise's margin too.
    from test_safeguards import family_as_jpeg

    from aarecovery.lab.realtools import FAMILIES
    from aarecovery.plan import analysis
    from aarecovery.plan.resample import box_downsample
    from aarecovery.spec import pure_colours
    monkeypatch.setattr(analysis, "COMPRESSED_LUMA_PURITY", 0.0)
    scene, clean, original = family_as_jpeg("starburst", 96, 85, "linear")
    gamma = np.rint((np.arange(256) / 255.0) ** 2.2 * 255).astype(np.uint8)
    filtered = gamma[original]
    reference = box_downsample(gamma[scene].astype(np.float32) / 255, FAMILIES["starburst"].k, "linear")
    band = edge_band(clean.astype(np.float32) / 255, gamma[clean].astype(np.float32) / 255, reference)

    def reduction():
        with aarecovery.Engine("numpy") as engine:
            engine.set_images(original, filtered)
            assert engine.plan().pure_colours.noise_contrast > 0
            recovered = aarecovery.recover(original, filtered, engine=engine)
        return error_reduction(recovered.astype(np.float32) / 255, filtered.astype(np.float32) / 255, reference, band)

    with_margin = reduction()
    monkeypatch.setattr(pure_colours, "RIDGE_NOISE_MARGIN", 0.0)
    assert with_margin > 0.03
    assert with_margin > reduction() + 0.1


def _cube_curve(levels):
    """G'MIC's ``-pow 3`` on 8-bit levels, clipped: a step at 6 levels."""
    return np.minimum(levels.astype(np.float64) ** 3, 255) / 255


@pytest.mark.parametrize("space", ["srgb", "linear"])
def test_a_nearly_whole_pixel_of_an_ink_that_o_shows_gets_its_pure_colour(backend, monkeypatch, space):
    # Serif text in green ink (0, 0.35, 0.15) on grey-green paper under the cube curve: a
    # pixel 83-99 % covered lies within a fifth of the span of the cube (MIN_REACH), and F
    # shows it as paper. The ink recurs whole in O's strokes, so its extension to the cube
    # lands on a colour O shows (PureColourPrior.inks) and is taken. Measured on the green
    # band, both backends: sRGB 0.856 with the inks, 0.555 without; linear 0.935 and 0.458.
    from aarecovery.lab.realtools import FAMILIES, render_family
    from aarecovery.plan import pure_colours as plan_pure_colours
    scene = np.rint(render_family("serif", 96) * 255).astype(np.uint8)
    original = np.rint(box_downsample(scene.astype(np.float32) / 255, FAMILIES["serif"].k, space) * 255).astype(np.uint8)
    filtered = np.rint(_cube_curve(original) * 255).astype(np.uint8)
    reference = box_downsample(_cube_curve(scene).astype(np.float32), FAMILIES["serif"].k, space)
    green = slice(3 * original.shape[0] // 4 + 1, None)
    o, f = original.astype(np.float32) / 255, filtered.astype(np.float32) / 255
    band = edge_band(o, f, reference)
    band[:green.start] = False

    def reduction():
        recovered = aarecovery.recover(original, filtered, backend=backend)
        return error_reduction(recovered.astype(np.float32) / 255, f, reference, band)

    with_inks = reduction()
    inks = plan_pure_colours.inks_of(o[green])
    assert np.abs(inks - [0, 89 / 255, 38 / 255]).max(axis=1).min() < 0.5 / 255
    monkeypatch.setattr(plan_pure_colours, "inks_of", lambda original: np.zeros((0, 3), np.float32))
    without = reduction()
    assert with_inks > without + 0.1


def test_a_channel_without_pixels_takes_the_curve_of_a_channel_that_agrees_with_it():
    from aarecovery.plan.pure_colours import shared_channel_table
    levels = np.arange(256, dtype=np.float32)
    curve = np.minimum(levels ** 3, 255) / 255
    filled = np.zeros((256, 3), bool)
    filled[:, 0] = True            # red reaches 0 (a green ink's red channel)
    filled[35:, 1] = True          # green and blue only from 35 up (the darkest grey stroke)
    filled[35:, 2] = True
    fitted = np.stack([curve, np.where(levels < 35, 1.0, curve), curve * 0.9], -1).astype(np.float32)
    table, held = shared_channel_table(fitted, filled)
    np.testing.assert_array_equal(table[:, 0], fitted[:, 0])
    np.testing.assert_allclose(table[:, 1], curve, atol=1e-6)  # agrees with red from 35 up: red's steps below
    assert held[:, 1].all()
    # Blue is another curve (0.9 of it): it keeps its own bins and its flat end.
    np.testing.assert_array_equal(table[:, 2], fitted[:, 2])
    np.testing.assert_array_equal(held[:, 2], filled[:, 2])


@pytest.mark.parametrize("space", ["srgb", "linear"])
def test_thin_strokes_of_an_ink_no_channel_shows_whole_take_the_curve_another_channel_shows(backend, monkeypatch,
                                                                                            space):
    # Serif's dark grey text on near-white paper under the cube curve (a step at 6 levels):
    # its thinnest strokes are no darker than 34 in any channel, so O fills the green and blue
    # columns of the table from there up only, all 255, and the pure colour near black took 255
    # there. The green ink's red channel shows the same curve down to 0, and the columns agree
    # where both hold pixels. Measured on the edge band of the page's top quarter, both
    # backends: sRGB 0.976 with the shared columns, 0.324 without; linear 0.812 and 0.307.
    from aarecovery.lab.realtools import FAMILIES, render_family
    from aarecovery.plan import pure_colours as plan_pure_colours
    scene = np.rint(render_family("serif", 96) * 255).astype(np.uint8)
    original = np.rint(box_downsample(scene.astype(np.float32) / 255, FAMILIES["serif"].k, space) * 255).astype(np.uint8)
    filtered = np.rint(_cube_curve(original) * 255).astype(np.uint8)
    reference = box_downsample(_cube_curve(scene).astype(np.float32), FAMILIES["serif"].k, space)
    o, f = original.astype(np.float32) / 255, filtered.astype(np.float32) / 255
    band = edge_band(o, f, reference)
    band[original.shape[0] // 4:] = False

    def reduction():
        recovered = aarecovery.recover(original, filtered, backend=backend)
        return error_reduction(recovered.astype(np.float32) / 255, f, reference, band)

    shared = reduction()
    monkeypatch.setattr(plan_pure_colours, "SHARED_CHANNEL_AGREEMENT", -1.0)
    alone = reduction()
    assert shared > alone + 0.3


def test_near_whole_pixels_of_black_ink_that_o_never_shows_whole_get_black(backend, monkeypatch):
    # The manga page saved at q 95 and thresholded: the JPEG leaves no exact black, so no ink
    # is seen, and a pixel nearly covered by the dark ink lies within MIN_REACH of the cube's
    # corner: it kept F's colour until black became an ink of every page (CORNER_INKS).
    # Measured (NumPy), with the dark ink left out of the palette (the next test): 0.840 of
    # the error with the corners, 0.684 without.
    from test_jpeg_evidence import _encoded, _jpeg_round_trip

    from aarecovery.filters import apply
    from aarecovery.lab.realtools import render_family
    from aarecovery.plan import pure_colours as plan_pure_colours
    case = make_case(render_family("manga", 96), "threshold", 8, "linear")
    original = _encoded(_jpeg_round_trip(np.rint(np.clip(case.original, 0, 1) * 255).astype(np.uint8), 95))
    filtered = np.clip(apply("threshold", original), 0, 1).astype(np.float32)

    def reduction():
        return error_reduction(aarecovery.recover(original, filtered, backend=backend), filtered, case.reference, None)

    monkeypatch.setattr(plan_pure_colours, "_DARK_INK_COUNT", 10 ** 9)
    with_corners = reduction()
    monkeypatch.setattr(plan_pure_colours, "CORNER_INKS", ())
    assert with_corners > reduction() + 0.1


def test_a_dark_ink_that_leaves_no_flat_pixel_stops_the_extension_short_of_black(backend, monkeypatch):
    # The manga page's ink is (10, 10, 13); saved at q 95 it leaves no flat pixel, and its
    # near-whole pixels were extended to black (CORNER_INKS), which the built-in gamma
    # (x ** 0.5, steep at black) maps 50 levels from the ink's colour. The median of O's
    # pixels within 24 levels of black is a palette colour (DARK_INK_REACH) and stops the
    # extension there. Measured (NumPy): sRGB page 0.492 of the error against 0.325 without.
    from test_jpeg_evidence import _encoded, _jpeg_round_trip

    from aarecovery.filters import apply
    from aarecovery.lab.realtools import render_family
    from aarecovery.plan import pure_colours as plan_pure_colours
    case = make_case(render_family("manga", 96), "gamma", 8, "srgb")
    original = _encoded(_jpeg_round_trip(np.rint(np.clip(case.original, 0, 1) * 255).astype(np.uint8), 95))
    filtered = np.clip(apply("gamma", original), 0, 1).astype(np.float32)
    ink = plan_pure_colours.palette_of(original)[-1] * 255
    assert np.abs(ink - [10, 10, 13]).max() <= 3, ink

    def reduction():
        return error_reduction(aarecovery.recover(original, filtered, backend=backend), filtered, case.reference, None)

    with_dark_ink = reduction()
    monkeypatch.setattr(plan_pure_colours, "_DARK_INK_COUNT", 10 ** 9)
    assert with_dark_ink > reduction() + 0.1


def screentone_page(size=48, scale=8):
    """Black shapes and a patch of screentone on white, antialiased in linear light at 8 x 8
    samples a pixel: dots of 0.9 px centred on every other pixel, thresholded, so that the
    reference is the page itself. Every pixel of the dot grid is symmetric about its centre."""
    n = size * scale
    y, x = (np.mgrid[0:n, 0:n] + 0.5) / scale
    ink = (np.abs(x - 12) < 6) & (np.abs(y - 12) < 6)
    ink |= (x - 34) ** 2 + (y - 12) ** 2 < 36
    ink |= (np.abs(x - 36) < 7) & (np.abs(y - 36) < 5) & ~((np.abs(x - 36) < 5) & (np.abs(y - 36) < 3))
    patch = (y > 30) & (y < 40) & (x > 4) & (x < 24)
    centre_y, centre_x = np.floor(y / 2) * 2 + 0.5, np.floor(x / 2) * 2 + 0.5
    ink |= patch & ((x - centre_x) ** 2 + (y - centre_y) ** 2 < 0.45 ** 2)
    linear = (~ink).astype(np.float32).reshape(size, scale, size, scale).mean(axis=(1, 3))
    original = np.repeat(linear_to_srgb(linear)[..., None], 3, -1).astype(np.float32)
    return original, (original >= 0.5).astype(np.float32)


def test_ridge_magnitude_is_a_centred_lines_contrast_and_none_on_a_ramp():
    def around(image):
        return neighbours(planes(rgba(image.astype(np.float32))))

    line = np.zeros((3, 3, 3)); line[:, 1] = 1             # a unit line through the centre
    step = np.zeros((3, 3, 3)); step[:, 2] = 1             # a unit step beside it
    ramp = np.broadcast_to(np.arange(3.0)[None, :, None], (3, 3, 3))
    assert sobel_magnitude(around(line))[1, 1] == 0       # symmetric: no gradient
    assert ridge_magnitude(around(line))[1, 1] == pytest.approx(np.sqrt(3))  # 1 in each channel
    assert ridge_magnitude(around(step))[1, 1] == pytest.approx(np.sqrt(3) / 2)
    assert ridge_magnitude(around(ramp))[1, 1] == 0
    assert ridge_magnitude(around(np.full((3, 3, 3), 0.3)))[1, 1] == 0


def test_a_screentone_grid_erased_by_a_threshold_is_restored(backend):
    # A dot centred on a pixel has no Sobel gradient, nor has any pixel of a regular grid of
    # them: with the Sobel edge strength alone the safe default kept F there (0.33 of the
    # page's edge error, as the paper's passes); the ridge magnitude restores it. Measured,
    # both backends: 1.000.
    original, filtered = screentone_page()
    plan = analyse(rgba(original), rgba(filtered))
    assert plan.decision == aarecovery.Decision.POINTWISE_HARD_EDGED and plan.pure_colours is not None, plan.reason
    band = edge_band(original, filtered, original)
    safe = aarecovery.recover(original, filtered, backend=backend)
    paper = aarecovery.recover(original, filtered, backend=backend, mode="paper")
    assert error_reduction(safe, filtered, original, band) > 0.95
    assert error_reduction(paper, filtered, original, band) < 0.5
