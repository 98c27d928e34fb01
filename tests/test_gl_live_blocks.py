"""With pure colours the fit and the Jacobi steps skip blocks where nothing can change.

The pure colours' fit needs O's active blocks, about twice F's, but where the classification
runs on the GPU (GL 4.3) it covers only those near a pixel that could be a thin feature's ridge
or where F varies (``pure_colour_blocks.glsl``), and then flags the blocks where a step can
give other than F, and those its gathers read (``live_blocks.glsl``); the steps run over
them alone and the rest of R is F. Both must be exactly their NumPy twins
(``blocks.pure_colour_mask``, ``blocks.live_mask`` on the fit's own model); O's edges that F
lost without a thin feature are neither fitted nor stepped; and R is the same as without
them: equal to the NumPy specification. The paper's steps keep F's active blocks.
"""

import dataclasses

import numpy as np
import pytest

import aarecovery
from aarecovery.backends.gl.blocks import BLOCK_SIDE, active_mask, live_mask, pure_colour_mask
from aarecovery.lab import scenes as _scenes
from aarecovery.lab.groundtruth import make_case
from aarecovery.params import Parameters
from aarecovery.plan import make_plan
from parity import assert_results_agree

pytestmark = pytest.mark.gl


@pytest.fixture(scope="module")
def thin_text_and_a_lost_edge():
    """Thresholded text (thin strokes vanish from F: pure colours) beside a soft edge between
    two light greys that both threshold to white: O has edges there, F none, and no thin
    feature, so neither the fit nor a step needs those blocks. Float images: the working
    textures are float, read back exactly."""
    case = make_case(_scenes.render("text", 48, 4), "threshold", 4, "linear")
    height = case.original.shape[0]
    ramp = np.clip((np.arange(48) - 23.5) / 3 + 0.5, 0, 1).astype(np.float32)
    panel = np.broadcast_to((0.75 + 0.15 * ramp)[None, :, None], (height, 48, 3))
    original = np.concatenate([case.original, panel], axis=1).astype(np.float32)
    filtered = np.concatenate([case.filtered, np.ones_like(panel)], axis=1).astype(np.float32)
    return original, filtered


def _read(texture, channels=4):
    width, height = texture.size
    return np.frombuffer(texture.read(), np.float32).reshape(height, width, channels)


def _fitted(mask, shape):
    return np.kron(mask, np.ones((BLOCK_SIDE, BLOCK_SIDE), bool))[:shape[0], :shape[1]]


def test_live_blocks_are_the_specifications_and_skip_blocks(thin_text_and_a_lost_edge, gl_path):
    original, filtered = thin_text_and_a_lost_edge
    plan = dataclasses.replace(make_plan(original, filtered, Parameters()), pure_colour_blocks=True)
    with aarecovery.Engine("gl", gl_path=gl_path) as engine:
        recovered = aarecovery.recover(original, filtered, engine=engine, plan=plan)
        assert engine.last_plan.pure_colours is not None
        impl = engine._impl
        with engine.context:
            assert impl._classifier.compute  # llvmpipe and every GL 4.3 device
            model = _read(impl._work("model"))
            constant = _read(impl._work("jacobi_constant"))
            original_work = _read(impl._work("original_work"))
            changed = (constant != _read(impl._work("filtered_work"))).any(axis=-1)
            grid = impl._lists["live"].grid
            flags = np.frombuffer(impl._pixel_buffers["live_flags"].read(), np.uint32)[:grid[0] * grid[1]]
            fitted_flags = np.frombuffer(impl._lists["pure_colours"].flags.read(), np.uint32)[:grid[0] * grid[1]]
    fitted = pure_colour_mask(original_work, original, filtered) != 0
    np.testing.assert_array_equal(fitted_flags.reshape(grid[1], grid[0]) != 0, fitted)
    expected = live_mask(model[..., 1], model[..., 2], changed & _fitted(fitted, model.shape), _fitted(fitted, model.shape))
    np.testing.assert_array_equal(flags.reshape(grid[1], grid[0]) != 0, expected)
    assert not (expected & ~fitted).any()
    # The lost edge's blocks (the panel's middle column of blocks): O's active, not fitted.
    assert active_mask(original)[:, -2].all() and not fitted[:, -2].any()
    assert changed.any() and expected.sum() <= fitted.sum() < active_mask(original).sum()
    assert_results_agree(recovered, aarecovery.recover(original, filtered, backend="numpy"))


def test_the_papers_steps_keep_fs_blocks(thin_text_and_a_lost_edge, gl_path):
    original, filtered = thin_text_and_a_lost_edge
    with aarecovery.Engine("gl", gl_path=gl_path) as engine:
        recovered = aarecovery.recover(original, filtered, engine=engine, mode="paper")
        assert "live" not in engine._impl._lists
    assert_results_agree(recovered, aarecovery.recover(original, filtered, backend="numpy", mode="paper"))


def test_live_mask_flags_the_blocks_of_both_gathers():
    beta = np.zeros((32, 48), np.float32)
    code = np.zeros((32, 48), np.float32)
    beta[15, 16] = 0.5  # in block (0, 1); extreme a up-left, in block (0, 0), b to its right
    code[15, 16] = (-1 + 1) + 3 * (-1 + 1) + 9 * (1 + 1) + 27 * (0 + 1) + 162
    changed = np.zeros_like(beta, bool)
    changed[20, 40] = True
    fitted = np.ones_like(changed)
    assert live_mask(beta, code, changed, fitted).tolist() == [[True, True, False], [False, False, True]]
    assert not live_mask(beta, code, changed, ~fitted).any()
