"""The pure colours' fit covers only the blocks where it can change anything (GL 4.3).

Of O's active blocks, those near a pixel that could be a thin feature's ridge
(``spec.pure_colours.possible_ridges``, a necessary condition of ``extend_extreme``'s ridge
test) or where F varies (``blocks.pure_colour_mask``). The condition must hold wherever the
specification extends an extreme, the GPU's wakes and flags must be the NumPy twin's, and R
the NumPy specification's. The plan lists them where enough of O's edges are flat in F
(``plan.fit_blocks``).
"""

import dataclasses

import numpy as np
import pytest

import aarecovery
from aarecovery.backends.gl.blocks import (BLOCK_SIDE, FIT_PLAIN, FIT_WHOLE, WAKE_FILTERED, WAKE_RIDGE, active_mask,
                                           blocks_near, differing_pixels, pure_colour_mask)
from aarecovery.lab import scenes as _scenes
from aarecovery.lab.groundtruth import make_case
from aarecovery.lab.processes import thin_features_pair
from aarecovery.params import Parameters
from aarecovery.plan import make_plan
from aarecovery.spec import to_working_space
from aarecovery.spec.neighbourhood import NEIGHBOUR_OFFSETS, neighbours, planes
from aarecovery.spec.pure_colours import RIDGE_NOISE_MARGIN, fit_pure_colour_model, possible_ridges
from parity import assert_results_agree


def _thin_pair(height=80, width=96, seed=3):
    return thin_features_pair(width, height, seed)


