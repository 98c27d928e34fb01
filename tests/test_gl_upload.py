"""8-bit RGB uploaded as packed rows and expanded on the GPU (``unpack_rgb8.comp``) gives the
same textures and results as the driver's upload, on the compute path where GPUs use it."""

import numpy as np
import pytest

import aarecovery
from scenes import luminance, shapes

pytestmark = pytest.mark.gl


def _pairs():
    structured = shapes(72, seed=5, noise=0.02)
    grey = (luminance(structured / np.float32(255)) * 255).astype(np.uint8)
    # Odd widths: rows of 3 bytes a pixel do not end on 4-byte words.
    odd = structured[:61, :45]
    yield "rgb-threshold", structured, np.where(structured > 110, 255, 0).astype(np.uint8)
    yield "odd-rgb-posterize", odd, (odd // 64 * 85).astype(np.uint8)
    yield "rgb-to-grey", structured, np.where(grey > 120, 255, 0).astype(np.uint8)
    yield "grey-to-rgb", grey, np.stack([grey, 255 - grey, grey // 2], -1)


@pytest.mark.parametrize("name, original, filtered", list(_pairs()), ids=[name for name, *_ in _pairs()])
def test_unpacked_rgb8_equals_the_drivers_upload(name, original, filtered):
    results = {}
    for unpack in (False, True):
        with aarecovery.Engine("gl", gl_path="compute") as engine:
            engine._impl.unpack_rgb8_on_gpu = unpack
            for mode in ("paper", "safe"):
                results[unpack, mode] = aarecovery.recover(original, filtered, engine=engine, mode=mode)
            # Tiles upload windows of the images.
            results[unpack, "tiled"] = aarecovery.recover(original, filtered, engine=engine, tile_size=24)
            engine.set_images(original, filtered)
            packed = {key for key in engine._impl._pixel_buffers if key.startswith("packed_")}
            expected = {f"packed_{which}" for which, image in (("original", original), ("filtered", filtered))
                        if unpack and image.ndim == 3}
            assert packed == expected, name
            for which, image in (("original", original), ("filtered", filtered)):
                texture = engine.texture(which).texture
                texels = np.empty((image.shape[0], image.shape[1], texture.components), np.uint8)
                with engine.context:
                    texture.read_into(texels)
                channels = image.shape[2] if image.ndim == 3 else 1
                np.testing.assert_array_equal(texels[..., :channels], image.reshape(texels.shape[:2] + (channels,)))
                if unpack and channels == 3:
                    assert (texels[..., 3] == 255).all()
    for mode in ("paper", "safe", "tiled"):
        np.testing.assert_array_equal(results[True, mode], results[False, mode], err_msg=f"{name} {mode}")
