"""The safe plan's faster formulations give bit for bit what the direct NumPy ones gave.

The plan's decisions compare its figures with thresholds, so a speed-up may not move them by
an ulp: each is checked here against the formula it replaced.
"""

import io

import numpy as np
import pytest
from PIL import Image

from aarecovery.colour import REC601_LUMA, largest_channel
from aarecovery.params import SIGMA_D, SIGMA_E
from aarecovery.plan import compression, pointwise
from aarecovery.spec import to_working_space
from aarecovery.spec.blend_model import fit_paper_model

from jpeg_scans import scan_page


@pytest.mark.parametrize("shape", [(7, 3), (5, 6, 4), (9, 2, 1), (64,)])
def test_largest_channel_is_max_over_the_last_axis(shape):
    values = np.random.default_rng(1).normal(size=shape).astype(np.float32)
    values.flat[::5] = np.nan
    np.testing.assert_array_equal(largest_channel(values), values.max(axis=-1))


def _jpeg_luma(quality):
    _, page, _ = scan_page(2, quality)
    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(page[5:, 3:])).save(buffer, format="JPEG", quality=quality)
    buffer.seek(0)
    with Image.open(buffer) as decoded:
        pixels = np.asarray(decoded.convert("RGB")).astype(np.float64)
    return pixels @ np.array(REC601_LUMA)


@pytest.mark.parametrize("quality", [75, 95])
def test_the_grid_search_dcts_and_busy_blocks_are_the_direct_ones(quality):
    luma = _jpeg_luma(quality)
    dct = compression._DCT
    block = compression.BLOCK
    for row in range(block):
        shared = compression._column_transforms(luma, row)
        for column in range(block):
            rows, columns = (luma.shape[0] - row) // block, (luma.shape[1] - column) // block
            blocks = luma[row:row + rows * block, column:column + columns * block]
            blocks = blocks.reshape(rows, block, columns, block).transpose(0, 2, 1, 3).reshape(-1, block, block)
            direct = dct @ blocks @ dct.T
            np.testing.assert_array_equal(compression._block_dct(luma, row, column, shared), direct)
            busy = np.abs(direct.reshape(len(direct), -1)[:, 1:]).max(axis=1) > compression._BUSY_COEFFICIENT
            assert busy.any() and not busy.all()
            np.testing.assert_array_equal(compression._busy(direct), busy)


def _grid_search_over_every_block(luma):
    """The grid search's shares as it computed them before it skipped the blocks that cannot be busy."""
    shares = np.full((compression.BLOCK, compression.BLOCK), -1.0)
    for row in range(compression.BLOCK):
        shared = compression._column_transforms(luma, row)
        for column in range(compression.BLOCK):
            coefficients = compression._block_dct(luma, row, column, shared)
            busy = compression._busy(coefficients)
            if busy.sum() >= compression._MIN_BUSY_BLOCKS:
                shares[row, column] = float((np.abs(coefficients[busy][:, 3:, 3:])
                                             < compression._ZERO_COEFFICIENT).mean())
    return shares


@pytest.mark.parametrize("quality", [None, 75, 95])
def test_the_grid_search_skips_only_blocks_that_are_not_busy(quality):
    luma = _jpeg_luma(quality) if quality else scan_page(2, 75)[0][5:, 3:].astype(np.float64) @ np.array(REC601_LUMA)
    sums, squares = compression._summed_areas(luma)
    skipped = 0
    for row in range(compression.BLOCK):
        for column in range(compression.BLOCK):
            every = compression._block_dct(luma, row, column)
            candidates = compression._may_be_busy(sums, squares, row, column)
            assert candidates.size == len(every)
            np.testing.assert_array_equal(compression._block_dct(luma, row, column, only=candidates),
                                          every[candidates.ravel()])
            busy = compression._busy(every)
            assert not (busy & ~candidates.ravel()).any()
            skipped += int((~candidates).sum())
    assert skipped > 0
    # The whole search: the same shares, so the same phase and margin (and the table, measured
    # at that phase from every block).
    encoded = np.repeat((luma / 255.0)[..., None], 3, axis=-1).astype(np.float32)
    phase, margin, _ = compression.detect_block_grid(encoded)
    shares = _grid_search_over_every_block(compression._luma(encoded))
    assert shares.max() >= 0
    order = np.argsort(shares.ravel())
    assert phase == tuple(int(i) for i in np.unravel_index(order[-1], shares.shape))
    assert margin == float(shares.ravel()[order[-1]] - max(shares.ravel()[order[-2]], 0.0))


