"""The safe default: its per-image decisions, paper mode unchanged, tiling unchanged."""

import numpy as np
import pytest

import aarecovery
from aarecovery import Decision, filters
from aarecovery.lab import scenes as _scenes
from aarecovery.lab.groundtruth import make_case
from aarecovery.spec import fit_blend_model, to_working_space
from aarecovery.plan import analyse
from aarecovery.plan.blend_space import choose_blend_space
from aarecovery.plan.lowpass import fit_lowpass
from aarecovery.plan.pointwise import fit_pointwise


def rgba(image):
    return np.concatenate([image, np.ones(image.shape[:2] + (1,), np.float32)], -1)


@pytest.fixture(scope="module")
def shapes():
    return _scenes.render("shapes", 48, 4)


@pytest.mark.parametrize("space", ["linear", "srgb"])
def test_blend_space_is_the_space_of_the_antialiasing(shapes, space):
    case = make_case(shapes, "threshold", 4, space)
    chosen, residuals = choose_blend_space(rgba(case.original))
    assert chosen == space, residuals


def _map(space, quality=None, family="maps"):
    """The real-tools suite's map, antialiased in `space`, 8-bit (through a JPEG at `quality`)."""
    import io

    from PIL import Image

    from aarecovery.lab.realtools import FAMILIES, render_family
    from aarecovery.plan.resample import box_downsample
    levels = np.rint(box_downsample(render_family(family, 96), FAMILIES[family].k, space) * 255).astype(np.uint8)
    if quality is not None:
        buffer = io.BytesIO()
        Image.fromarray(levels).save(buffer, format="JPEG", quality=quality)
        levels = np.asarray(Image.open(io.BytesIO(buffer.getvalue())).convert("RGB"))
    return levels.astype(np.float32) / 255


@pytest.mark.parametrize("space", ["linear", "srgb"])
def test_a_maps_edges_vote_for_its_space_where_three_colours_meet(space):
    # A map's contour lines over its tints meet in pixels of three colours, which fit no
    # colour line in either space: the mean residuals tie (the sRGB map 0.024 against 0.025)
    # and told linear light; its two-colour edges fit only their own space.
    from aarecovery.plan.blend_space import means_tell_srgb
    chosen, residuals = choose_blend_space(rgba(_map(space)))
    assert chosen == space, residuals
    assert not means_tell_srgb(residuals)


@pytest.mark.parametrize("space", ["linear", "srgb"])
def test_text_and_chrome_over_a_photo_tell_its_space(space):
    # Text and chrome over a photo (the poster over the coffee photo, the screenshot's window
    # over the grey camera photo): the photo's texture ties the whole window's means and does
    # not vote, so the sRGB scenes read as linear light; their drawn pixels' edges tell
    # (plan.blend_space).
    from aarecovery.plan.mixed_content import drawn_at
    for family in ("poster", "screenshot"):
        original = _map(space, family=family)
        assert choose_blend_space(rgba(original))[0] == "linear", family
        chosen, residuals = choose_blend_space(rgba(original), drawn=lambda rows, cols: drawn_at(original, rows, cols))
        assert chosen == space, (family, residuals)
        assert analyse(rgba(original), rgba(original ** 2)).blend_space == space, family


def test_a_jpegs_edges_do_not_vote():
    # Compression noise fits sRGB values better whatever the space (plan.blend_space): the
    # star burst antialiased in linear light, saved at q 75, would vote for sRGB values.
    original = _map("linear", quality=75, family="starburst")
    assert choose_blend_space(rgba(original))[0] == "srgb"
    assert choose_blend_space(rgba(original), lossless=False)[0] == "linear"
    # Its repair under a curve blends in sRGB values for another reason: the JPEG averaged
    # its encoded values across the edges (compression.COMPRESSED_HARD_EDGED_BLEND_SPACE).
    plan = analyse(rgba(original), rgba(original ** 2))
    assert plan.decision == Decision.POINTWISE_HARD_EDGED_COMPRESSED and plan.blend_space == "srgb", plan.reason


