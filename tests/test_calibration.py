"""Self-calibration of the strength (``aarecovery.plan.calibration``) on textured images."""

import numpy as np

from aarecovery.plan.calibration import calibrate_strength
from aarecovery.plan.pointwise import fit_pointwise
from aarecovery.params import ITERATIONS, SIGMA_D, SIGMA_E
from scenes import shapes as shapes_uint8

PARAMETERS = (SIGMA_D.default, SIGMA_E.default, ITERATIONS.default)


def shapes(size, seed, noise):
    return (shapes_uint8(size, seed=seed, noise=noise) / 255).astype(np.float32)


def _fitted(original, filtered):
    return fit_pointwise(original, filtered, np.ones(original.shape[:2], bool))


def test_the_grid_is_refined_halfway_towards_the_better_neighbour():
    original = shapes(96, seed=3, noise=0.02)
    filtered = np.where(original.mean(axis=-1, keepdims=True) > 0.5, 1.0, 0.0).repeat(3, -1).astype(np.float32)
    strength, errors = calibrate_strength(original, _fitted(original, filtered), filtered, "linear", *PARAMETERS)
    grid = (0.0, 0.25, 0.5, 1.0)
    assert set(grid) < set(errors) and len(errors) == 5
    best = grid.index(min(grid, key=errors.get))
    closer = min((grid[i] for i in (best - 1, best + 1) if 0 <= i < 4), key=errors.get)
    assert set(errors) - set(grid) == {(grid[best] + closer) / 2}
    assert strength == min(errors, key=errors.get) and strength > 0, errors


def test_nothing_to_repair_chooses_zero():
    """The identity filter: F is already the target at half resolution."""
    original = shapes(96, seed=4, noise=0.02)
    strength, errors = calibrate_strength(original, _fitted(original, original), original, "linear", *PARAMETERS)
    assert strength == 0.0 and errors[0.0] == min(errors.values()), errors