def _direct_scaled_luma(source, result, source_luma):
    """The scaled luma as the scale tables computed it with NumPy's reductions over the last axis."""
    usable = (result < 1 - 1 / 512) & (source > 1e-4)
    channel = np.argmax(np.where(usable, source, -1), axis=-1)
    rows = np.arange(len(source))
    ratio = result[rows, channel] / np.maximum(source[rows, channel], 1e-4)
    scaled = np.where(source_luma > 1e-6, ratio * source_luma, result.mean(axis=-1))
    return scaled, usable.any(axis=-1) | (source_luma <= 1e-6)


def test_the_scaled_luma_is_that_of_the_direct_formulas():
    rng = np.random.default_rng(3)
    source = rng.random((5000, 3))
    source[::4] = 0
    source[::7, 1] = 1
    source[::5, 1:] = source[::5, :1]  # ties between channels: the first wins
    result = np.clip(source * rng.uniform(0.5, 2, (5000, 1)), 0, 1)
    result[::9, 2] = rng.random(len(result[::9]))
    source_luma = source @ np.array([0.2126, 0.7152, 0.0722])
    fast, direct = pointwise._scaled_luma(source, result, source_luma), _direct_scaled_luma(source, result, source_luma)
    for a, b in zip(fast, direct):
        np.testing.assert_array_equal(a, b)
    assert 0 < direct[1].mean() < 1 and (source_luma <= 1e-6).any()


def test_a_model_fitted_on_some_pixels_is_the_whole_fit_there():
    rng = np.random.default_rng(5)
    blocks = (rng.random((40, 40, 3)) > 0.5).astype(np.float32).repeat(4, 0).repeat(4, 1)
    encoded = (blocks[:-1, :-1] + blocks[1:, :-1] + blocks[:-1, 1:] + blocks[1:, 1:]) / 4
    noisy = np.clip(encoded + rng.normal(0, 0.01, encoded.shape), 0, 1).astype(np.float32)
    work = to_working_space(np.concatenate([noisy, np.ones(noisy.shape[:2] + (1,), np.float32)], -1))
    only = np.zeros(work.shape[:2], bool)
    only[1::3] = True
    whole = fit_paper_model(work, work, SIGMA_D.default, SIGMA_E.default)
    some = fit_paper_model(work, work, SIGMA_D.default, SIGMA_E.default, only=only)
    assert (whole.beta[only] > 0.5).any()
    for name in ("alpha", "beta", "index_a", "index_b", "residual"):
        np.testing.assert_array_equal(getattr(some, name)[only], getattr(whole, name)[only])
    assert not some.beta[~only].any() and (some.alpha[~only] == 0.5).all()