def test_f_affine_in_linear_light_is_kept_where_the_edges_voted_for_srgb():
    # The sRGB map's grey by luminance in linear light (G'MIC's -luminance) is 53 dB from
    # the reference: where the means tie, an affine map in either space is F already right.
    from aarecovery.colour import LUMA, linear_to_srgb, srgb_to_linear
    original = _map("srgb")
    grey = linear_to_srgb(srgb_to_linear(original) @ np.array(LUMA, np.float32))
    filtered = np.repeat(np.rint(grey * 255)[..., None] / 255, 3, axis=-1).astype(np.float32)
    plan = analyse(rgba(original), rgba(filtered))
    assert plan.blend_space == "srgb"
    assert plan.decision == Decision.AFFINE_KEPT and "in linear values" in plan.reason


def test_blur_is_detected_and_left_alone(shapes):
    case = make_case(shapes, "blur", 4, "srgb")
    assert fit_lowpass(case.original, case.filtered)[0]
    plan = analyse(rgba(case.original), rgba(case.filtered))
    assert plan.strength == 0
    result = aarecovery.recover(case.original, case.filtered, backend="numpy")
    np.testing.assert_array_equal(result, case.filtered)
    assert not fit_lowpass(case.original, filters.unsharp_mask(case.original))[0]


def test_pointwise_filters_are_recognised(shapes):
    case = make_case(shapes, "gradientmap", 4, "linear")
    edges = np.ones(case.original.shape[:2], bool)
    assert fit_pointwise(case.original, case.filtered, edges).consistency > 0.99
    unsharp = make_case(shapes, "unsharp", 4, "linear")
    assert fit_pointwise(unsharp.original, unsharp.filtered, edges).consistency < 0.9


def test_paper_mode_is_the_reference_passes_exactly(shapes):
    case = make_case(shapes, "posterize", 4, "linear")
    o, f = rgba(case.original), rgba(case.filtered)
    model = fit_blend_model(to_working_space(o), to_working_space(f), 0.1, 0.01)
    same = fit_blend_model(to_working_space(o), to_working_space(f), 0.1, 0.01, strength=1.0)
    np.testing.assert_array_equal(model.beta, same.beta)
    paper = aarecovery.recover(case.original, case.filtered, backend="numpy", mode="paper")
    explicit = aarecovery.recover(case.original, case.filtered, backend="numpy", mode="paper", blend_space="linear")
    np.testing.assert_array_equal(paper, explicit)


# Small tiles on purpose: they put tile borders everywhere in a small image.
@pytest.mark.filterwarnings("ignore::aarecovery.errors.TileSizeWarning")
def test_safe_mode_tiled_equals_untiled():
    scene = _scenes.render("astronaut", 64, 4)
    case = make_case(scene, "gamma", 4, "linear")
    whole = aarecovery.recover(case.original, case.filtered, backend="numpy")
    tiled = aarecovery.recover(case.original, case.filtered, backend="numpy", tile_size=24)
    np.testing.assert_array_equal(whole, tiled)


def test_engine_compute_takes_the_mode(shapes):
    case = make_case(shapes, "threshold", 4, "srgb")
    engine = aarecovery.Engine("numpy")
    engine.set_images(case.original, case.filtered)
    safe = engine.recover()
    assert engine.last_plan is not None and engine.last_plan.blend_space == "srgb"
    np.testing.assert_array_equal(safe, aarecovery.recover(case.original, case.filtered, backend="numpy"))
    paper = engine.recover(mode="paper")
    assert engine.last_plan.mode == "paper" and engine.last_plan.strength == 1
    np.testing.assert_array_equal(paper, aarecovery.recover(case.original, case.filtered, backend="numpy",
                                                            mode="paper"))
    with pytest.raises(aarecovery.InputError, match="'fast'"):
        engine.compute(mode="fast")


