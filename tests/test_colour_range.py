"""Never invent a colour: what a recovered pixel may show, as properties over random scenes.

The solve is ``R' = beta (alpha R[a] + (1 - alpha) R[b]) + (1 - beta) F`` with alpha and beta
in [0, 1], starting from R = F, where the safe default's pure colours may stand in for
``R[a]`` or ``R[b]`` (the filter's own colour for a thin feature's ink). So after k
iterations each channel of R lies within the range of F over the (2k + 1)-square around the
pixel, widened only by those pure colours. Measured (docs/quality.md), a 3 x 3 bound would
undo the repair itself: the thin lines a filter erased from F are restored, nearer the
supersampled reference than F, from colours F no longer shows next to them.
"""

import numpy as np
import pytest

import aarecovery
from aarecovery import filters
from aarecovery.params import ITERATIONS, SIGMA_D, SIGMA_E
from aarecovery.plan.analysis import analyse
from aarecovery.spec import to_working_space
from aarecovery.spec.passes import recover_working
from scenes import box_downsample, shapes

SLACK = 1.5 / 255
POINT_WISE = [
    ("threshold", {}), ("posterize", {"steps": 3}), ("gamma", {"black": 0.3, "white": 0.45}),
    ("tonemap", {}), ("replacecolour", {}), ("gradientmap", {}), ("colourtogrey", {}),
]


def _window_range(values, radius):
    """Per-channel minimum and maximum over the (2 radius + 1)-square, borders replicated."""
    height, width = values.shape[:2]
    padded = np.pad(values, ((radius, radius), (radius, radius), (0, 0)), mode="edge")
    windows = [padded[radius + dy:radius + dy + height, radius + dx:radius + dx + width]
               for dy in range(-radius, radius + 1) for dx in range(-radius, radius + 1)]
    return np.minimum.reduce(windows), np.maximum.reduce(windows)


def _thin_lines(size, seed, factor=8):
    """Random thin strokes (0.3 to 1.5 px wide) in random colours on a random ground."""
    rng = np.random.default_rng(seed)
    n = size * factor
    y, x = (np.mgrid[0:n, 0:n] + 0.5) / factor
    scene = np.empty((n, n, 3), np.float32)
    scene[:] = rng.random(3)
    for _ in range(6):
        angle, offset = rng.random() * np.pi, rng.random() * size
        width = 0.3 + 1.2 * rng.random()
        distance = np.abs((x - size / 2) * np.cos(angle) + (y - size / 2) * np.sin(angle) - offset + size / 2)
        scene[distance < width / 2] = rng.random(3)
    return np.round(box_downsample(scene, factor) * 255) / 255


def _pairs(count):
    for seed in range(count):
        original = shapes(48, seed=seed).astype(np.float32) / 255 if seed % 2 else _thin_lines(48, seed)
        name, overrides = POINT_WISE[seed % len(POINT_WISE)]
        original = original.astype(np.float32)
        yield f"{name}-{seed}", original, filters.apply(name, original, **overrides).astype(np.float32)


@pytest.mark.parametrize("mode", ["paper", "safe"])
def test_recovery_stays_within_f_over_the_solver_reach(backend, mode):
    """With no pure colours in play, every channel stays in F's range over the solver's reach."""
    reach = ITERATIONS.default
    checked = 0
    # 14 pairs: the colour replacement of shapes (seed 11) has pure colours since the
    # identity prior of neighbourhood filters that keep flat colours (plan/flat_colours.py).
    for label, original, filtered in _pairs(14):
        engine = aarecovery.Engine(backend)
        result = aarecovery.recover(original, filtered, engine=engine, mode=mode)
        if mode == "safe" and engine.last_plan is not None and engine.last_plan.pure_colours is not None:
            continue  # the next test bounds these with the filter's own colours
        low, high = _window_range(filtered, reach)
        outside = ((result < low - SLACK) | (result > high + SLACK)).any(axis=-1)
        assert not outside.any(), f"{label}: {outside.sum()} pixels leave F's range over {2 * reach + 1} px"
        checked += 1
    assert checked >= 3


def test_pure_colours_widen_the_range_only_by_the_filters_own_colours():
    """The specification, in the working space: F over the reach plus the fixed ink colours."""
    iterations = ITERATIONS.default
    with_pure_colours = 0
    for label, original, filtered in _pairs(18):
        alpha = np.ones(original.shape[:2] + (1,), np.float32)
        o_rgba, f_rgba = np.concatenate([original, alpha], -1), np.concatenate([filtered, alpha], -1)
        plan = analyse(o_rgba, f_rgba)
        o_work = to_working_space(o_rgba, blend_space=plan.blend_space)
        f_work = to_working_space(f_rgba, blend_space=plan.blend_space)
        recovered, model = recover_working(o_work, f_work, SIGMA_D.default, SIGMA_E.default, iterations,
                                           max(plan.strength, 0.5), plan.pure_colours, plan.blend_space)
        assert 0 <= model.alpha.min() and model.alpha.max() <= 1, label
        assert 0 <= model.beta.min() and model.beta.max() <= 1, label
        sources = [f_work]
        if model.pure_a is not None:
            with_pure_colours += int(model.pure_a.any() or model.pure_b.any())
            sources += [np.where(model.pure_a[..., None], model.fixed_a, f_work),
                        np.where(model.pure_b[..., None], model.fixed_b, f_work)]
        bounds = [_window_range(values, iterations) for values in sources]
        low = np.minimum.reduce([b[0] for b in bounds])
        high = np.maximum.reduce([b[1] for b in bounds])
        outside = ((recovered < low - 1e-5) | (recovered > high + 1e-5)).any(axis=-1)
        assert not outside.any(), f"{label}: {outside.sum()} pixels leave the bound"
    assert with_pure_colours >= 2, "no scene brought pure colours into play: the test checks less than it says"