def _cases():
    """Thin strokes and filled shapes under a threshold, in the layouts the passes read O from."""
    original, filtered = _thin_pair()
    yield "rgb8", original, filtered
    # Odd sides: the blocks' scan of the wakes reads 2 x 2 texels at a time, the last row and
    # column of the image clamped (flag_wakes.comp).
    yield "rgb8-odd", *_thin_pair(height=81, width=97, seed=5)
    yield "rgb-float", (original / 255).astype(np.float32), (filtered / 255).astype(np.float32)
    alpha = np.full(original.shape[:2] + (1,), 255, np.uint8)
    alpha[:, original.shape[1] // 2:] = 160  # half the layer translucent
    yield "rgba8", np.concatenate([original, alpha], -1), np.concatenate([filtered, alpha], -1)
    grey = (original.astype(np.uint32).sum(-1) * 65535 // 765).astype(np.uint16)
    yield "grey16", grey, np.where(grey > 32767, 65535, 0).astype(np.uint16)
    case = make_case(_scenes.render("text", 48, 4), "threshold", 4, "linear")
    yield "text-linear", case.original, case.filtered


CASES = list(_cases())


def _banner_over_photo():
    """Text bars on a flat banner over a photo, posterized: pure colours gated to the banner."""
    scene = _scenes.render("astronaut", 128, 4).copy()
    scene[:21 * 4] = (0.93, 0.9, 0.8)
    for bar in range(3):
        scene[8 + 16 * bar:14 + 16 * bar, 16:-16] = (0.1, 0.1, 0.3)
    case = make_case(scene, "posterize", 4, "linear")
    return "banner-over-photo", case.original, case.filtered


GL_CASES = CASES + [_banner_over_photo()]


def _rgba(image):
    image = image.reshape(image.shape[0], image.shape[1], -1)
    scale = {np.dtype(np.uint8): 255.0, np.dtype(np.uint16): 65535.0}.get(image.dtype, 1.0)
    image = (image / scale).astype(np.float32)
    if image.shape[-1] < 3:
        image = np.concatenate([image[..., :1].repeat(3, -1), image[..., 1:]], -1)
    if image.shape[-1] == 3:
        image = np.concatenate([image, np.ones(image.shape[:2] + (1,), np.float32)], -1)
    return image


def _uploaded(image):
    dtype = image.dtype if image.dtype in (np.uint8, np.uint16) else np.float32
    return np.ascontiguousarray(image.reshape(image.shape[0], image.shape[1], -1), dtype=dtype)


@pytest.mark.parametrize("name, original, filtered", CASES, ids=[name for name, *_ in CASES])
def test_every_extended_extreme_is_a_possible_ridge(name, original, filtered):
    o, f = _rgba(original), _rgba(filtered)
    linear = name.endswith("linear")
    plan = make_plan(o, f, Parameters(), linear=linear)
    assert plan.pure_colours is not None and not plan.pure_colours.drawn_only
    work_o = to_working_space(o, linear_input=linear, blend_space=plan.blend_space)
    work_f = to_working_space(f, linear_input=linear, blend_space=plan.blend_space)
    model = fit_pure_colour_model(work_o, work_f, plan.sigma_d, plan.sigma_e, 1.0, plan.pure_colours,
                                  plan.blend_space, best=plan.best_pair)
    possible = possible_ridges(neighbours(planes(work_o)))
    offsets = np.asarray(NEIGHBOUR_OFFSETS)
    extended = 0
    for pure, index in ((model.pure_a, model.index_a), (model.pure_b, model.index_b)):
        rows, cols = np.nonzero(pure)
        q = offsets[index[rows, cols]]
        assert possible[rows + q[:, 0], cols + q[:, 1]].all()
        extended += len(rows)
    assert extended > 0  # the cases have thin features
    assert possible.mean() < 0.25  # and a straight edge is no possible ridge


def test_possible_ridges_are_peaks_along_a_line_not_steps_or_flats():
    row = np.array([0.2, 0.2, 0.2, 0.8, 0.2, 0.2, 0.5, 0.8, 0.8, 0.8], np.float32)
    image = np.broadcast_to(row[None, :, None], (5, 10, 3))
    work = np.concatenate([image, np.ones((5, 10, 1), np.float32)], -1)
    possible = possible_ridges(neighbours(planes(work)))
    # The one-pixel line at column 3 (inside the border rows) is; the step's middle
    # (column 6, darker on one side, brighter on the other) and the flats are not.
    assert possible[1:-1, 3].all()
    assert not possible[:, [1, 5, 6, 8]].any() and not possible[[0, -1]].any()


def test_noise_below_the_ridges_noise_margin_is_no_possible_ridge():
    rng = np.random.default_rng(7)
    grey = 0.6 + rng.integers(-2, 3, (24, 24, 1)).astype(np.float32) / 255
    work = np.concatenate([grey.repeat(3, -1), np.ones((24, 24, 1), np.float32)], -1)
    colours = neighbours(planes(work))
    assert possible_ridges(colours)[1:-1, 1:-1].mean() > 0.5  # any difference may be a ridge
    # Differences of at most 4 levels in each channel: below a margin for noise of 5 levels.
    assert not possible_ridges(colours, RIDGE_NOISE_MARGIN * 5 / 255).any()


def test_the_plan_lists_the_blocks_where_os_edges_are_flat_in_f():
    original, filtered = thin_features_pair(512, 512, 0)
    assert make_plan(original, filtered, Parameters()).pure_colour_blocks
    # Every block of a page of text that holds O's edges holds F's too: no listing.
    case = make_case(_scenes.render("text", 256, 4), "threshold", 4, "srgb")
    page = np.tile(case.original, (2, 2, 1)), np.tile(case.filtered, (2, 2, 1))
    plan = make_plan(*page, Parameters())
    assert plan.pure_colours is not None and not plan.pure_colour_blocks
    # Nor without pure colours (the paper's model over F's blocks).
    assert not make_plan(original, filtered, Parameters(), mode="paper").pure_colour_blocks


def test_blocks_near_differing_pixels_are_the_active_blocks():
    rng = np.random.default_rng(5)
    for shape in ((1, 1), (17, 33), (40, 16), (64, 64)):
        dots = (rng.random(shape + (3,)) > 0.98).astype(np.uint8) * 255
        np.testing.assert_array_equal(blocks_near(differing_pixels(dots)), active_mask(dots))


def _read(texture, components, dtype):
    width, height = texture.size
    return np.frombuffer(texture.read(), dtype).reshape(height, width, components)


@pytest.mark.gl
@pytest.mark.parametrize("name, original, filtered", GL_CASES, ids=[name for name, *_ in GL_CASES])
def test_gpu_flags_and_result_are_the_specifications(gl_path, name, original, filtered):
    linear = name.endswith("linear")
    plan = make_plan(original, filtered, Parameters(), linear=linear)
    gated = plan.pure_colours.drawn_only
    assert gated == (name == "banner-over-photo")  # a photo's pure colours are gated, and listed
    assert plan.pure_colour_blocks or not gated
    plan = dataclasses.replace(plan, pure_colour_blocks=True)
    with aarecovery.Engine("gl", gl_path=gl_path) as engine:
        recovered = aarecovery.recover(original, filtered, engine=engine, linear=linear, plan=plan)
        assert engine.last_plan.pure_colours is not None
        impl = engine._impl
        with engine.context:
            assert impl._classifier.compute  # llvmpipe and every GL 4.3 device
            work = impl._working_textures()[0]
            if impl._uploads_are_working:
                channels = impl._textures["original"].components
                scale = {"f1": 255.0, "nu2": 65535.0}[work.dtype]
                texels = _read(work, channels, np.uint8 if work.dtype == "f1" else np.uint16)
                work_o = _rgba((texels / scale).astype(np.float32))
            else:
                work_o = _read(work, 4, np.float32)
            lists = impl._lists["pure_colours"]
            grid = lists.grid
            flags = np.frombuffer(lists.flags.read(), np.uint32)[:grid[0] * grid[1]].reshape(grid[1], grid[0])
            wakes = _read(impl._work("wakes"), 1, np.uint8)[..., 0]
            gate = _read(impl._work("strength_factor"), 2, np.float32)[..., 1] if gated else None
    height, width = work_o.shape[:2]
    tile_o, tile_f = _uploaded(original), _uploaded(filtered)  # one tile
    fitted = active_mask(tile_o)
    inside = np.kron(fitted, np.ones((BLOCK_SIDE, BLOCK_SIDE), bool))[:height, :width]
    floor = RIDGE_NOISE_MARGIN * plan.pure_colours.ridge_noise
    ridges = possible_ridges(neighbours(planes(work_o)), floor)
    expected_wakes = (np.where(ridges, WAKE_RIDGE, 0) | np.where(differing_pixels(tile_f), WAKE_FILTERED, 0)) * inside
    np.testing.assert_array_equal(np.where(inside, wakes, 0), expected_wakes)
    codes = pure_colour_mask(work_o, tile_o, tile_f, floor, gate)
    np.testing.assert_array_equal(flags, codes)
    # Measured: 13 of O's 14 active blocks fitted, 7 of them whole, on the shapes; the photo
    # under the banner fits without the extension tests.
    if name in ("rgb8", "banner-over-photo"):
        assert (codes == FIT_PLAIN).any() and (codes == FIT_WHOLE).any()
    if name == "rgb8":
        assert (codes != 0).sum() < fitted.sum()
    assert_results_agree(recovered, aarecovery.recover(original, filtered, backend="numpy", linear=linear))


@pytest.mark.gl
def test_tiles_of_a_text_page_listed_equal_the_specification(gl_path):
    # A page of text in tiles: most blocks are live, some of O's are not fitted, and a tile's
    # steps must not read the model where the tile before left it (a regression: drawn as
    # one triangle where nearly every block was live, they did, 255 levels off).
    case = make_case(_scenes.render("text", 512, 4), "threshold", 4, "srgb")
    to8 = lambda image: np.clip(np.rint(image * 255), 0, 255).astype(np.uint8)
    original, filtered = to8(case.original), to8(case.filtered)
    plan = dataclasses.replace(make_plan(original, filtered, Parameters()), pure_colour_blocks=True)
    with aarecovery.Engine("gl", gl_path=gl_path) as engine:
        listed = aarecovery.recover(original, filtered, engine=engine, plan=plan, tile_size=128)
        whole = aarecovery.recover(original, filtered, engine=engine, plan=dataclasses.replace(
            plan, pure_colour_blocks=False), tile_size=128)
    np.testing.assert_array_equal(listed, whole)
    assert_results_agree(listed, aarecovery.recover(original, filtered, backend="numpy", plan=plan))