def _drawn_and_noisy(seed, height=48, width=40):
    """Flat colours in blocks (ties, exact recurrences), some pixels nudged by less and more
    than the flat span, black and the image's borders included."""
    rng = np.random.default_rng(seed)
    levels = rng.integers(0, 4, (height // 4, width // 4, 3)) / np.float32(3)
    image = np.repeat(np.repeat(levels, 4, 0), 4, 1)[:height, :width].astype(np.float32)
    image[:, : width // 4] = 0
    nudges = rng.choice(np.array([0, 0, 0.4, 0.6, 3.0], np.float32) / 255, image.shape)
    return np.clip(image + nudges, 0, 1).astype(np.float32)


def _direct_flat_pixels(encoded):
    from aarecovery.spec.local_plan import FLAT_SPAN
    height, width = encoded.shape[:2]
    padded = np.pad(encoded, ((1, 1), (1, 1), (0, 0)), mode="edge")
    window = [padded[dy:dy + height, dx:dx + width] for dy in range(3) for dx in range(3)]
    brightest = np.max(window, axis=0)
    flat = (brightest - np.min(window, axis=0)).max(axis=-1) <= np.float32(FLAT_SPAN)
    return flat & (brightest.max(axis=-1) > np.float32(FLAT_SPAN))


@pytest.mark.parametrize("seed", range(4))
def test_flat_pixels_by_running_extremes_are_the_stacked_ones(seed):
    from aarecovery.spec.local_plan import flat_pixels
    image = _drawn_and_noisy(seed)
    np.testing.assert_array_equal(flat_pixels(image), _direct_flat_pixels(image))


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("share", [0.1, 0.2, 0.4, 0.8])
def test_the_local_factor_at_some_pixels_is_the_whole_factor_there(seed, share):
    """Both ways of reading the ink at some pixels (their neighbourhoods gathered, or the
    whole image's weight above local_plan._GATHERED_SHARE of its pixels) give its values, at
    the 8-bit span and at a JPEG's."""
    from aarecovery.plan.mixed_content import COMPRESSED_INK_SPAN
    from aarecovery.spec.local_plan import LocalStrength, ink_weight, ink_weight_at
    image = _drawn_and_noisy(seed)
    rows, cols = np.nonzero(np.random.default_rng(seed).random(image.shape[:2]) < share)
    assert ink_weight(image)[rows, cols].any()
    np.testing.assert_array_equal(ink_weight_at(image, rows, cols), ink_weight(image)[rows, cols])
    np.testing.assert_array_equal(ink_weight_at(image, rows, cols, COMPRESSED_INK_SPAN),
                                  ink_weight(image, span=COMPRESSED_INK_SPAN)[rows, cols])
    for local in (LocalStrength(0.25), LocalStrength(0.5, drawn_ink=False)):
        np.testing.assert_array_equal(local.factor_at(image, rows, cols), local.factor(image)[rows, cols])


def test_the_hard_edged_share_is_that_of_the_whole_factor_at_the_edges():
    from aarecovery.spec.local_plan import LocalStrength
    image = _drawn_and_noisy(5)
    edges = np.random.default_rng(5).random(image.shape[:2]) < 0.3
    for local in (LocalStrength(0.0), LocalStrength(0.4), LocalStrength(0.5, drawn_ink=False)):
        expected = float((local.factor(image)[edges] > (1 + local.textured) / 2).mean())
        assert local.hard_edged_share(image, edges) == expected
    assert LocalStrength(0.3).hard_edged_share(image, np.zeros(edges.shape, bool)) == 0.0


def _same(one, other):
    """Equal analyses, arrays bit for bit (a dataclass's repr abbreviates its arrays)."""
    if isinstance(one, np.ndarray) or isinstance(other, np.ndarray):
        np.testing.assert_array_equal(one, other, strict=True)
    elif hasattr(one, "__dict__") and not isinstance(one, type):
        assert type(one) is type(other)
        assert vars(one).keys() == vars(other).keys()
        for name in vars(one):
            _same(getattr(one, name), getattr(other, name))
    elif hasattr(one, "__dataclass_fields__"):
        for name in one.__dataclass_fields__:
            _same(getattr(one, name), getattr(other, name))
    else:
        assert one == other


def _analysed_pairs():
    from jpeg_scans import scan_page

    from aarecovery.filters import apply
    from aarecovery.lab.bench import bench_image_pair
    from aarecovery.lab.processes import thin_features_pair

    photo = bench_image_pair(192, 160)
    _, page, _ = scan_page(3, 80)
    return {"thin features": thin_features_pair(200, 176), "photo-like": photo,
            "blur": (photo[0], apply("blur", photo[0])), "jpeg page": (page, apply("threshold", page))}


@pytest.mark.parametrize("name", ["thin features", "photo-like", "blur", "jpeg page"])
def test_the_plan_with_one_blas_thread_is_the_plan_with_blas_as_it_is(name, monkeypatch):
    from contextlib import nullcontext

    import aarecovery.plan as plan_layer
    from aarecovery.params import Parameters

    original, filtered = _analysed_pairs()[name]
    limited = plan_layer.make_plan(original, filtered, Parameters())
    monkeypatch.setattr(plan_layer, "one_blas_thread", nullcontext)
    _same(limited, plan_layer.make_plan(original, filtered, Parameters()))


def test_one_blas_thread_limits_blas_inside_and_restores_it():
    from threadpoolctl import threadpool_info

    from aarecovery.plan.blas import one_blas_thread

    def threads():
        # NumPy's BLAS, the plan's: a library another test loads later (OpenCV's) is not the
        # plan's, and the controller, made once per process, does not see it.
        return [library["num_threads"] for library in threadpool_info()
                if library["user_api"] == "blas" and "numpy" in library["filepath"]]

    before = threads()
    assert before, "NumPy's BLAS library was not found by threadpoolctl"
    with one_blas_thread():
        assert set(threads()) <= {1}
    assert threads() == before
    # Two threads' blocks that end in the other order than they began.
    first, second = one_blas_thread(), one_blas_thread()
    first.__enter__()
    second.__enter__()
    first.__exit__(None, None, None)
    assert set(threads()) <= {1}
    second.__exit__(None, None, None)
    assert threads() == before


@pytest.mark.parametrize("strength", [0.25, 0.5, 0.75, 0.375])
def test_a_model_fitted_at_strength_one_and_scaled_is_the_fit_at_that_strength(strength):
    import dataclasses

    from aarecovery.lab.bench import bench_image_pair
    from aarecovery.spec import fit_blend_model
    from aarecovery.spec.blend_model import scaled_confidence

    original, filtered = (to_working_space(np.concatenate([image / np.float32(255), np.ones(image.shape[:2] + (1,),
                                                                                            np.float32)], -1)
                                           .astype(np.float32), blend_space=space)
                          for image, space in zip(bench_image_pair(96, 80, "gamma"), ("srgb", "srgb")))
    once = fit_blend_model(original, filtered, SIGMA_D.default, SIGMA_E.default)
    scaled = dataclasses.replace(once, beta=scaled_confidence(once.beta, strength))
    direct = fit_blend_model(original, filtered, SIGMA_D.default, SIGMA_E.default, strength)
    assert (direct.beta > 0).any()
    _same(scaled, direct)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_flat_pixels_of_the_palette_by_running_extremes_are_those_of_the_nine_differences(seed):
    from aarecovery.plan import pure_colours

    rng = np.random.default_rng(seed)
    # Flat patches of 8-bit colours, steps of exactly the tolerance and of one ulp around it.
    base = np.repeat(np.repeat(rng.integers(0, 256, (12, 10, 3)), 4, 0), 4, 1) / np.float32(255)
    step = np.float32(1 / 255) + rng.choice([-1, 0, 1], base.shape) * np.spacing(np.float32(1 / 255))
    image = np.clip(base + rng.choice([-1, 0, 0, 0, 1], base.shape) * step, 0, 1).astype(np.float32)
    height, width = image.shape[:2]
    padded = np.pad(image, ((1, 1), (1, 1), (0, 0)), mode="edge")
    direct = np.ones((height, width), bool)
    for dy in range(3):
        for dx in range(3):
            direct &= largest_channel(np.abs(padded[dy:dy + height, dx:dx + width] - image)) <= 1 / 255
    assert 0 < direct.sum() < direct.size
    np.testing.assert_array_equal(pure_colours._flat(image), direct)


def test_without_threadpoolctl_the_plan_runs_with_blas_as_it_is(monkeypatch):
    import sys

    from aarecovery.plan import blas

    blas._controller.cache_clear()
    monkeypatch.setitem(sys.modules, "threadpoolctl", None)
    try:
        with blas.one_blas_thread():
            assert blas._controller() is None
    finally:
        blas._controller.cache_clear()


@pytest.mark.parametrize("quality,offset", [(75, (0, 0)), (95, (5, 3)), (98, (2, 7))])
def test_every_phases_block_grain_from_the_running_spans_is_the_blocks_own(quality, offset):
    # hidden_compression reads all 64 phases from one array of 8 x 8 spans (42 -> 2.4 ms on a
    # 512 x 512 window); each phase's share must be the one its reshaped blocks give.
    luma = _jpeg_luma(quality)[offset[0]:, offset[1]:]
    spans = compression._block_spans(luma)
    for row in range(compression.BLOCK):
        for column in range(compression.BLOCK):
            assert compression._grain_of_spans(spans[row::compression.BLOCK, column::compression.BLOCK]) \
                == compression._block_grain_at(luma, row, column)


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.float32, np.float64])
@pytest.mark.parametrize("channels", [None, 1, 3, 4])
def test_the_window_choice_counts_the_edge_pixels_of_the_direct_formula(dtype, channels):
    from aarecovery import sample
    from aarecovery.colour import luma

    rng = np.random.default_rng(3)
    shape = (40, 50) if channels is None else (40, 50, channels)
    # A walk whose steps straddle the edge step, so that rounding would show.
    walk = np.clip(0.5 + np.cumsum(rng.normal(0, 0.06, size=shape), axis=1), 0, 1)
    region = (np.rint(walk * np.iinfo(dtype).max) if np.dtype(dtype).kind == "u" else walk).astype(dtype)
    values = region if region.ndim == 2 else region[..., 0] if region.shape[2] <= 2 else region[..., :3]
    scale = np.float32(1 / np.iinfo(values.dtype).max) if values.dtype.kind in "ui" else np.float32(1)
    light = values.astype(np.float32) * scale
    if light.ndim == 3:
        light = luma(light)
    direct = (int((np.abs(np.diff(light, axis=1)) > sample._EDGE_STEP).sum())
              + int((np.abs(np.diff(light, axis=0)) > sample._EDGE_STEP).sum()))
    assert 0 < direct < 2 * light.size  # some steps above the edge step, some below
    assert sample._edge_pixels(region) == direct


def _direct_grain_spreads(encoded):
    """The grain's spreads as stacked views gave them: the 3 x 3 span and that of the high pass."""
    height, width = encoded.shape[:2]
    padded = np.pad(encoded, ((1, 1), (1, 1), (0, 0)), mode="edge")
    window = [padded[dy:dy + height, dx:dx + width] for dy in range(3) for dx in range(3)]
    high = encoded - np.mean(window, axis=0)
    padded = np.pad(high, ((1, 1), (1, 1), (0, 0)), mode="edge")
    high_window = [padded[dy:dy + height, dx:dx + width] for dy in range(3) for dx in range(3)]
    return (np.max(window, axis=0) - np.min(window, axis=0),
            np.max(high_window, axis=0) - np.min(high_window, axis=0))


@pytest.mark.parametrize("seed", range(3))
def test_the_grain_by_running_sums_and_extremes_is_that_of_the_stacked_views(seed):
    from aarecovery.plan import texture
    from aarecovery.spec.sobel import gradient_magnitude

    rng = np.random.default_rng(seed)
    image = _drawn_and_noisy(seed, height=64, width=64) * np.float32(0.2)
    image[32:] += rng.normal(0, 2 / 255, (32, 64, 3)).astype(np.float32)  # grain on half the page
    image = np.clip(image, 0, 1)
    spread, high_spread = _direct_grain_spreads(image)
    quiet = ~texture._spread(gradient_magnitude(image) > texture._QUIET_GRADIENT, texture._QUIET_DISTANCE)
    grainy = ((largest_channel(spread) > texture._GRAIN_RANGE)
              & (largest_channel(high_spread) > texture._GRAIN_HIGH_PASS))
    assert quiet.sum() >= texture._MIN_QUIET and 0 < grainy[quiet].mean() < 1
    assert texture.grain(image) == float(grainy[quiet].mean())
