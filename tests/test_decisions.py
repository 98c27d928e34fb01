"""Every exit of the safe default has a name: one pair per decision, asserting the name the
plan carries (never the wording of its reason)."""

import numpy as np
import pytest

import aarecovery
from aarecovery import Decision
from aarecovery.colour import LUMA_WEIGHTS, linear_to_srgb, srgb_to_linear
from aarecovery.lab import scenes as _scenes
from aarecovery.lab.groundtruth import make_case
from aarecovery.lab.realtools import render_family
from test_colour_map import PALETTE, _photo_like, _quantise


def _box(image, factor):
    height, width = image.shape[0] // factor, image.shape[1] // factor
    return image[:height * factor, :width * factor].reshape(height, factor, width, factor, 3).mean((1, 3))


def _drawing(name, width=64):
    scene = render_family(name, width)
    return _box(scene, scene.shape[0] // width).astype(np.float32)


def _saturate(image, factor):
    """Push each colour away from its brightest channel: a saturation change (not affine)."""
    brightest = image.max(axis=-1, keepdims=True)
    return np.clip(brightest + (image - brightest) * factor, 0, 1).astype(np.float32)


def _case(scene, filter_name):
    case = make_case(_scenes.render(scene, 64, 4), filter_name, 4, "linear")
    return case.original, case.filtered


def _channel_mixer():
    original = _case("shapes", "gamma")[0]
    mixed = srgb_to_linear(original) @ np.array([[0.5, 0.2, 0.1], [0.3, 0.6, 0.2], [0.2, 0.2, 0.7]], np.float32)
    return original, linear_to_srgb(np.clip(mixed, 0, 1))


def _indexed_map():
    """A colour map drawing converted to indexed colour: its own 6 colours, no dithering."""
    from PIL import Image

    original = _drawing("maps", 128)
    pixels = Image.fromarray(np.rint(original * 255).astype(np.uint8))
    indexed = pixels.quantize(colors=6, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
    return original, np.asarray(indexed.convert("RGB"), np.float32) / 255


def _jpeg_page_thresholded(quality=85):
    """A page of serif text saved as a JPEG and decoded, then thresholded: a scan's workflow."""
    import io

    from PIL import Image

    page = np.rint(_drawing("serif", 96) * 255).astype(np.uint8)
    buffer = io.BytesIO()
    Image.fromarray(page).save(buffer, format="JPEG", quality=quality)
    buffer.seek(0)
    with Image.open(buffer) as decoded:
        original = np.asarray(decoded.convert("RGB")).astype(np.float32) / 255
    luma = original @ LUMA_WEIGHTS
    filtered = np.repeat((luma > 0.5)[..., None], 3, axis=-1).astype(np.float32)
    return original, filtered


def _grained_page_levels():
    """A page of text on coarse-grained tinted paper under narrow levels."""
    page = _box(render_family("notice", 64), 8)
    original = (np.rint(page * 255) / 255).astype(np.float32)
    return original, np.clip((original - 0.3) / 0.4, 0, 1).astype(np.float32)


def _grey_photo(filter_name):
    scene = _scenes.render("astronaut", 128, 4)
    case = make_case(np.repeat(scene.mean(axis=-1, keepdims=True), 3, axis=-1), filter_name, 4, "linear")
    return case.original, case.filtered


def _quantised_photo():
    original = _photo_like(seed=2)
    return original, _quantise(original, PALETTE)


PAIRS = {
    Decision.LOWPASS_KEPT: lambda: _case("shapes", "blur"),
    Decision.AFFINE_KEPT: _channel_mixer,
    Decision.POINTWISE_HARD_EDGED_COMPRESSED: _jpeg_page_thresholded,
    Decision.POINTWISE_HARD_EDGED_GRAINED: _grained_page_levels,
    Decision.POINTWISE_HARD_EDGED: lambda: _case("shapes", "posterize"),
    Decision.POINTWISE_CALIBRATED: lambda: _case("astronaut", "posterize"),
    Decision.NEIGHBOURHOOD_TEXTURED_KEPT: lambda: _case("astronaut", "bilateral"),
    Decision.NEIGHBOURHOOD_TEXTURED: lambda: _grey_photo("unsharp"),
    Decision.NEIGHBOURHOOD_MIXED: lambda: (_drawing("poster"), aarecovery.filters.apply("unsharp", _drawing("poster"))),
    Decision.COLOUR_MAP_KEPT: lambda: (_drawing("maps"), _saturate(_drawing("maps"), 1.5)),
    Decision.COLOUR_MAP_CALIBRATED: _quantised_photo,
    Decision.COLOUR_MAP_HARD_EDGED: _indexed_map,
    Decision.NEIGHBOURHOOD_HARD_EDGED_KEPT: lambda: (_drawing("pies"), _saturate(_drawing("pies"), 1.1)),
    Decision.NEIGHBOURHOOD_HARD_EDGED: lambda: _case("shapes", "bilateral"),
}
_KEEPS_F = {Decision.LOWPASS_KEPT, Decision.AFFINE_KEPT, Decision.NEIGHBOURHOOD_TEXTURED_KEPT,
            Decision.COLOUR_MAP_KEPT, Decision.NEIGHBOURHOOD_HARD_EDGED_KEPT}


def test_every_decision_of_the_safe_default_has_a_pair_here():
    assert set(PAIRS) | {Decision.PAPER} == set(Decision)


@pytest.mark.parametrize("decision", list(PAIRS), ids=str)
def test_the_plan_names_the_decision_it_took(decision):
    original, filtered = PAIRS[decision]()
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(original, filtered)
        plan = engine.plan()
        paper = engine.plan(mode="paper")
    assert plan.decision == decision, plan.reason
    assert plan.keeps_filtered == (decision in _KEEPS_F)
    # Where F is kept, the plan says what forcing a repair would do (the summary's hint).
    assert (plan.forcing is not None) == plan.keeps_filtered
    assert paper.decision == Decision.PAPER
