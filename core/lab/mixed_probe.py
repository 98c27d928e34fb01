"""Mixed content for tuning the local plan: a photo with text, a logo and map lines drawn over it.

Each scene is a bundled photo at 8 times O's size (the photo's own pixels repeated twice,
so that O is the photo box-downsampled by 4 as in the real-tools suite) with graphics
rendered at that scale: a banner with text, a caption written straight on the photo, a
flat logo and thin route lines. ``O = box_downsample(scene, 8)``, F a real tool's output
on O, the reference the same tool on the scene, box-downsampled, as
:mod:`aarecovery.lab.realtools` builds its cases. The graphics' coverage gives the two
regions that :func:`measure_regions` scores apart: the graphics (text, logo, lines, with
a two-pixel margin) and the photo (the rest).

The split follows the real-tools suite's: photos and tool operations of the ``tune`` half
for tuning, of ``heldout`` for reporting.
"""

from dataclasses import dataclass

import numpy as np

from ..plan.resample import box_downsample
from .drawings import _serif
from .realtools import FAMILIES, TOOL_FILTERS, render_family

__all__ = ["MIXED_SPLIT", "MixedCase", "mixed_scene", "build_mixed_cases", "measure_regions"]

_K = 8
#: Photos and point-wise tool operations per half (the real-tools suite's halves).
MIXED_SPLIT = {
    "tune": (("coffee", "camera"), ("gegl-threshold", "gegl-levels", "gegl-posterize", "gmic-threshold")),
    "heldout": (("astronaut", "rocket", "chelsea"), ("im-threshold", "im-level", "im-posterize", "gmic-gamma")),
}


@dataclass
class MixedCase:
    """O, F and the reference of one mixed scene under one tool, with its graphics region."""

    photo: str
    filter_name: str
    original: np.ndarray
    filtered: np.ndarray
    reference: np.ndarray
    graphics: np.ndarray


def mixed_scene(photo, seed=0):
    """The scene (float32, ``(H * 8, W * 8, 3)``) and its graphics' coverage at O's size."""
    from PIL import Image, ImageDraw
    base = render_family(photo, 0)
    base = np.repeat(np.repeat(base, _K // FAMILIES[photo].k, axis=0), _K // FAMILIES[photo].k, axis=1)
    height, width = base.shape[:2]
    rng = np.random.default_rng(seed)
    canvas = Image.fromarray(np.rint(base * 255).astype(np.uint8))
    mask = Image.new("L", canvas.size, 0)
    draws = [ImageDraw.Draw(canvas), ImageDraw.Draw(mask)]
    ink = tuple(int(v) for v in rng.integers(0, 90, 3))
    paper = tuple(int(v) for v in rng.integers(200, 256, 3))
    accent = tuple(int(v) for v in rng.integers(0, 256, 3))

    def both(shape, *args, fill, **kwargs):
        getattr(draws[0], shape)(*args, fill=fill, **kwargs)
        getattr(draws[1], shape)(*args, fill=255, **kwargs)

    unit = width / 128
    # A banner with a headline, across the top.
    both("rectangle", [0, 0, width, int(22 * unit)], fill=paper)
    both("text", (int(4 * unit), int(2 * unit)), "Summer Sale 2026", fill=ink, font=_serif(int(14 * unit), True))
    # A caption written straight on the photo.
    both("text", (int(6 * unit), height - int(20 * unit)), "photo: A. Lens", fill=paper, font=_serif(int(9 * unit)))
    # A flat logo: a disc and a triangle.
    cx, cy, radius = width - int(20 * unit), int(40 * unit), int(10 * unit)
    both("ellipse", [cx - radius, cy - radius, cx + radius, cy + radius], fill=accent)
    both("polygon", [(cx - radius // 2, cy + radius // 2), (cx + radius // 2, cy + radius // 2), (cx, cy - radius // 2)],
         fill=paper)
    # Route lines of a map, 1 and 2 O pixels wide.
    points = [(int(x * width), int(y * height)) for x, y in rng.uniform(0.15, 0.85, (5, 2))]
    both("line", points, fill=accent, width=max(1, int(_K * 1.0)), joint="curve")
    both("line", [(0, height // 2), (width, int(height * 0.7))], fill=ink, width=max(1, int(_K * 0.6)))
    scene = np.asarray(canvas, np.float32) / np.float32(255)
    coverage = box_downsample(np.repeat((np.asarray(mask, np.float32) / 255)[..., None], 3, -1), _K, "srgb")[..., 0]
    return scene, coverage


def _grow(mask, radius):
    out = mask.copy()
    for axis in (0, 1):
        grown = out.copy()
        for step in range(1, radius + 1):
            grown[tuple(slice(step, None) if a == axis else slice(None) for a in (0, 1))] |= \
                out[tuple(slice(None, -step) if a == axis else slice(None) for a in (0, 1))]
            grown[tuple(slice(None, -step) if a == axis else slice(None) for a in (0, 1))] |= \
                out[tuple(slice(step, None) if a == axis else slice(None) for a in (0, 1))]
        out = grown
    return out


def build_mixed_cases(half, space="linear", *, photos=None, filters=None):
    """The mixed cases of `half` ("tune" or "heldout"): list of :class:`MixedCase`.

    `photos` and `filters` choose among the half's (default: all of them).
    """
    from .tools import TOOLS
    all_photos, all_filters = MIXED_SPLIT[half]
    photos = tuple(p for p in all_photos if photos is None or p in photos)
    filters = tuple(f for f in all_filters if filters is None or f in filters)
    scenes = {photo: mixed_scene(photo, seed) for seed, photo in enumerate(photos)}
    originals = {photo: np.rint(box_downsample(scene, _K, space) * 255).astype(np.float32) / 255
                 for photo, (scene, _) in scenes.items()}
    cases = []
    for name in filters:
        spec = TOOL_FILTERS[name]
        tool = TOOLS[spec.tool]
        outputs = tool.run(spec.command(1), [originals[p] for p in photos], support=spec.support(1),
                           whole_image=spec.whole_image)
        truths = tool.run(spec.command(_K), [scenes[p][0] for p in photos], support=spec.support(_K),
                          whole_image=spec.whole_image)
        for photo, filtered, truth in zip(photos, outputs, truths):
            graphics = _grow(scenes[photo][1] > 0.02, 2)
            cases.append(MixedCase(photo, name, originals[photo], filtered, box_downsample(truth, _K, space),
                                   graphics))
    return cases


def measure_regions(case, result):
    """Edge-band error reduction of `result` in the graphics and the photo region: dict."""
    from .metrics import edge_band, error_reduction
    band = edge_band(case.original, case.filtered, case.reference)
    return {"graphics": error_reduction(result, case.filtered, case.reference, band & case.graphics),
            "photo": error_reduction(result, case.filtered, case.reference, band & ~case.graphics),
            "all": error_reduction(result, case.filtered, case.reference, band)}
