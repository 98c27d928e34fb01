"""JPEG scans of text on tinted or textured paper, made in the tests (no files).

A page of DejaVu Serif lines with wide margins is rendered at 4x, box-filtered in linear
light, saved as JPEG by Pillow (4:2:0) and thresholded on its luma, as ``magick -threshold``
does: the commonest scanning workflow, and the one where O's paper grain and ringing could
reach F's white background.
"""

import io

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from aarecovery.lab.drawings import SERIF_FONT
from aarecovery.plan.resample import box_downsample

_WORDS = "the quick brown fox jumps over a lazy dog while scanners hum along the tinted page".split()
_LUMA = np.array([0.2126, 0.7152, 0.0722], np.float32)


def scan_page(seed, quality, *, size=192, textured=False, factor=4):
    """One page: the lossless original, the JPEG as decoded, and the JPEG file's bytes.

    Parameters
    ----------
    seed : int
        Paper and ink colours, font size, words and line spacing.
    quality : int
        Pillow's JPEG quality.
    size : int
        Page side in pixels.
    textured : bool
        Paper with a low-amplitude grain (a few levels, 2-pixel blobs).

    Returns
    -------
    png, jpeg : ndarray of uint8, shape (size, size, 3)
    data : bytes
    """
    rng = np.random.default_rng(seed)
    paper = rng.uniform([165, 150, 120], [225, 215, 200])
    ink = rng.uniform(10, 60, 3)
    page = Image.new("RGB", (size * factor, size * factor), tuple(int(v) for v in paper))
    draw = ImageDraw.Draw(page)
    font = ImageFont.truetype(SERIF_FONT, int(rng.uniform(9, 14) * factor))
    margin = size // 6
    top = margin
    while top < size - margin - 12:
        draw.text((margin * factor // 2, top * factor), " ".join(rng.choice(_WORDS, 6)), font=font,
                  fill=tuple(int(v) for v in ink))
        top += int(rng.uniform(26, 40))
    scene = np.asarray(page, np.float32) / 255
    if textured:
        blobs = rng.normal(0, 1, (size * factor // 8 + 1,) * 2)
        grain = np.kron(blobs, np.ones((8, 8)))[:size * factor, :size * factor, None]
        scene = np.clip(scene + np.float32(4 / 255) * grain * (scene > 0.4), 0, 1)
    png = np.rint(np.clip(box_downsample(scene, factor, "linear"), 0, 1) * 255).astype(np.uint8)
    buffer = io.BytesIO()
    Image.fromarray(png).save(buffer, format="JPEG", quality=quality)
    with Image.open(io.BytesIO(buffer.getvalue())) as decoded:
        jpeg = np.asarray(decoded.convert("RGB"))
    return png, jpeg, buffer.getvalue()


def threshold(image, level=0.55):
    """Black or white by the luma of the encoded values, as ``magick -threshold 55%``."""
    luma = image.astype(np.float32) / 255 @ _LUMA
    return np.repeat(np.where(luma > level, 255, 0).astype(np.uint8)[..., None], 3, axis=-1)


def _all_around(mask, radius):
    height, width = mask.shape
    padded = np.pad(mask, radius, constant_values=True)
    out = np.ones_like(mask)
    for dy in range(2 * radius + 1):
        for dx in range(2 * radius + 1):
            out &= padded[dy:dy + height, dx:dx + width]
    return out


def haze(recovered, filtered, clean, tolerance=10, radius=2, paper_range=6):
    """Pixels of bare paper, white in F, that R made darker than F by more than `tolerance` levels.

    Bare paper: F is white and the lossless original `clean` spans at most `paper_range`
    levels in the (2 `radius` + 1)^2 window around the pixel, so no ink is near (a light
    stroke the threshold erased from F is ink, and restoring it is the method's business).
    """
    quiet = clean.astype(np.int64)
    window = [np.roll(np.roll(quiet, dy, 0), dx, 1) for dy in range(-radius, radius + 1)
              for dx in range(-radius, radius + 1)]
    paper = (np.max(window, axis=0) - np.min(window, axis=0)).max(axis=-1) <= paper_range
    flat = _all_around(filtered.min(axis=-1) >= 250, radius) & paper
    darker = (filtered.astype(np.int64) - recovered.astype(np.int64)).max(axis=-1) > tolerance
    return int((flat & darker).sum())
