"""The real-tools suite's later families and tools, run for real on small images.

Mixed content (graphics over photos) with its regions, scans of text with their paper
background and the haze measure, comics with screentone, and the OpenCV and Pillow filters.
"""

import numpy as np
import pytest

from aarecovery.lab import realtools
from aarecovery.lab.comics import COMICS
from aarecovery.lab.metrics import HAZE_TOLERANCE, flat_areas, haze_pixels
from aarecovery.lab.overlays import MIXED, SCANS, overlay_regions, paper_background
from aarecovery.lab.tools import TOOLS
from test_realtools import require_tool

_NEW_TOOLS = ("opencv", "pillow")
_NEW_FILTERS = [name for name, f in realtools.TOOL_FILTERS.items() if f.tool in _NEW_TOOLS]


def test_comics_are_deterministic_and_hard_edged():
    for name, render in COMICS.items():
        first, second = render(24, 24, 4), render(24, 24, 4)
        assert first.shape == (96, 96, 3) and first.dtype == np.float32
        np.testing.assert_array_equal(first, second)
        np.testing.assert_array_equal(np.rint(first * 255) / 255, first.astype(np.float64), err_msg=name)
        assert len(np.unique(first.reshape(-1, 3), axis=0)) <= 8, name
        # Screentone: a large share of the page is dots and hatching, not flat colour.
        assert 0.1 < (first.min(axis=-1) < 0.5).mean() < 0.7, name


@pytest.mark.parametrize("name", [*MIXED, *SCANS])
def test_mixed_and_scan_scenes_are_deterministic(name):
    family = realtools.FAMILIES[name]
    (scene, mask), (again, mask_again) = realtools.render_scene(name, 32), realtools.render_scene(name, 32)
    np.testing.assert_array_equal(scene, again)
    np.testing.assert_array_equal(mask, mask_again)
    assert scene.dtype == np.float32 and mask.shape == scene.shape[:2]
    assert scene.shape[0] % family.k == 0 and scene.shape[1] % family.k == 0
    np.testing.assert_array_equal(np.rint(scene * 255) / 255, scene.astype(np.float64))
    assert 0.02 < mask.mean() < 0.5, name  # something drawn, most of the image left to the photo or paper