def test_grain_tells_rendered_content_from_photographs():
    from aarecovery.plan.texture import GRAIN_SHARE, grain
    drawing = make_case(_scenes.render("shapes", 96, 4), "gamma", 4, "linear").original
    assert grain(drawing) == 0.0
    photo = make_case(_scenes.render("astronaut", 96, 4), "gamma", 4, "linear").original
    grey = np.repeat(photo.mean(axis=-1, keepdims=True), 3, axis=-1)
    assert grain(photo) > GRAIN_SHARE and grain(grey) > GRAIN_SHARE
    # A drawing on a soft gradient (about a level per pixel) is still a drawing, in colour
    # and in grey (the 3 x 3 range alone called it a photo: 0.73 and 0.23 of quiet pixels).
    from scenes import disc_and_bar
    gradient = (np.rint(disc_and_bar(80, 112)[..., :3] * 255) / 255).astype(np.float32)
    grey = np.repeat(np.rint(gradient @ np.float32([0.2126, 0.7152, 0.0722]) * 255)[..., None] / 255, 3, axis=-1)
    assert grain(gradient) < GRAIN_SHARE and grain(grey.astype(np.float32)) < GRAIN_SHARE


def test_a_grey_photograph_under_an_exposure_boost_is_not_destroyed():
    """Grey photos have no colour lines to fail, so the colour test called them hard-edged
    and the pure colours of thin features turned them into blotches (11-16 dB worse than F)."""
    from aarecovery.lab.metrics import edge_band, psnr
    scene = _scenes.render("astronaut", 96, 4)
    scene = np.repeat(scene.mean(axis=-1, keepdims=True), 3, axis=-1)
    case = make_case(scene, "gamma", 4, "linear", gamma=4.0)
    plan = analyse(rgba(case.original), rgba(case.filtered))
    # Read as a photo: pure colours, if any, only where the local plan reads drawn regions.
    assert plan.local is not None and (plan.pure_colours is None or plan.pure_colours.drawn_only), plan.reason
    recovered = aarecovery.recover(case.original, case.filtered, backend="numpy")
    band = edge_band(case.original, case.filtered, case.reference)
    assert psnr(recovered, case.reference, band) >= psnr(case.filtered, case.reference, band) - 0.1


def test_an_affine_filter_in_the_blend_space_keeps_f():
    """A channel mixer in linear light commutes with antialiasing in linear light: F is the
    reference already, and the safe default leaves it alone."""
    from aarecovery.colour import linear_to_srgb, srgb_to_linear
    from aarecovery.plan.linearity import affine_share
    from aarecovery.spec.sobel import gradient_magnitude
    original = make_case(_scenes.render("shapes", 64, 4), "gamma", 4, "linear").original
    mixed = srgb_to_linear(original) @ np.array([[0.5, 0.2, 0.1], [0.3, 0.6, 0.2], [0.2, 0.2, 0.7]], np.float32)
    filtered = linear_to_srgb(np.clip(mixed, 0, 1))
    edges = gradient_magnitude(original) >= 0.02
    assert affine_share(original, filtered, edges, "linear") == 1.0
    assert affine_share(original, (original > 0.5).astype(np.float32), edges, "linear") < 0.5
    plan = analyse(rgba(original), rgba(filtered))
    assert plan.strength == 0 and plan.decision == Decision.AFFINE_KEPT
    np.testing.assert_array_equal(aarecovery.recover(original, filtered, backend="numpy"), filtered)


@pytest.mark.parametrize("scene", ["shapes", "lines"])
def test_repair_to_error_ratio_weighs_the_repair_against_the_models_error(scene):
    """Under the identity filter every repair is the model's own error (ratio 1); under a
    threshold the repairs dwarf it."""
    from aarecovery.plan.model_error import MIN_REPAIR_TO_ERROR, repair_to_error_ratio
    from aarecovery.params import SIGMA_D, SIGMA_E
    case = make_case(_scenes.render(scene, 64, 4), "threshold", 4, "linear")
    sigmas = dict(linear_input=False, blend_space="linear", sigma_d=SIGMA_D.default, sigma_e=SIGMA_E.default)
    identity = repair_to_error_ratio(rgba(case.original), rgba(case.original), **sigmas)
    thresholded = repair_to_error_ratio(rgba(case.original), rgba(case.filtered), **sigmas)
    assert identity == pytest.approx(1.0, abs=1e-3)
    assert thresholded > 50 * MIN_REPAIR_TO_ERROR


