"""Pure colours of thin features over a photo: gated by the local plan's weight, so that they
act on the text and drawings and not on the photo, and fade in with the weight."""

import dataclasses

import numpy as np
import pytest

import aarecovery
from aarecovery import Decision
from aarecovery.lab import scenes as _scenes
from aarecovery.lab.groundtruth import make_case
from aarecovery.plan.mixed_content import DRAWN_REGION_SHARE, drawn_only
from aarecovery.spec.sobel import gradient_magnitude
from aarecovery.spec import recover_working, to_working_space
from aarecovery.spec.local_plan import LocalStrength, flat_share, hard_edged_weight, ink_weight
from aarecovery.spec.pure_colours import MIN_CONTRAST
from test_local_plan import banner_over_photo  # noqa: F401 (a fixture)
from test_local_plan import _BANNER

# The banner covers O's top rows; the photo lies below them (a margin for the local plan's square).
_BANNER_ROWS = _BANNER + 20


def _plan_and_work(case):
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(case.original, case.filtered)
        plan = engine.plan()
        forced = engine.plan(strength=0.5)
    rgba = lambda image: np.concatenate([image, np.ones(image.shape[:2] + (1,), np.float32)], -1)
    space = dict(linear_input=False, blend_space=plan.blend_space)
    return plan, forced, to_working_space(rgba(case.original), **space), to_working_space(rgba(case.filtered), **space)


def test_over_a_photo_the_pure_colours_are_gated_by_the_local_plan(banner_over_photo):
    plan, forced, _, _ = _plan_and_work(banner_over_photo)
    assert plan.decision == Decision.POINTWISE_CALIBRATED and plan.local is not None
    assert plan.pure_colours is not None and plan.pure_colours.drawn_only
    # A strength the user gives drops the local plan, and the gated pure colours with it.
    assert forced.local is None and forced.pure_colours is None


def test_a_photo_with_no_drawn_region_gets_no_gated_pure_colours(banner_over_photo):
    # The same photo without the banner: calibrated and local, but a prior gated shut
    # everywhere would only cost its passes over every active block.
    photo = make_case(_scenes.render("astronaut", 128, 4), "posterize", 4, "linear")
    plan, _, _, _ = _plan_and_work(photo)
    assert plan.decision == Decision.POINTWISE_CALIBRATED and plan.local is not None
    assert plan.pure_colours is None
    # The rule itself, on the banner's window: its drawn regions pass, the photo's part not.
    banner_plan, _, _, _ = _plan_and_work(banner_over_photo)
    prior = dataclasses.replace(banner_plan.pure_colours, drawn_only=False)
    encoded = banner_over_photo.original
    edges = gradient_magnitude(encoded) > 0.02
    gated = drawn_only(prior, encoded, edges)
    assert gated is not None and gated.drawn_only
    below = encoded[_BANNER_ROWS:]
    below_edges = gradient_magnitude(below) > 0.02
    assert np.mean(LocalStrength.region_weight(below)[below_edges] > 0) < DRAWN_REGION_SHARE
    assert drawn_only(prior, below, below_edges) is None
    assert drawn_only(None, encoded, edges) is None


def test_the_gate_is_the_regions_weight_without_the_drawn_ink(banner_over_photo):
    encoded = banner_over_photo.original
    gate = LocalStrength.region_weight(encoded)
    np.testing.assert_array_equal(gate, hard_edged_weight(flat_share(encoded)))
    # The factor also counts drawn ink, which the gate leaves out (a grey photo's levels
    # recur as exactly as ink: see plan/analysis.py).
    local = LocalStrength(0.25)
    weight = np.maximum(gate, ink_weight(encoded))
    np.testing.assert_allclose(local.factor(encoded), 0.25 + 0.75 * weight, atol=1e-6)
    assert (weight > gate).any() and gate.min() == 0 and gate.max() == 1