@pytest.mark.parametrize("name", list(MIXED))
def test_region_masks_partition_the_mixed_images(name):
    family = realtools.FAMILIES[name]
    scene, mask = realtools.render_scene(name, 32)
    regions = overlay_regions(mask, family.k)
    assert set(regions) == {"text/graphics", "photo"}
    graphics, photo = regions["text/graphics"], regions["photo"]
    assert graphics.shape == (scene.shape[0] // family.k, scene.shape[1] // family.k)
    assert not (graphics & photo).any() and (graphics | photo).all()
    assert graphics.any() and photo.any()
    # A pixel is text/graphics exactly where the overlay reaches into its k x k block.
    y, x = np.argwhere(mask)[0]
    assert graphics[y // family.k, x // family.k]


def test_paper_background_keeps_a_pixel_away_from_ink():
    ink = np.zeros((32, 32), bool)
    ink[9, 10] = True  # one scene pixel of ink, in O pixel (2, 2) at k = 4
    paper = paper_background(ink, 4)
    assert paper.shape == (8, 8) and paper.sum() == 64 - 9
    assert not paper[1:4, 1:4].any() and paper[0, 0] and paper[4, 4]


def test_haze_counts_a_synthetic_haze_and_is_zero_on_f():
    filtered = np.ones((20, 30, 3), np.float32)  # a thresholded page: white paper ...
    filtered[8:12, 5:25] = 0  # ... and a line of black ink
    background = np.ones((20, 30), bool)
    background[7:13, 4:26] = False
    assert haze_pixels(filtered, filtered, background) == 0
    hazy = filtered.copy()
    hazy[0:3, 0:10] = (0.93, 0.9, 0.8)  # 30 pixels of the paper's tint painted over the white
    hazy[15, 0] = 1 - HAZE_TOLERANCE / 2  # within the tolerance: not haze
    hazy[8:12, 5:8] = 0.5  # on the ink, not on the paper: not counted
    hazy[18, 29] = (1, 1, 1)  # unchanged
    assert haze_pixels(hazy, filtered, background) == 30
    lighter = filtered.copy()
    lighter[8:12, 5:25] = 0.2
    assert haze_pixels(lighter, filtered, np.ones((20, 30), bool)) == 0  # only darker counts


def test_flat_areas_are_where_fs_3x3_neighbourhood_is_one_8_bit_colour():
    filtered = np.ones((12, 16, 3), np.float32)  # a thresholded page's white ...
    filtered[5, 4:12] = 0  # ... a line of ink ...
    filtered[10, 14] = (1, 1, 254 / 255)  # ... and one blue level off white (a grain speck)
    flat = flat_areas(filtered)
    assert flat.shape == (12, 16) and flat[0, 0] and flat[8, 8]
    assert not flat[4:7, 3:13].any()  # the line and every pixel beside it
    assert not flat[9:12, 13:16].any() and flat[9, 12]
    # Half an 8-bit level apart is still flat; the haze counted on F's flat paper only.
    filtered[0, 0] = 1 - 0.4 / 255
    assert flat_areas(filtered)[0, 1]
    hazy = filtered.copy()
    hazy[0:2, 0:16] = 0.9  # 32 paper pixels greyed: 32 on the paper, 32 of them where F is flat
    hazy[4, 4] = 0.9  # beside the ink, where F is not flat: darker, but not haze
    assert haze_pixels(hazy, filtered, np.ones((12, 16), bool)) == 33
    assert haze_pixels(hazy, filtered, flat_areas(filtered)) == 32


def test_cases_carry_regions_and_paper():
    require_tool("opencv")
    suite = realtools.RealToolsSuite("marks", ("poster", "memo", "manga"), ("cv-threshold",), 24,
                                     {"poster": ("linear",), "memo": ("srgb",), "manga": ("srgb",)})
    cases = realtools.build_cases(suite, "tune")
    assert len(cases) == 6
    for case in cases:
        kind = realtools.FAMILIES[case.family].kind
        assert (case.regions is not None) == (kind == "mixed")
        assert (case.paper is not None) == (kind == "scan")
        if case.regions is not None:
            assert case.regions["photo"].shape == case.original.shape[:2]
        if case.paper is not None:
            assert case.paper.shape == case.original.shape[:2] and case.paper.mean() > 0.2
    scan = [c for c in cases if c.family == "memo" and c.quality is not None]
    assert scan[0].quality in realtools.FAMILIES["memo"].jpeg_qualities


def _photo_tile():
    from aarecovery.lab.realtools import render_family
    scene = render_family("coffee", 64)
    return np.ascontiguousarray(scene[100:140, 200:260])


@pytest.mark.parametrize("name", _NEW_FILTERS)
def test_new_tools_run_and_their_groups_are_right(name):
    """Each OpenCV and Pillow filter runs for real, and acts as its group says: a point-wise
    filter commutes with shuffling the pixels (the shuffle keeps the histogram, so per-image
    state such as equalization's is the same), a neighbourhood filter does not."""
    spec = realtools.TOOL_FILTERS[name]
    tool = require_tool(spec.tool)
    image = _photo_tile()
    order = np.random.default_rng(3).permutation(image.shape[0] * image.shape[1])
    shuffled = image.reshape(-1, 3)[order].reshape(image.shape)
    output, output_of_shuffled = tool.run(spec.command(), [image, shuffled], whole_image=spec.whole_image)
    assert output.shape == image.shape and output.dtype == np.float32
    assert 0 <= output.min() and output.max() <= 1
    assert np.abs(output - image).max() > 4 / 255, "the filter changed nothing"
    commutes = np.array_equal(output.reshape(-1, 3)[order].reshape(image.shape), output_of_shuffled)
    pointwise = spec.group not in realtools.NEIGHBOURHOOD_GROUPS
    assert commutes == pointwise, (name, spec.group)


def test_opencv_filters_give_what_opencv_gives():
    tool = require_tool("opencv")
    import cv2
    image = _photo_tile()
    pixels = np.rint(image * 255).astype(np.uint8)
    threshold = tool.run(realtools.TOOL_FILTERS["cv-threshold"].command(), [image])[0]
    np.testing.assert_array_equal(threshold, (pixels > 127).astype(np.float32))
    turbo = tool.run(realtools.TOOL_FILTERS["cv-turbo"].command(), [image])[0]
    grey = cv2.cvtColor(pixels, cv2.COLOR_RGB2GRAY)
    expected = cv2.applyColorMap(grey, cv2.COLORMAP_TURBO)[..., ::-1]
    np.testing.assert_array_equal(np.rint(turbo * 255).astype(np.uint8), expected)
    spec = realtools.TOOL_FILTERS["cv-bilateral"]
    bilateral = tool.run(spec.command(scale=2), [image])[0]
    np.testing.assert_array_equal(np.rint(bilateral * 255).astype(np.uint8),
                                  cv2.bilateralFilter(pixels, -1, 40, spec.lengths["sigma"] * 2))


def test_pillow_filters_give_what_pillow_gives():
    from PIL import Image, ImageOps
    tool = require_tool("pillow")
    image = _photo_tile()
    pixels = np.rint(image * 255).astype(np.uint8)
    luma, blue, red = Image.fromarray(pixels).convert("YCbCr").split()
    ycbcr_equalized = Image.merge("YCbCr", (ImageOps.equalize(luma), blue, red)).convert("RGB")
    for name, expected in (("pil-posterize", ImageOps.posterize(Image.fromarray(pixels), 2)),
                           ("pil-solarize", ImageOps.solarize(Image.fromarray(pixels), 160)),
                           ("pil-ycbcr-equalize", ycbcr_equalized)):
        result = tool.run(realtools.TOOL_FILTERS[name].command(), [image])[0]
        np.testing.assert_array_equal(np.rint(result * 255).astype(np.uint8), np.asarray(expected), err_msg=name)


def test_python_tools_say_what_to_install(monkeypatch):
    import importlib.util
    tool = TOOLS["opencv"]
    monkeypatch.setattr(importlib.util, "find_spec", lambda name: None)
    assert not tool.available()
    with pytest.raises(RuntimeError, match="opencv-python-headless"):
        tool.run(["threshold", "value=127"], [np.zeros((4, 4, 3), np.float32)])


def test_summary_prints_regions_haze_and_neighbourhood_filters():
    from aarecovery.lab.realeval import run_realtools, summarize_realtools
    from aarecovery.lab.realreport import format_realtools
    for name in ("opencv", "imagemagick"):
        require_tool(name)
    suite = realtools.RealToolsSuite("regions", ("banner", "letter", "comicstrip"),
                                     ("cv-edge-preserving", "im-threshold-55"), 32,
                                     {"banner": ("linear",), "letter": ("srgb",), "comicstrip": ("srgb",)}, (85,))
    results, missing_tools, _ = run_realtools(suite, "heldout", peers=False)
    assert not missing_tools and len(results) == 3 * 2 * 2
    mixed = [r for r in results if r.kind == "mixed"]
    assert mixed and all(set(r.region_reduction) == {"text/graphics", "photo"} for r in mixed)
    scans = [r for r in results if r.kind == "scan"]
    assert scans and all(r.haze["F"] == 0 and r.darker["F"] == 0 and 0 < r.flat_paper_pixels <= r.paper_pixels
                         and r.haze["R"] <= r.darker["R"] and "reference" in r.darker for r in scans)
    summary = summarize_realtools(results)
    assert summary["mixed"]["text/graphics"][1] > 0 and summary["neighbourhood_cases"] > 0
    assert "png" in summary["haze"] and "jpeg" in summary["haze"]
    table = format_realtools(results, half="heldout")
    for line in ("mixed content under every filter, text/graphics regions' edge band",
                 "mixed content under every filter, photo regions' edge band",
                 "mixed content under point-wise filters, whole edge band",
                 "neighbourhood filters (unsharp, bilateral, abstraction, detail)", "scans: haze,",
                 "== mixed content per family", "== scans: haze per filter"):
        assert line in table, line
    assert "banner " in table.split("== mixed content per family")[1]
    assert "im-threshold-55 " in table.split("== scans: haze per filter")[1]


def test_the_mixed_summary_says_by_how_much_the_worst_region_is_worse():
    from aarecovery.lab.realeval import RealCaseResult, summarize_mixed

    def case(name, photo):
        result = RealCaseResult("banner", "linear", name, "mixed", 0.1)
        result.psnr_band, result.reduction = {"F": 20.0, "R": 21.0, "paper": 21.0}, {"R": 0.3, "paper": 0.2}
        result.region_error = {"text/graphics": 1e-3, "photo": 1e-3}
        result.region_reduction = {"text/graphics": {"R": 0.4, "paper": 0.5}, "photo": {"R": photo, "paper": -1.0}}
        return result

    means, cases, worse, worst_db = summarize_mixed([case("a", 0.2), case("b", -0.01), case("c", -0.1)])["photo"]
    assert cases == 3 and len(worse) == 2 and means["R"] == pytest.approx(0.03)
    # MSE(R) = 1.1 MSE(F) in the worst: 0.41 dB.
    assert worst_db == pytest.approx(10 * np.log10(1.1))
    assert summarize_mixed([case("a", 0.2)])["photo"][2:] == ([], 0.0)