def test_a_grey_drawing_stretched_in_its_encoded_values_is_kept():
    # A grey image cannot tell its antialiasing space, so the plan blends in linear light; a
    # levels stretch of its encoded values (Pillow's autocontrast) is affine there only in
    # sRGB values, and its edges are already right if it was antialiased in sRGB values.
    size, k = 64, 8
    y, x = np.mgrid[0:size * k, 0:size * k] / k
    scene = np.full((size * k, size * k), 0.85, np.float32)
    scene[np.hypot(y - 30, x - 28) < 17] = 0.1
    scene[(np.abs(y - x * 0.6 - 12) < 0.6) | (np.abs(x - 50) < 0.4)] = 0.05
    original = scene.reshape(size, k, size, k).mean((1, 3))
    original = np.repeat(np.round(original * 255)[..., None], 3, -1).astype(np.uint8)
    low, high = int(original.min()), int(original.max())
    filtered = np.round((original.astype(np.float32) - low) * 255 / (high - low)).astype(np.uint8)
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(original, filtered)
        plan = engine.plan()
        assert plan.decision == Decision.AFFINE_KEPT, plan.reason
        np.testing.assert_array_equal(aarecovery.recover(original, filtered, engine=engine), filtered)


def family_as_jpeg(name, width, quality, space="srgb"):
    """A real-tools drawing family antialiased in `space` ("srgb" values or "linear" light),
    saved as a JPEG by Pillow.

    Returns
    -------
    scene, clean, original : ndarray of uint8
        The 8-bit scene at its supersampling factor, O as a PNG and O as the decoded JPEG.
    """
    import io

    from PIL import Image

    from aarecovery.lab.realtools import FAMILIES, render_family
    from aarecovery.plan.resample import box_downsample
    scene = np.rint(render_family(name, width) * 255).astype(np.uint8)
    clean = np.rint(box_downsample(scene.astype(np.float32) / 255, FAMILIES[name].k, space) * 255).astype(np.uint8)
    buffer = io.BytesIO()
    Image.fromarray(clean).save(buffer, format="JPEG", quality=quality)
    with Image.open(io.BytesIO(buffer.getvalue())) as decoded:
        return scene, clean, np.asarray(decoded.convert("RGB"))


def test_a_faintly_tinted_drawing_saved_as_jpeg_and_stretched_in_its_encoded_values_is_kept():
    # The manga page's cream paper differs by 3 levels between channels; saved as a JPEG at
    # q 98 its chroma's rounding adds 2 more. The stretch (Pillow's autocontrast) is still
    # affine in sRGB values, and repairing it at the calibrated strength lost 4.9 dB against F
    # on the tuning half.
    from PIL import Image, ImageOps

    from aarecovery.lab.realtools import FAMILIES
    from aarecovery.plan.resample import box_downsample
    scene, _, original = family_as_jpeg("manga", 48, 98)
    assert np.ptp(original.astype(int), axis=-1).max() > 4, "the JPEG no longer adds chroma noise"
    filtered = np.asarray(ImageOps.autocontrast(Image.fromarray(original), cutoff=2))
    reference = box_downsample(np.asarray(ImageOps.autocontrast(Image.fromarray(scene), cutoff=2), np.float32) / 255,
                               FAMILIES["manga"].k, "srgb")
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(original, filtered)
        assert engine.plan().decision == Decision.AFFINE_KEPT, engine.plan().reason
        recovered = aarecovery.recover(original, filtered, engine=engine)
    error = {name: np.mean(np.square(image.astype(np.float32) / 255 - reference))
             for name, image in (("F", filtered), ("R", recovered))}
    assert error["R"] <= error["F"], error