def test_the_gate_fades_the_extension_in_and_leaves_the_photo_the_papers(banner_over_photo):
    plan, _, work_o, work_f = _plan_and_work(banner_over_photo)
    prior, textured = plan.pure_colours, plan.local.textured
    shape = work_o.shape[:2]

    def run(gate, gated=True, prior=prior):
        factor = np.full(shape, textured + (1 - textured) * gate, np.float32)
        return recover_working(work_o, work_f, plan.sigma_d, plan.sigma_e, plan.iterations, plan.strength, prior,
                               plan.blend_space, factor, gate=np.full(shape, gate, np.float32) if gated else None)

    # Gate 0 (a photo): no extension, and the paper's model and result at that strength.
    photo, model = run(0.0)
    assert not model.pure_a.any() and not model.pure_b.any()
    factor = np.full(shape, textured, np.float32)
    paper, paper_model = recover_working(work_o, work_f, plan.sigma_d, plan.sigma_e, plan.iterations, plan.strength,
                                         None, plan.blend_space, factor)
    np.testing.assert_allclose(model.beta, paper_model.beta, atol=1e-6)
    np.testing.assert_allclose(photo, paper, atol=1e-6)
    # Gate 1 (a drawing): the prior as on hard-edged content, but on this lossless O only
    # against a flat colour or towards a pure colour O shows (PureColourPrior.backed_or_seen).
    assert prior.backed_or_seen
    ungated, ungated_model = run(1.0, gated=False)
    full, full_model = run(1.0)
    assert full_model.pure_a.sum() + full_model.pure_b.sum() > 20
    for gated_side, ungated_side in ((full_model.pure_a, ungated_model.pure_a), (full_model.pure_b, ungated_model.pure_b)):
        assert not (gated_side & ~ungated_side).any()
    assert full_model.pure_a.sum() + full_model.pure_b.sum() < ungated_model.pure_a.sum() + ungated_model.pure_b.sum()
    # Without that rule (a noise contrast at the least contrast tested anyway: the same
    # extremes tested), exactly the prior as on hard-edged content.
    unbacked = dataclasses.replace(prior, noise_contrast=MIN_CONTRAST)
    assert not unbacked.backed_or_seen and unbacked.min_contrast == prior.min_contrast
    unbacked_full, unbacked_model = run(1.0, prior=unbacked)
    np.testing.assert_array_equal(unbacked_model.pure_a, ungated_model.pure_a)
    np.testing.assert_allclose(unbacked_full, ungated, atol=1e-5)
    # Between: the same extremes extended, the pure colours that share of the way.
    _, faint = run(1e-6)
    _, half = run(0.5)
    np.testing.assert_array_equal(half.pure_a, full_model.pure_a)
    np.testing.assert_array_equal(faint.pure_b, full_model.pure_b)
    np.testing.assert_allclose(half.colour_a, (faint.colour_a + full_model.colour_a) / 2, atol=1e-5)
    # With the local plan's own regions' weight: the photo below the banner is not extended.
    encoded = banner_over_photo.original
    gate = plan.local.region_weight(encoded)
    _, local_model = recover_working(work_o, work_f, plan.sigma_d, plan.sigma_e, plan.iterations, plan.strength,
                                     prior, plan.blend_space, plan.local.factor(encoded), gate=gate)
    extended = local_model.pure_a | local_model.pure_b
    assert extended.any() and (gate[extended] > 0).all() and (gate == 0).any()


def gl_agrees_with_numpy(case, gl_path):
    """R of `case` on the NumPy backend and on GL (`gl_path`), checked equal within 1e-5, and
    GL's plan: (numpy_result, gl_result, plan)."""
    numpy_result = aarecovery.recover(case.original, case.filtered, backend="numpy")
    with aarecovery.Engine("gl", gl_path=gl_path) as engine:
        gl_result = aarecovery.recover(case.original, case.filtered, engine=engine)
        plan = engine.last_plan
    np.testing.assert_allclose(gl_result, numpy_result, atol=1e-5)
    return numpy_result, gl_result, plan


@pytest.mark.filterwarnings("ignore::aarecovery.errors.TileSizeWarning")
def test_gated_pure_colours_agree_on_both_backends_and_tiled(banner_over_photo, gl_path):
    case = banner_over_photo
    numpy_result, gl_result, plan = gl_agrees_with_numpy(case, gl_path)
    assert plan.pure_colours.drawn_only
    for tile in (24, 40):
        tiled = aarecovery.recover(case.original, case.filtered, backend="gl", gl_path=gl_path, tile_size=tile)
        np.testing.assert_array_equal(tiled, gl_result)
    # The gate changed the result: without pure colours it differs on the banner's bars.
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(case.original, case.filtered)
        engine.run(dataclasses.replace(engine.plan(), pure_colours=None))
        assert np.abs(engine.result() - numpy_result).max() > 0.05


def test_light_text_over_a_dark_bar_beside_a_grey_photo_extends_to_its_ink(monkeypatch):
    """The sRGB screenshot's title (ink 235, 235, 242 on a 51, 56, 69 bar, never flat) under
    Pillow's YCbCr equalization: the grey photo's flat greys lie 0.028 from the title's colour
    line and, within the ridge test's LINE_TOLERANCE, stopped its extension at grey 197
    (INK_LINE_TOLERANCE says why): 0.37 of the edge error removed then, 0.54 now."""
    from aarecovery.lab.metrics import edge_band, error_reduction
    from aarecovery.spec import pure_colours
    case = _srgb_screenshot_equalized()
    band = edge_band(case.original, case.filtered, case.reference)
    gains = []
    for tolerance in (pure_colours.INK_LINE_TOLERANCE, pure_colours.LINE_TOLERANCE):
        monkeypatch.setattr(pure_colours, "INK_LINE_TOLERANCE", tolerance)
        with aarecovery.Engine("numpy") as engine:
            engine.set_images(case.original, case.filtered)
            plan = engine.plan()
            assert plan.blend_space == "srgb" and plan.pure_colours is not None, plan.reason
            engine.run(plan)
            gains.append(error_reduction(engine.result(), case.filtered, case.reference, band))
    assert gains[0] > 0.5 and gains[1] < 0.45, gains


def test_light_text_over_a_dark_bar_agrees_on_gl(gl_path):
    gl_agrees_with_numpy(_srgb_screenshot_equalized(), gl_path)


def _srgb_screenshot_equalized():
    from aarecovery.lab import realtools
    suite = dataclasses.replace(realtools.REAL_FULL, families=("screenshot",), filters=("pil-ycbcr-equalize",),
                                spaces={"screenshot": ("srgb",)})
    (case,) = realtools.build_cases(suite, "tune", jpeg=False)
    return case
