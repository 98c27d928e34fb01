"""The GL backend against its NumPy twin, pass by pass, on both GL paths (fragment and compute).

The tolerances are in one table, ``tests/parity.py``: the working-space textures within 1e-6
relative (float32 rounding of the same sRGB formula), the maps and the final R by dtype.
"""

import dataclasses
import io

import numpy as np
import pytest
from PIL import Image

import aarecovery
from aarecovery import spec
from aarecovery.contract import layout_of, to_rgba_float
from parity import MAPS, WORKING_SPACE, assert_maps_agree, assert_results_agree
from scenes import luminance, shapes, to_uint8

pytestmark = pytest.mark.gl


def pairs():
    rng = np.random.default_rng(7)
    noise = (rng.random((40, 56, 3)) * 255).astype(np.uint8)
    structured = shapes(72, seed=2, noise=0.01)
    grey = luminance(structured / np.float32(255))
    yield "random-threshold", noise, np.where(noise > 128, 255, 0).astype(np.uint8)
    yield "shapes-threshold", structured, np.where(structured > 110, 255, 0).astype(np.uint8)
    yield "shapes-gradient-map", structured, to_uint8(np.stack([grey ** 0.5, grey, 1 - grey], -1))
    alpha = structured.copy()
    alpha = np.concatenate([structured, (grey[..., None] * 255).astype(np.uint8)], -1)
    yield "rgba-posterize", alpha, (alpha // 64 * 85).astype(np.uint8)
    sixteen = (structured.astype(np.uint16) * 257 + rng.integers(0, 256, structured.shape)).astype(np.uint16)
    yield "uint16-threshold", sixteen, np.where(sixteen > 30000, 65535, 0).astype(np.uint16)
    floats = structured[..., 0] / np.float32(255)
    yield "float-grey-gamma", floats, floats ** 2.2


PAIRS = list(pairs())
IDS = [name for name, *_ in PAIRS]


def _numpy_model(original, filtered, blend_space="linear", linear=False):
    o = spec.to_working_space(to_rgba_float(original, layout_of(original, "o"), "o"),
                                    linear_input=linear, blend_space=blend_space)
    f = spec.to_working_space(to_rgba_float(filtered, layout_of(filtered, "f"), "f"),
                                    linear_input=linear, blend_space=blend_space)
    return o, f, spec.fit_blend_model(o, f, 0.1, 0.01)


@pytest.fixture(scope="module")
def gl_engine(gl_path):
    engine = aarecovery.Engine(backend="gl", gl_path=gl_path)
    assert engine.gl_path == gl_path
    yield engine
    engine.release()


def _working_textures(engine):
    """O and F in the working space, read back as float32 RGBA."""
    impl = engine._impl
    with engine.context:
        impl._to_working_space()  # over the whole image; runs keep to the blocks they read
        textures = impl._working_textures()
        return [np.frombuffer(impl._framebuffer([texture]).read(components=4, dtype="f4"), np.float32)
                for texture in textures]


@pytest.mark.parametrize("name, original, filtered", PAIRS, ids=IDS)
@pytest.mark.parametrize("blend_space", ["linear", "srgb"])
def test_to_working_space(gl_engine, name, original, filtered, blend_space):
    gl_engine.set_images(original, filtered, blend_space=blend_space)
    expected_o, expected_f, _ = _numpy_model(original, filtered, blend_space)
    for actual, expected in zip(_working_textures(gl_engine), (expected_o, expected_f)):
        rtol, atol = WORKING_SPACE
        np.testing.assert_allclose(actual.reshape(expected.shape), expected, rtol=rtol, atol=atol)


@pytest.mark.parametrize("name, original, filtered", PAIRS, ids=IDS)
def test_fit_blend_model(gl_engine, name, original, filtered):
    gl_engine.set_images(original, filtered, blend_space="linear")
    gl_engine.compute(mode="paper", maps=True)
    actual = gl_engine.maps()
    _, _, expected = _numpy_model(original, filtered)
    expected.edge_strength = expected.edge
    assert_maps_agree(actual, expected)


@pytest.mark.parametrize("iterations", [0, 1, 2, 3, 5])
@pytest.mark.parametrize("name, original, filtered", PAIRS, ids=IDS)
def test_jacobi_steps_and_result(gl_engine, name, original, filtered, iterations):
    gl_engine.set_images(original, filtered, blend_space="linear")
    actual = gl_engine.recover(iterations=iterations, mode="paper")
    expected = aarecovery.recover(original, filtered, iterations=iterations, backend="numpy", mode="paper",
                                  blend_space="linear")
    assert_results_agree(actual, expected)


@pytest.mark.parametrize("blend_space, linear", [("srgb", False), ("linear", True), ("srgb", True)])
def test_blend_spaces_and_linear_input(gl_engine, blend_space, linear):
    _, original, filtered = PAIRS[2]
    if linear:
        original, filtered = original / np.float32(255), filtered / np.float32(255)
    gl_engine.set_images(original, filtered, blend_space=blend_space, linear=linear)
    actual = gl_engine.recover(mode="paper")
    expected = aarecovery.recover(original, filtered, backend="numpy", mode="paper",
                                  blend_space=blend_space, linear=linear)
    assert_results_agree(actual, expected)


def test_safe_mode_agrees(gl_engine):
    for _, original, filtered in PAIRS:
        actual = aarecovery.recover(original, filtered, engine=gl_engine)
        expected = aarecovery.recover(original, filtered, backend="numpy")
        assert_results_agree(actual, expected)


def test_engine_reuse_matches_fresh_runs(gl_engine):
    _, original, filtered = PAIRS[1]
    gl_engine.set_images(original, filtered)
    for sigma_d, sigma_e, iterations in [(0.1, 0.01, 3), (0.05, 0.02, 2), (0.2, 0.005, 4)]:
        again = gl_engine.recover(sigma_d=sigma_d, sigma_e=sigma_e, iterations=iterations, mode="paper")
        fresh = aarecovery.recover(original, filtered, sigma_d=sigma_d, sigma_e=sigma_e, iterations=iterations,
                                   backend="gl", mode="paper", gl_path=gl_engine.gl_path)
        np.testing.assert_array_equal(again, fresh)


def _borrowed_context():
    """A context of the caller's, as the viewer's window gives: GL 4.3 where the driver has it
    (NVIDIA's EGL makes exactly the version asked for), for the compute path."""
    from aarecovery.backends.gl.context import create_context
    return create_context()


def test_borrowed_context_state_is_restored(gl_path):
    import moderngl
    context = _borrowed_context()
    try:
        screen = context.simple_framebuffer((8, 8))
        screen.use()
        context.enable(moderngl.BLEND)
        engine = aarecovery.Engine(backend="gl", context=context, gl_path=gl_path)
        _, original, filtered = PAIRS[0]
        engine.set_images(original, filtered)
        blended = engine.recover(mode="paper")
        assert context.fbo == screen
        engine.release()
        assert_results_agree(blended, aarecovery.recover(original, filtered, backend="numpy", mode="paper"))
        assert not context.error or context.error == "GL_NO_ERROR"
    finally:
        context.release()


@pytest.mark.parametrize("caller_framebuffer", [True, False])
def test_a_borrowed_context_takes_pairs_of_every_size(gl_path, caller_framebuffer):
    # The classification, the copy of F and the readback bind the engine's own framebuffers,
    # and a new size releases them: the engine must leave the caller's bound after each call
    # and never bind a released one (with none of the caller's bound, the second pair's
    # first run raised an AttributeError).
    context = _borrowed_context()
    try:
        screen = None
        if caller_framebuffer:
            screen = context.simple_framebuffer((8, 8))
            screen.use()
        engine = aarecovery.Engine(backend="gl", context=context, gl_path=gl_path)
        for _, original, filtered in PAIRS:
            engine.set_images(original, filtered)
            for mode in ("paper", "safe"):
                assert_results_agree(engine.recover(mode=mode),
                                     aarecovery.recover(original, filtered, backend="numpy", mode=mode))
                if screen is not None:
                    assert context.fbo == screen
        engine.release()
    finally:
        context.release()


@pytest.mark.parametrize("scene, filter_name, space", [("text", "threshold", "linear"), ("lines", "gamma", "srgb"),
                                                       ("lines", "gradientmap", "linear"),
                                                       ("lines", "tonemap", "srgb"), ("lines", "equalize", "srgb"),
                                                       ("lines", "posterize", "srgb")])
def test_pure_colours_agree(gl_engine, scene, filter_name, space):
    # The safe default's pure-colour extension (fit_pure_colour_model, jacobi_step with fixed
    # colours) on thin features, 8-bit: the final R within 1/255, and the extension in use.
    from aarecovery.lab import scenes as _scenes
    from aarecovery.lab.groundtruth import make_case
    case = make_case(_scenes.render(scene, 48, 4), filter_name, 4, space)
    original = np.rint(case.original * 255).astype(np.uint8)
    filtered = np.rint(case.filtered * 255).astype(np.uint8)
    actual = aarecovery.recover(original, filtered, engine=gl_engine)
    gl_engine.set_images(original, filtered)
    gl_engine.compute()
    assert gl_engine.last_plan.pure_colours is not None
    # Tone mapping and equalization scale colour with a mapped luminance / luma (table keys 3, 2).
    assert gl_engine.last_plan.pure_colours.key == {"tonemap": "luminance_scale", "equalize": "luma_scale"}.get(
        filter_name, gl_engine.last_plan.pure_colours.key)
    expected = aarecovery.recover(original, filtered, backend="numpy")
    assert_results_agree(actual, expected)
    paper = aarecovery.recover(original, filtered, backend="numpy", mode="paper")
    assert np.abs(expected.astype(np.int64) - paper).max() > 16
    _, maps = aarecovery.recover(original, filtered, engine=gl_engine, return_maps=True)
    _, expected_maps = aarecovery.recover(original, filtered, backend="numpy", return_maps=True)
    assert_maps_agree(maps, expected_maps, names=("beta",))


@pytest.mark.parametrize("iterations", [1, 3])
def test_pure_colour_jacobi_steps_agree_on_float_data(gl_engine, iterations):
    # The GL steps add the fit's constant ((1 - beta) F plus the fixed pure colours' share) to
    # the weighted gathers instead of forming the spec's blend: float results within 1e-5.
    from aarecovery.lab import scenes as _scenes
    from aarecovery.lab.groundtruth import make_case
    case = make_case(_scenes.render("text", 48, 4), "threshold", 4, "linear")
    original, filtered = case.original[..., :3], case.filtered[..., :3]
    actual = aarecovery.recover(original, filtered, engine=gl_engine, iterations=iterations)
    assert gl_engine.last_plan.pure_colours is not None
    expected = aarecovery.recover(original, filtered, backend="numpy", iterations=iterations)
    np.testing.assert_allclose(actual, expected, rtol=0, atol=1e-5)
    paper = aarecovery.recover(original, filtered, backend="numpy", mode="paper", iterations=iterations)
    assert np.abs(expected - paper).max() > 16 / 255


def test_pure_colours_agree_above_a_jpegs_noise(gl_engine):
    # O's compression noise raises the contrast an extreme needs, and a colour whose luma is
    # a flat colour's is that colour (uniforms in GL).
    from jpeg_scans import scan_page, threshold
    _, original, _ = scan_page(7, 75)
    filtered = threshold(original)
    actual = aarecovery.recover(original, filtered, engine=gl_engine)
    assert gl_engine.last_plan.pure_colours.noise_contrast > 30 / 255
    assert gl_engine.last_plan.pure_colours.luma_purity > 0
    expected = aarecovery.recover(original, filtered, backend="numpy")
    assert np.abs(actual.astype(np.int64) - expected).max() <= 1


def test_pure_colours_agree_at_the_floor_of_a_jpegs_noise_contrast(gl_engine):
    # Where O's noise estimate from its pixels falls to the floor (MIN_NOISE_CONTRAST), 8-bit
    # extremes must not tie with the contrast they need: at exactly 20 levels GL and NumPy
    # took different extremes as thin features on this page, 20 pixels up to 38 levels apart.
    from PIL import ImageDraw, ImageFont

    from aarecovery.lab.drawings import SERIF_FONT
    from aarecovery.plan.compression import MIN_NOISE_CONTRAST
    page = Image.new("RGB", (512, 512), (214, 203, 170))
    draw = ImageDraw.Draw(page)
    for line in range(4):
        draw.text((42, 64 + 102 * line), "the quick fox jumps", font=ImageFont.truetype(SERIF_FONT, 44),
                  fill=(35, 30, 45))
    buffer = io.BytesIO()
    page.resize((128, 128), Image.BOX).save(buffer, format="JPEG", quality=90)
    original = np.asarray(Image.open(buffer).convert("RGB"))
    filtered = np.where(original >= 128, 255, 0).astype(np.uint8)
    actual = aarecovery.recover(original, filtered, engine=gl_engine)
    assert gl_engine.last_plan.pure_colours.noise_contrast == MIN_NOISE_CONTRAST
    expected = aarecovery.recover(original, filtered, backend="numpy")
    assert np.abs(actual.astype(np.int64) - expected).max() <= 1


@pytest.mark.parametrize("ink_count", [1, 2, 3, 5, 16])
def test_the_seen_ink_test_agrees_at_every_compiled_length(gl_engine, ink_count):
    # The GL loop over O's inks is compiled to the fewest of a few lengths that hold them
    # (INK_SLOTS), its spare slots holding no colour. Serif text in green ink under the cube
    # curve, where the green ink that O shows decides (test_pure_colours), first of `ink_count`
    # inks; the others lie on the cube's faces far from every colour of the scene.
    from aarecovery.lab.realtools import FAMILIES, render_family
    from aarecovery.plan.resample import box_downsample
    from aarecovery.spec.pure_colours import INK_COUNT
    scene = np.rint(render_family("serif", 96) * 255).astype(np.uint8)
    original = np.rint(box_downsample(scene.astype(np.float32) / 255, FAMILIES["serif"].k, "srgb") * 255
                       ).astype(np.uint8)
    filtered = np.rint(np.minimum(original.astype(np.float64) ** 3, 255)).astype(np.uint8)
    engines = {"numpy": aarecovery.Engine("numpy"), "gl": gl_engine}
    plan = engines["numpy"].set_images(original, filtered) or engines["numpy"].plan()
    green = np.float32([0, 89, 38]) / 255
    assert np.abs(plan.pure_colours.inks - green).max(axis=1).min() < 0.5 / 255
    others = np.float32([[1, 1, 0.5 + step / 64] for step in range(INK_COUNT)])
    results = {}
    for inks in (green[None], np.concatenate([green[None], others])[:ink_count]):
        tried = dataclasses.replace(plan, pure_colours=dataclasses.replace(plan.pure_colours, inks=inks))
        for name, engine in engines.items():
            engine.set_images(original, filtered)
            engine.run(tried)
            results[name, len(inks)] = engine.result()
    assert_results_agree(results["gl", ink_count], results["numpy", ink_count])
    # The spare inks change nothing; without the green ink the result would differ.
    np.testing.assert_array_equal(results["gl", ink_count], results["gl", 1])
    without = dataclasses.replace(plan, pure_colours=dataclasses.replace(plan.pure_colours, inks=green[:0]))
    gl_engine.run(without)
    assert np.abs(gl_engine.result().astype(np.int64) - results["gl", 1]).max() > 16


def _sparse_pair():
    """A few features in a large flat image: most blocks are skipped."""
    from aarecovery.lab.groundtruth import make_case
    from aarecovery.lab.scenes import render
    case = make_case(render("text", 48, 4), "threshold", 4, "linear")
    original = np.full((160, 176, 3), 255, np.uint8)
    filtered = np.full((160, 176, 3), 255, np.uint8)
    original[70:70 + 48, 100:100 + 48] = np.rint(case.original[..., :3] * 255)
    filtered[70:70 + 48, 100:100 + 48] = np.rint(case.filtered[..., :3] * 255)
    original[20, 10:40] = 170  # a thin light stroke the threshold erased from F
    return original, filtered


def test_switching_modes_on_one_engine(gl_engine):
    # paper and safe (pure colours) draw different block sets; what one wrote outside the
    # other's blocks must not leak into the next result.
    original, filtered = _sparse_pair()
    gl_engine.set_images(original, filtered)
    for mode, iterations in [("safe", 3), ("paper", 3), ("safe", 1), ("paper", 2), ("safe", 3)]:
        gl_engine.compute(mode=mode, iterations=iterations, maps=True)
        actual, maps = gl_engine.result(), gl_engine.maps()
        expected, expected_maps = aarecovery.recover(original, filtered, backend="numpy", mode=mode,
                                                     iterations=iterations, return_maps=True)
        assert_results_agree(actual, expected, (mode, iterations))
        assert_maps_agree(maps, expected_maps, names=("beta", "edge_strength"), message=(mode, iterations))


def _list_lengths(engine, image_name):
    from gl_blocks import gpu_lists
    with engine.context:
        return {name: len(blocks) for name, blocks in gpu_lists(engine._impl, image_name).items()}


@pytest.mark.parametrize("mode", ["paper", "safe"])
def test_block_passes_match_whole_image_passes(gl_engine, mode):
    # The fit and inner Jacobi passes cover only blocks where the edge strength can be non-zero
    # (F not flat; O not flat with pure colours), the rest gets F. A few features in a large
    # flat image, so that most blocks are skipped, must give the NumPy result everywhere.
    from aarecovery.backends.gl.blocks import BLOCK_SIDE
    original, filtered = _sparse_pair()
    actual = aarecovery.recover(original, filtered, engine=gl_engine, mode=mode)
    total = -(-160 // BLOCK_SIDE) * -(-176 // BLOCK_SIDE)
    lengths = _list_lengths(gl_engine, "filtered")
    assert 0 < lengths["active"] < total / 2 and lengths["active"] + lengths["inactive"] == total
    if mode == "safe":  # pure colours cover O's blocks, found when first needed
        assert 0 < _list_lengths(gl_engine, "original")["active"] < total / 2
    expected = aarecovery.recover(original, filtered, backend="numpy", mode=mode)
    assert_results_agree(actual, expected)


def test_pure_colour_decisions_agree_where_a_neighbour_sits_exactly_on_the_ridge_margin(gl_engine):
    """Synthetic scenes give exact coverages, and so neighbours exactly 10 % less extreme than
    the extreme: with a ridge margin of exactly 0.1, rounding decided the ridge test, the two
    backends extended different extremes and beta differed by 0.08-0.22 (shapes under a cube
    curve, float input). The margin sits off such ties (0.1001); every map must now agree."""
    from aarecovery.lab.scenes import render
    from aarecovery.plan.resample import box_downsample
    original = box_downsample(render("shapes", 200, 4), 4, "linear")
    filtered = original ** 3
    _, expected = aarecovery.recover(original, filtered, backend="numpy", iterations=1, return_maps=True)
    _, actual = aarecovery.recover(original, filtered, engine=gl_engine, iterations=1, return_maps=True)
    assert_maps_agree(actual, expected)


@pytest.mark.parametrize("weights", ["LUMA", "LUMINANCE_D50"])
def test_luminance_keyed_tables_agree(gl_engine, weights):
    """Thresholds of the encoded luminance of linear light, as GEGL and GIMP compute it: the
    table is keyed by that luminance (table keys 4 and 5) on both backends, and the inks
    are taken from O's flat colours where they lie beyond a thin feature."""
    from aarecovery import colour
    from aarecovery.lab.scenes import render
    from aarecovery.plan.resample import box_downsample
    original = np.rint(box_downsample(render("text", 64, 4), 4, "linear") * 255).astype(np.uint8)
    linear = colour.srgb_to_linear(original / np.float32(255))
    luminance = colour.linear_to_srgb(linear @ np.array(getattr(colour, weights), np.float32))
    filtered = np.repeat(np.where(luminance >= 0.5, 255, 0).astype(np.uint8)[..., None], 3, axis=-1)
    gl_engine.set_images(original, filtered)
    gl_engine.compute()
    # On this grey-inked text the two weightings tie; either luminance key (4, 5) will do.
    assert gl_engine.last_plan.pure_colours.key in ("luminance", "luminance_d50")
    actual = gl_engine.result()
    expected = aarecovery.recover(original, filtered, backend="numpy")
    assert_results_agree(actual, expected)
    assert np.abs(expected.astype(np.int64) - filtered).max() > 16


def test_rec601_grey_keyed_tables_agree(gl_engine):
    """A colour map of a colour image's 8-bit Rec. 601 grey, as OpenCV's applyColorMap takes
    it: the table is keyed by that grey (table key 8) on both backends, which round it from
    the 8-bit channels in whole numbers."""
    from test_pure_colours import opencv_jet_of_grey

    from aarecovery.lab.scenes import render
    from aarecovery.plan.resample import box_downsample
    original = np.rint(box_downsample(render("chart", 64, 4), 4, "srgb") * 255).astype(np.uint8)
    filtered = np.rint(opencv_jet_of_grey(original / np.float32(255)) * 255).astype(np.uint8)
    gl_engine.set_images(original, filtered)
    gl_engine.compute()
    assert gl_engine.last_plan.pure_colours.key == "luma601"
    actual = gl_engine.result()
    expected = aarecovery.recover(original, filtered, backend="numpy")
    assert_results_agree(actual, expected)
    assert np.abs(expected.astype(np.int64) - filtered).max() > 16


@pytest.mark.parametrize("overlap_readback", [False, True])
@pytest.mark.parametrize("compute_classification", [True, False])
def test_transfer_and_classification_variants_agree(gl_path, overlap_readback, compute_classification):
    # Pixel-buffer readbacks (what a GPU does, overlapping the next tile) and the block
    # classification of GL 3.3 to 4.2 (a GPU block mask, listed on the CPU), forced on llvmpipe.
    engine = aarecovery.Engine(backend="gl", gl_path=gl_path)
    try:
        engine._impl._overlap_readback = overlap_readback
        engine._impl._classifier.compute = compute_classification
        for _, original, filtered in PAIRS[1:5] + [("sparse",) + _sparse_pair()]:
            for mode, tile_size in (("paper", 23), ("safe", None)):
                actual = aarecovery.recover(original, filtered, engine=engine, mode=mode, tile_size=tile_size)
                expected = aarecovery.recover(original, filtered, backend="numpy", mode=mode)
                assert_results_agree(actual, expected)
    finally:
        engine.release()


def test_shared_memory_fit_agrees():
    # The compute path's fit with its neighbourhoods in shared memory (off by default: slower
    # on llvmpipe, see paths.py), against the NumPy model and result.
    engine = aarecovery.Engine(backend="gl", gl_path="compute")
    try:
        engine._impl.shared_tile = True
        for _, original, filtered in PAIRS:
            engine.set_images(original, filtered, blend_space="linear")
            engine.compute(mode="paper", maps=True)
            _, _, expected = _numpy_model(original, filtered)
            np.testing.assert_allclose(engine.maps().beta, expected.beta, rtol=0, atol=MAPS["beta"])
            actual = engine.result()
            reference = aarecovery.recover(original, filtered, backend="numpy", mode="paper", blend_space="linear")
            assert_results_agree(actual, reference)
    finally:
        engine.release()


def test_neighbours_equally_far_from_the_mean_start_the_fit_alike(gl_engine):
    """Quantised noise holds exact ties of the EM's start: two neighbours equally far from the
    mean (819 / (81 * 255^2) at (468, 546) of this photo-like pair). Rounding broke them
    differently on GL and NumPy, the three EM steps had not converged, and the extremes
    differed: R by up to 7/255 here, 37/255 on a 3000 x 3000 pair. Ties now keep the first
    neighbour on both (SPREAD_TIE)."""
    from aarecovery.lab.bench import bench_image_pair
    original, filtered = bench_image_pair(1000, 1000, "threshold", seed=0)
    for row, column in [(468, 546), (469, 663), (509, 385), (845, 551)]:
        window = np.s_[row - 8:row + 8, column - 8:column + 8]
        arguments = dict(mode="paper", blend_space="srgb", return_maps=True)
        expected, expected_maps = aarecovery.recover(original[window], filtered[window], backend="numpy",
                                                     **arguments)
        actual, maps = aarecovery.recover(original[window], filtered[window], engine=gl_engine, **arguments)
        assert_results_agree(actual, expected, (row, column))
        assert_maps_agree(maps, expected_maps, message=(row, column))


@pytest.mark.parametrize("filter_name", ["threshold", "gamma"])
def test_best_pairs_agree(gl_engine, filter_name):
    # The safe default's best pair of neighbours where the colour line misses a pixel
    # (spec.blend_model.best_pair, its GLSL twin in blend_model.glsl): overlapping shapes in
    # many colours, 8-bit, where the search replaces the line's extremes at junctions.
    import dataclasses

    from aarecovery.lab import scenes as _scenes
    from aarecovery.lab.groundtruth import make_case
    case = make_case(_scenes.render("shapes", 64, 4), filter_name, 4, "srgb")
    original = np.rint(case.original * 255).astype(np.uint8)
    filtered = np.rint(case.filtered * 255).astype(np.uint8)
    actual, maps = aarecovery.recover(original, filtered, engine=gl_engine, return_maps=True)
    assert gl_engine.last_plan.best_pair
    expected, expected_maps = aarecovery.recover(original, filtered, backend="numpy", return_maps=True)
    assert_results_agree(actual, expected)
    assert_maps_agree(maps, expected_maps, names=("alpha", "beta", "residual"))
    numpy_engine = aarecovery.Engine(backend="numpy")
    numpy_engine.set_images(original, filtered)
    numpy_engine.run(dataclasses.replace(gl_engine.last_plan, best_pair=False))
    assert np.abs(numpy_engine.result().astype(np.int64) - expected).max() > 8  # the search acted
