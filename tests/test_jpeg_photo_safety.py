"""JPEG photos, in colour and in grey, under point-wise and sharpening filters: the safe default
never ends worse than the filtered image (the issue's "JPEG photos under threshold or levels
come out 2-4 dB worse than F")."""

import io

import numpy as np
import pytest
from PIL import Image

import aarecovery
from aarecovery import filters
from aarecovery.lab import scenes as _scenes
from aarecovery.lab.groundtruth import make_case
from aarecovery.lab.metrics import edge_band, psnr


def _jpeg(image, quality):
    buffer = io.BytesIO()
    Image.fromarray(np.rint(np.clip(image, 0, 1) * 255).astype(np.uint8)).save(buffer, format="JPEG", quality=quality)
    buffer.seek(0)
    with Image.open(buffer) as decoded:
        return np.asarray(decoded.convert("RGB")).astype(np.float32) / 255


@pytest.mark.parametrize("grey", [False, True], ids=["colour", "grey"])
@pytest.mark.parametrize("name", ["astronaut", "coffee", "chelsea"])
def test_a_jpeg_photo_never_ends_worse_than_f(name, grey):
    """F is the filter of the decoded JPEG; the reference is the filter of the scene, so F
    carries the compression error, which no repair removes: the test is that R adds none."""
    scene = _scenes.render(name, 64, 4)
    if grey:
        scene = np.repeat(scene.mean(axis=-1, keepdims=True), 3, axis=-1)
    losses = {}
    with aarecovery.Engine("numpy") as engine:
        for filter_name in ("threshold", "gamma", "posterize", "unsharp"):
            case = make_case(scene, filter_name, 4, "linear")
            band = edge_band(case.original, case.filtered, case.reference)
            for quality in (75, 90):
                original = _jpeg(case.original, quality)
                filtered = filters.apply(filter_name, original)
                result = aarecovery.recover(original, filtered, engine=engine)
                loss = psnr(filtered, case.reference, band) - psnr(result, case.reference, band)
                if loss > 0.1:
                    losses[filter_name, quality] = round(float(loss), 2)
    assert not losses, losses
