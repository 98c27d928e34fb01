"""The local plan's passes over the blocks the fit reads give the result of the whole-image passes.

Without maps the GL backend runs the local plan's first two passes over the dilated blocks
and the last over the active ones (``GLBackend._local_factor``); with maps, over the whole
image, as the strength map reads it. The fit reads the factor only in the active blocks (and,
without pure colours or a move towards O, only where F varies around the pixel: elsewhere the
last pass counts no drawn ink), so R must be the same, bit for bit, untiled and tiled, on
both paths.
"""

import numpy as np
import pytest

import aarecovery
from aarecovery.backends.gl.blocks import BLOCK_SIDE, active_mask
from aarecovery.lab import scenes as _scenes
from aarecovery.lab.groundtruth import make_case
from test_local_plan import _FACTOR_TOLERANCE, _pairs


@pytest.fixture(scope="module")
def bars_over_photo():
    """A photo whose top fifth is a flat banner with two dark bars, posterized: a local plan
    with inactive (flat) blocks beside the bars' active ones."""
    scene = _scenes.render("astronaut", 256, 4).copy()
    scene[:256 * 4 // 5] = (0.93, 0.9, 0.8)
    for bar in range(2):
        scene[24 + 48 * bar:48 + 48 * bar, 64:512] = (0.1, 0.1, 0.3)
    return make_case(scene, "posterize", 4, "linear")


@pytest.mark.filterwarnings("ignore::aarecovery.errors.TileSizeWarning")
def test_the_factor_over_the_fitted_blocks_gives_the_whole_images_result(bars_over_photo, gl_path):
    for name, original, filtered, linear in _pairs(bars_over_photo):
        with aarecovery.Engine("gl", gl_path=gl_path) as engine:
            whole, maps = aarecovery.recover(original, filtered, engine=engine, linear=linear, return_maps=True)
            assert engine.last_plan.local is not None, name
        blocks = aarecovery.recover(original, filtered, backend="gl", gl_path=gl_path, linear=linear)
        # Some pixels' repairs are weakened by the factor, and some blocks are inactive.
        assert (maps.beta > 0).mean() < 0.95 and (maps.strength < 1).any(), name
        np.testing.assert_array_equal(blocks, whole, err_msg=name)
        for tile in (40, 64):
            tiled = aarecovery.recover(original, filtered, backend="gl", gl_path=gl_path, linear=linear, tile_size=tile)
            np.testing.assert_array_equal(tiled, whole, err_msg=f"{name}, tile {tile}")


def test_the_factor_is_the_specifications_where_the_fit_reads_it(bars_over_photo, gl_path):
    for name, original, filtered, linear in _pairs(bars_over_photo):
        _, numpy_maps = aarecovery.recover(original, filtered, backend="numpy", linear=linear, return_maps=True)
        with aarecovery.Engine("gl", gl_path=gl_path) as engine:
            aarecovery.recover(original, filtered, engine=engine, linear=linear)
            channels = np.empty(filtered.shape[:2] + (2,), np.float32)
            with engine.context:
                engine._impl._textures["strength_factor"].read_into(channels)
            factor = channels[..., 0]
        pixels = filtered if filtered.ndim == 3 else filtered[..., None]
        active = active_mask(np.ascontiguousarray(pixels)).repeat(BLOCK_SIDE, 0).repeat(BLOCK_SIDE, 1)
        active = active[:factor.shape[0], :factor.shape[1]]
        assert 0.05 < 1 - active.mean() < 0.9, name
        # The region sums reach 8 pixels into the neighbouring blocks: where those hold flat
        # pixels the factor depends on them.
        assert np.abs(numpy_maps.strength[active] - 1).max() > 0.3, name
        # Where F is flat around a pixel its beta is 0 whatever the factor, which the last
        # pass then leaves without its drawn ink (FACTOR_FOR_BETA): the fit reads the rest.
        padded = np.pad(pixels, ((1, 1), (1, 1), (0, 0)), mode="edge")
        height, width = pixels.shape[:2]
        varies = np.zeros((height, width), bool)
        for dy in range(3):
            for dx in range(3):
                varies |= (padded[dy:dy + height, dx:dx + width] != pixels).any(axis=-1)
        read = active & varies
        assert read.sum() > 100, name
        np.testing.assert_allclose(factor[read], numpy_maps.strength[read], atol=_FACTOR_TOLERANCE, err_msg=name)


def test_equally_bright_extremes_tie_whatever_the_rounding(bars_over_photo):
    # Beside the bars, (233, 231, 236) and (233, 230, 237) are a 3 x 3 neighbourhood's
    # brightest by their channel sums, which are equal: the extreme must not be decided by
    # how 8-bit values became floats (u8 / 255 here, u8 * (1 / 255) there, a GPU's unorm
    # conversion), which moved the factor by 0.0026 (an NVIDIA H100 against NumPy).
    from aarecovery.spec.local_plan import LocalStrength
    original = np.rint(bars_over_photo.original * 255).astype(np.uint8)
    local = LocalStrength(textured=0.5)
    divided = local.factor(original / np.float32(255))
    multiplied = local.factor(original * np.float32(1 / 255))
    # Float rounding of the same choice moves it by a few 1e-7.
    np.testing.assert_allclose(divided, multiplied, rtol=0, atol=1e-6)
    rows, cols = np.nonzero(np.ones(original.shape[:2], bool))
    np.testing.assert_array_equal(local.factor_at(original * np.float32(1 / 255), rows, cols),
                                  multiplied.ravel())
