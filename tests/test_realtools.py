"""The real-tools bench: its tool runner, ground truth, split and report, run for real on small images.

The tools (GEGL, G'MIC, ImageMagick) are Debian packages that packaging/test.sh installs,
OpenCV a pip package of the test extra; a missing one fails these tests in CI (CI set) and
skips them loudly elsewhere.
"""

import dataclasses
import os
import subprocess

import numpy as np
import pytest

import aarecovery
from aarecovery import Decision
from aarecovery.lab import realtools
from aarecovery.lab.drawings import DRAWINGS
from aarecovery.lab.metrics import outside_local_range
from aarecovery.lab.peers import joint_bilateral
from aarecovery.lab.realeval import run_realtools, summarize_realtools
from aarecovery.lab.realreport import format_realtools
from aarecovery.lab.tools import TOOLS, read_float_rgb, write_png8


def require_tool(name):
    tool = TOOLS[name]
    if not tool.available():
        message = f"{tool.label} is not installed ({tool.install_hint()}; packaging/test.sh installs it)"
        if os.environ.get("CI"):
            pytest.fail(message)
        pytest.skip("REAL-TOOLS TEST NOT RUN: " + message)
    return tool


def real_case(family, filter_name, space, half="tune"):
    """The PNG case of the real-tools suite's `family` made in `space` under `filter_name`
    (its tool required), and its edge band's text and graphics and photo regions."""
    from aarecovery.lab.metrics import edge_band
    require_tool(realtools.TOOL_FILTERS[filter_name].tool)
    suite = dataclasses.replace(realtools.REAL_FULL, families=(family,), filters=(filter_name,),
                                spaces={family: (space,)})
    (case,) = realtools.build_cases(suite, half, jpeg=False)
    band = edge_band(case.original, case.filtered, case.reference)
    return case, band & case.regions["text/graphics"], band & case.regions["photo"]


def _ramp(width=64):
    """Every 8-bit grey level 0..255 across, in four colour rows: (4, 64, 3) in steps of 1/255 and 4/255."""
    rng = np.random.default_rng(5)
    image = rng.integers(0, 256, (6, width, 3)).astype(np.float32) / 255
    image[0] = (np.arange(width, dtype=np.float32) * 4 % 256 / 255)[:, None]
    return image


def _direct(tool, arguments, image, tmp_path):
    """The tool run by hand on one file, without the runner's batching, read back independently."""
    source, target = tmp_path / "in.png", tmp_path / "out.png"
    write_png8(source, image)
    if tool.name == "gegl":
        command = ["gegl", "--", "gegl:load", f"path={source}", *arguments, "gegl:png-save", f"path={target}",
                   "bitdepth=16"]
    elif tool.name == "gmic":
        target = tmp_path / "out.tif"
        command = ["gmic", "-v", "-", str(source), *arguments, "-o", f"{target},float"]
    else:
        command = [tool.executable(), str(source), *arguments, "-depth", "16", f"PNG48:{target}"]
    subprocess.run(command, check=True, capture_output=True)
    return read_float_rgb(target, full_scale=255)


@pytest.mark.parametrize("name, arguments", [("gegl", ["gegl:threshold", "value=0.5"]),
                                             ("gmic", ["-threshold", "40%", "-mul", "255"]),
                                             ("imagemagick", ["-threshold", "50%"])])
def test_runner_gives_what_the_tool_gives(name, arguments, tmp_path):
    tool = require_tool(name)
    image = _ramp()
    other = np.ascontiguousarray(image[:, ::-1])
    batch = tool.run(arguments, [image, other])
    assert batch[0].shape == image.shape and batch[0].dtype == np.float32
    np.testing.assert_allclose(batch[0], _direct(tool, arguments, image, tmp_path), atol=1e-6)
    np.testing.assert_allclose(batch[1], _direct(tool, arguments, other, tmp_path), atol=1e-6)


def test_imagemagick_batches_larger_than_its_pixel_cache_run_in_pieces(monkeypatch):
    """A batch over the pixels one command line may hold (Debian's policy caps ImageMagick's
    pixel cache) runs in consecutive pieces and gives what each image alone gives."""
    from aarecovery.lab import tools

    tool = require_tool("imagemagick")
    image = _ramp()
    images = [image, np.ascontiguousarray(image[:, ::-1]), np.ascontiguousarray(image[::-1]), image[:5]]
    pixels = image.shape[0] * image.shape[1]
    chunks = tools._imagemagick_chunks(images, 2 * pixels)
    assert [list(chunk) for chunk in chunks] == [[0, 1], [2, 3]]
    assert [list(chunk) for chunk in tools._imagemagick_chunks(images, pixels // 2)] == [[0], [1], [2], [3]]
    monkeypatch.setattr(tools, "_IMAGEMAGICK_PIXELS", 2 * pixels)
    batch = tool.run(["-threshold", "50%"], images)
    assert len(batch) == len(images)
    for result, source in zip(batch, images):
        np.testing.assert_array_equal(result, tool.run(["-threshold", "50%"], [source])[0])


@pytest.mark.parametrize("name", ["gegl", "gmic", "imagemagick"])
def test_identity_command_returns_the_input(name):
    tool = require_tool(name)
    image = _ramp()
    grey = np.repeat(image[..., :1], 3, axis=2)
    for result, source in zip(tool.run([], [image, grey]), (image, grey)):
        np.testing.assert_allclose(result, source, atol=1e-6)


def test_gegl_atlas_keeps_spatial_operations_apart():
    tool = require_tool("gegl")
    spec = realtools.TOOL_FILTERS["gegl-unsharp"]
    rng = np.random.default_rng(1)
    a = np.rint(rng.random((20, 30, 3)) * 255).astype(np.float32) / 255
    b = np.zeros((12, 40, 3), np.float32)
    alone = tool.run(spec.command(), [a], support=spec.support())[0]
    together = tool.run(spec.command(), [b, a], support=spec.support())[1]
    # GEGL's Gaussian is recursive (IIR): a black neighbour 6 sigma away still moves a pixel
    # by up to 1.7e-4, a twentieth of an 8-bit step.
    np.testing.assert_allclose(together, alone, atol=0.5 / 255)


def test_tool_conventions_measured_in_the_docs():
    # docs/real-tools.md: GEGL thresholds sRGB-encoded luminance (babl's
    # D50 weights); ImageMagick 6 thresholds the Rec. 709 luma of encoded values.
    from aarecovery.colour import linear_to_srgb, srgb_to_linear
    image = _ramp()
    gegl = require_tool("gegl").run(["gegl:threshold", "value=0.5"], [image])[0]
    luminance = linear_to_srgb(srgb_to_linear(image) @ np.array([0.22248840, 0.71690369, 0.06060791], np.float32))
    np.testing.assert_array_equal(gegl[..., 0], (luminance >= 0.5).astype(np.float32))
    magick = require_tool("imagemagick").run(["-threshold", "50%"], [image])[0]
    luma = image @ np.array([0.2126, 0.7152, 0.0722], np.float32)
    np.testing.assert_array_equal(magick[..., 0], (luma > 0.5).astype(np.float32))


def test_split_is_disjoint_and_covers_each_suite():
    for suite in (realtools.REAL_QUICK, realtools.REAL_FULL):
        tune, heldout, every = (set(suite.cases(h)) for h in realtools.HALVES)
        assert tune and heldout and not tune & heldout
        assert every == tune | heldout
        for family, _, filter_name in every:
            assert realtools.FAMILIES[family].half == realtools.TOOL_FILTERS[filter_name].half
        assert {c[0] for c in every} == set(suite.families)
        assert {c[2] for c in every} == set(suite.filters)
    # Each half has drawings and photos, and every tool has operations in both halves.
    for half in ("tune", "heldout"):
        assert {f.kind for f in realtools.FAMILIES.values() if f.half == half} == {"drawing", "photo", "mixed", "scan"}
        assert {f.tool for f in realtools.TOOL_FILTERS.values() if f.half == half} == set(TOOLS)
    with pytest.raises(Exception, match="half must be one of"):
        realtools.REAL_QUICK.cases("test")


def test_jpeg_quality_is_fixed_by_the_case_name():
    suite = realtools.REAL_FULL
    qualities = {suite.jpeg_quality(*case) for case in suite.cases("all") if realtools.FAMILIES[case[0]].kind != "scan"}
    assert qualities == set(suite.jpeg_qualities)
    # Scans have their own range, the scanning workflow's.
    scans = {suite.jpeg_quality(*case) for case in suite.cases("all") if realtools.FAMILIES[case[0]].kind == "scan"}
    assert scans == set(realtools.FAMILIES["memo"].jpeg_qualities) and min(scans) == 75 and max(scans) == 95
    assert suite.jpeg_quality("maps", "srgb", "gegl-threshold") == suite.jpeg_quality("maps", "srgb", "gegl-threshold")


def test_identity_tools_give_a_reference_equal_to_o(monkeypatch):
    # With an identity command the reference is box(scene) and F is O: both equal O within
    # O's 8-bit rounding (and the 16-bit or float read-back).
    for name in TOOLS:
        require_tool(name)
        monkeypatch.setitem(realtools.TOOL_FILTERS, f"{name}-identity",
                            realtools.ToolFilter(f"{name}-identity", name, (), "curves", "tune"))
    suite = realtools.RealToolsSuite("identity", ("starburst", "text"), tuple(f"{n}-identity" for n in TOOLS), 24,
                                     {"starburst": ("linear", "srgb")})
    cases = realtools.build_cases(suite, "tune")
    assert len(cases) == 2 * 3 * len(TOOLS)  # (2 spaces + 1 photo) x tools, each with its JPEG twin
    for case in cases:
        np.testing.assert_allclose(case.filtered, case.original, atol=1e-6)
        if case.quality is None:
            np.testing.assert_allclose(case.reference, case.original, atol=0.5 / 255 + 1e-4)


def test_drawings_are_deterministic_and_hard_edged():
    for name, render in DRAWINGS.items():
        first, second = render(16, 16, 4), render(16, 16, 4)
        assert first.shape == (64, 64, 3) and first.dtype == np.float32
        np.testing.assert_array_equal(first, second)
        np.testing.assert_array_equal(np.rint(first * 255) / 255, first.astype(np.float64), err_msg=name)
        assert len(np.unique(first.reshape(-1, 3), axis=0)) <= 16, name


def test_serif_scene_says_which_font_is_missing(monkeypatch):
    from aarecovery import InputError
    from aarecovery.lab import drawings
    monkeypatch.setattr(drawings, "SERIF_FONT", "/nonexistent/DejaVuSerif.ttf")
    with pytest.raises(InputError, match="fonts-dejavu-core"):
        drawings.DRAWINGS["serif"](16, 16, 2)


def test_joint_bilateral_keeps_o_edges_and_smooths_flat_regions():
    guide = np.zeros((8, 12, 3), np.float32)
    guide[:, 6:] = 1
    filtered = guide.copy()
    filtered[2, 1] = 0.5  # noise inside a flat region of O
    result = joint_bilateral(filtered, guide)
    assert abs(result[2, 1, 0] - 0.5) > 0.2  # smoothed towards its neighbours
    np.testing.assert_allclose(result[:, 5:7], guide[:, 5:7], atol=1e-3)  # the edge stays sharp
    np.testing.assert_allclose(joint_bilateral(guide, guide), guide, atol=1e-6)


def test_outside_local_range_finds_invented_colour():
    filtered = np.zeros((6, 6, 3), np.float32)
    filtered[:, 3:] = 1
    image = filtered.copy()
    image[1, 1] = (0.5, 0, 0)  # inside a flat black region: new colour
    image[1, 3] = (0.5, 0.5, 0.5)  # on the edge: within the local range
    mask = outside_local_range(image, filtered)
    assert mask[1, 1] and not mask[1, 3] and mask.sum() == 1


def test_small_suite_end_to_end_with_each_tool():
    for name in TOOLS:
        require_tool(name)
    suite = realtools.RealToolsSuite("tiny", ("starburst", "text"),
                                     ("gegl-threshold", "gmic-threshold", "im-sigmoidal", "cv-threshold",
                                      "pil-solarize"), 24, {"starburst": ("srgb",)}, (90,))
    results, missing_tools, missing_peers = run_realtools(suite, "tune", peers=True)
    assert not missing_tools
    assert len(results) == 2 * 5 * 2
    assert {r.tool for r in results} == set(TOOLS) and {r.source for r in results} == {"png", "jpeg90"}
    for r in results:
        assert {"F", "R", "paper", "jbf"} <= set(r.psnr_band) and r.plan
        assert 0 <= r.changed <= 1 and r.max_change >= 0 and r.outside["R"] >= 0
        assert r.half == "tune"
    summary = summarize_realtools(results)
    assert summary["hard_cases"] > 0 and "q>=85" in summary["jpeg_gain_kept"]
    table = format_realtools(results, missing_tools, missing_peers, suite_name="tiny", half="tune")
    assert "starburst/srgb/gegl-threshold/png" in table and "== targets of issue 10" in table
    assert "HELD-OUT" not in table
    assert "HELD-OUT" in format_realtools(results, half="heldout")


def test_jpeg_cases_carry_their_files_quantization_tables(tmp_path):
    from PIL import Image

    from aarecovery import read_quantization
    image = np.random.default_rng(3).random((24, 32, 3)).astype(np.float32)
    decoded, tables = realtools._jpeg_round_trip(image, 85)
    path = tmp_path / "o.jpg"
    Image.fromarray(np.rint(image * 255).astype(np.uint8)).save(path, format="JPEG", quality=85)
    assert tables == read_quantization(path) and len(tables[0]) == 64
    with Image.open(path) as reread:
        np.testing.assert_array_equal(decoded, np.asarray(reread.convert("RGB"), np.float32) / np.float32(255))


def test_eval_gives_the_tables_to_the_recovery_only_when_asked(capsys):
    from aarecovery.cli import main
    require_tool("opencv")
    argv = ["eval", "--suite", "realtools", "--scenes", "serif", "--filters", "cv-threshold", "--no-peers"]
    lines = []
    for extra in ([], ["--jpeg-tables"]):
        assert main(argv + extra) == 0
        lines.append([line for line in capsys.readouterr().out.splitlines() if "/cv-threshold/" in line])
    # The JPEG serif's noise is read from its tables with the option (tuning half: linear q 95
    # 0.17 -> 0.40 of its edge error), from its pixels without; the PNG cases are the same.
    png = [[line for line in run if "/png" in line] for run in lines]
    jpeg = [[line for line in run if "/jpeg" in line] for run in lines]
    assert png[0] and png[0] == png[1]
    assert jpeg[0] and jpeg[0] != jpeg[1]


def test_a_jpeg_files_tables_do_not_hide_a_drawing_whose_grid_its_pixels_do_not_show():
    # Serif at q 98 under GEGL's unsharp mask: its grid is not seen in the pixels, and its
    # tables say how much noise but not where the blocks lie; the flattest phase does.
    require_tool("gegl")
    suite = realtools.RealToolsSuite("one", ("serif",), ("gegl-unsharp",), 96, {"serif": ("srgb",)}, (98,))
    png, jpeg = realtools.build_cases(suite, "tune")
    assert jpeg.quantization is not None
    with aarecovery.Engine("numpy") as engine:
        decisions = []
        for tables in (None, jpeg.quantization):
            engine.set_images(jpeg.original, jpeg.filtered, quantization=tables)
            decisions.append(engine.plan().decision)
    assert decisions[0] == decisions[1] == Decision.NEIGHBOURHOOD_HARD_EDGED


def test_missing_tools_are_reported_loudly():
    from aarecovery.lab.peers import PEERS
    from aarecovery.lab.realeval import RealCaseResult
    result = RealCaseResult("maps", "srgb", "gegl-threshold", "drawing", 0.5, psnr={"F": 10, "R": 12},
                            ssim={"F": 0.5, "R": 0.6}, psnr_band={"F": 10, "R": 12}, ssim_band={"F": 0.5, "R": 0.6},
                            reduction={"R": 0.37}, tool="gegl", group="threshold", half="tune")
    table = format_realtools([result], missing_tools=list(TOOLS.values()), missing_peers=PEERS)
    assert table.count("NOT installed") == len(TOOLS) + len(PEERS)
    assert "imagemagick" in table and "gmic" in table and "maps/srgb/gegl-threshold/png" in table


def test_eval_command_runs_the_realtools_suite(capsys):
    from aarecovery.cli import main
    for name in ("gegl",):
        require_tool(name)
    assert main(["eval", "--suite", "realtools", "--scenes", "starburst", "--filters", "gegl-threshold",
                 "--width", "24", "--no-jpeg", "--no-peers"]) == 0
    out = capsys.readouterr().out
    assert "starburst/linear/gegl-threshold/png" in out and "half 'tune'" in out


@pytest.mark.parametrize("argv, message", [
    (["--suite", "realtools", "--filters", "im-threshold"], "belongs to the heldout half"),
    (["--suite", "realtools", "--scenes", "towers"], "belongs to the heldout half"),
    (["--suite", "realtools", "--half", "test"], "--half must be one of"),
    (["--suite", "realtools", "--k", "4"], "--k applies to the built-in suite only"),
    (["--half", "heldout"], "--half applies to --suite realtools only"),
    (["--jpeg-tables"], "--jpeg-tables applies to --suite realtools only"),
    (["--suite", "realtools", "--filters", "nosuch"], "unknown filter 'nosuch'"),
])
def test_eval_command_refuses_crossing_the_split(argv, message, capsys):
    from aarecovery.cli import main
    assert main(["eval", *argv]) == 1
    assert message in capsys.readouterr().err


def test_thin_spokes_under_narrow_levels_are_not_painted_red(backend):
    """The invented colour of issue 10: dark-blue spokes on tan under ``gegl:levels in-low=0.3
    in-high=0.4`` came back as red spokes up to 0.46 where F and the reference are black (419
    pixels, plan "pure colours of thin features")."""
    import aarecovery
    require_tool("gegl")
    suite = realtools.RealToolsSuite("spokes", ("starburst",), ("gegl-levels-narrow",), 96,
                                     {"starburst": ("linear", "srgb")})
    cases = realtools.build_cases(suite, "tune", jpeg=False)
    assert len(cases) == 2
    for case in cases:
        engine = aarecovery.Engine(backend)
        result = aarecovery.recover(case.original, case.filtered, engine=engine)
        black = (case.filtered.max(axis=-1) < 2 / 255) & (case.reference.max(axis=-1) < 2 / 255)
        assert black.sum() > 100, "the scene changed: it no longer has black spokes to check"
        assert result[black].max() <= 2 / 255, (case.space, engine.last_plan.reason, float(result[black].max()))
        # ... and the spokes are still repaired, not merely left alone.
        error = lambda image: float(((image - case.reference) ** 2).mean())
        assert error(result) < 0.2 * error(case.filtered), (case.space, engine.last_plan.reason)


@pytest.mark.parametrize("space", ["linear", "srgb"])
def test_a_saturation_change_of_line_art_is_not_made_worse(space):
    """ImageMagick's ``-modulate 100,100,150`` on ink line art: F is nearly the reference
    already, and the paper's passes lost 3-12 dB to it (held-out half). The repairs they
    would make are no larger than the model's own error there, so F is kept."""
    import aarecovery
    require_tool("imagemagick")
    suite = realtools.RealToolsSuite("modulate", ("inkart",), ("im-modulate",), 96, {"inkart": (space,)})
    (case,) = realtools.build_cases(suite, "heldout", jpeg=False)
    engine = aarecovery.Engine("numpy")
    result = aarecovery.recover(case.original, case.filtered, engine=engine)
    assert engine.last_plan.decision == Decision.NEIGHBOURHOOD_HARD_EDGED_KEPT, engine.last_plan.reason
    np.testing.assert_array_equal(result, case.filtered)
    paper = aarecovery.recover(case.original, case.filtered, mode="paper", backend="numpy")
    error = lambda image: float(((image - case.reference) ** 2).mean())
    assert error(case.filtered) < error(paper), "the scene changed: the paper's method no longer loses here"


def test_colour_to_grey_of_a_star_burst_is_not_made_worse():
    """G'MIC's ``-luminance`` on the sRGB star burst: the thin spokes' inks extended to the
    colour cube lost 4.7 dB to F (tuning half); F is a straight function of the table's key
    there, so the inks stay O's own and R gains."""
    import aarecovery
    require_tool("gmic")
    suite = realtools.RealToolsSuite("luminance", ("starburst",), ("gmic-luminance",), 96, {"starburst": ("srgb",)})
    (case,) = realtools.build_cases(suite, "tune", jpeg=False)
    engine = aarecovery.Engine("numpy")
    result = aarecovery.recover(case.original, case.filtered, engine=engine)
    error = lambda image: float(((image - case.reference) ** 2).mean())
    assert error(result) < 0.9 * error(case.filtered), engine.last_plan.reason


@pytest.mark.parametrize("family", ["rocket", "chelsea"])
def test_a_palette_quantiser_of_a_photo_is_repaired(family):
    """G'MIC's ``-quantize 4`` maps each colour to the nearest of four: a point-wise map of
    the whole colour that no one-channel table fits. It was kept as F on colour photos
    (strength 0); as a calibrated colour map R gains on the edge band."""
    import aarecovery
    from aarecovery.lab.metrics import edge_band, error_reduction
    require_tool("gmic")
    suite = realtools.RealToolsSuite("quantize", (family,), ("gmic-quantize",), 96, {family: ("linear",)})
    (case,) = realtools.build_cases(suite, "heldout", jpeg=False)
    engine = aarecovery.Engine("numpy")
    result = aarecovery.recover(case.original, case.filtered, engine=engine)
    assert engine.last_plan.decision == Decision.COLOUR_MAP_CALIBRATED, engine.last_plan.reason
    band = edge_band(case.original, case.filtered, case.reference)
    assert error_reduction(result, case.filtered, case.reference, band) > 0.1, engine.last_plan.reason


def test_safe_default_on_the_held_out_quick_suite():
    """What the safe default achieves on images and tools it was not tuned on (docs/quality.md).

    Issue 10's never-worse target holds here on its own families and tools and is asserted
    as stated, with issue 19's additions (mixed content, OpenCV's abstraction filter,
    ImageMagick at 55%): OpenCV's edge-preserving filter and GEGL's bilateral filter on the
    hatching, which lost 0.54 dB and more while the hatching was read as edges to blend, gain
    since hatched regions are repaired at a lower strength (``aarecovery.plan.hatching``).
    The other figures are
    floors a little under today's (0.54, 0.29 and 0.49 on this suite), short of the issue's
    targets (0.75, 0.3 and 0.8), so that a change that loses ground fails.
    """
    from aarecovery.lab.realeval import MAX_LOSS_DB
    for name in TOOLS:
        require_tool(name)
    results, missing_tools, _ = run_realtools(realtools.REAL_QUICK, "heldout", peers=True)
    assert not missing_tools and len(results) >= 90
    assert {r.half for r in results} == {"heldout"}
    summary = summarize_realtools(results)
    losses = {r.name for r in results if r.psnr_band["F"] - r.psnr_band["R"] > MAX_LOSS_DB}
    assert not losses, f"worse than F by over {MAX_LOSS_DB} dB: {losses}"
    assert summary["hard"]["R"] >= 0.5 and summary["hard"]["R"] > summary["hard"]["paper"], summary["hard"]
    # GEGL's bilateral filter is the one filter where a peer (the joint bilateral filter) does
    # better on this half; on every other filter R is ahead of each peer.
    assert set(summary["behind_peers"]) <= {"gegl-bilateral"}, summary["behind_peers"]
    assert summary["photo_pointwise"]["R"] >= 0.22, summary["photo_pointwise"]
    assert summary["jpeg_gain_kept"]["q>=85"]["R"][0] >= 0.35, summary["jpeg_gain_kept"]["q>=85"]


@pytest.mark.parametrize("family, filter_name", [("text", "pil-ycbcr-equalize"), ("memo", "pil-ycbcr-equalize")])
def test_a_tool_with_per_image_state_maps_the_scene_with_os_state(family, filter_name):
    # The reference is the user's filter, the histogram of O, applied to the scene: where the
    # scene's colours all appear in O, the reference is the box filter of the scene mapped as F
    # maps O's pixels of those colours. The scene's own histogram gives another map.
    from aarecovery.plan.resample import box_downsample
    suite = realtools.RealToolsSuite("state", (family,), (filter_name,), 32, {family: ("srgb",)})
    case, twin = realtools.build_cases(suite, "tune")
    scene, _ = realtools.render_scene(family, 32)
    k = realtools.FAMILIES[family].k

    def packed(image):
        values = np.rint(np.clip(image, 0, 1) * 255).astype(np.int64)
        return (values[..., 0] << 16) | (values[..., 1] << 8) | values[..., 2]

    in_scene, in_o = packed(scene), packed(case.original)
    mapped = np.zeros(scene.shape, np.float32)
    known = np.zeros(in_scene.shape, bool)
    for colour in np.unique(in_o):
        where = in_scene == colour
        mapped[where] = case.filtered[in_o == colour][0]
        known |= where
    blocks = known.reshape(known.shape[0] // k, k, known.shape[1] // k, k).all(axis=(1, 3))
    assert blocks.mean() > 0.5
    expected = box_downsample(mapped, k, case.space)
    np.testing.assert_allclose(case.reference[blocks], expected[blocks], atol=1e-6)
    spec = realtools.TOOL_FILTERS[filter_name]
    own_state = box_downsample(TOOLS[spec.tool].run(spec.command(), [scene], whole_image=True)[0], k, case.space)
    assert np.abs(own_state - expected)[blocks].max() > 2 / 255
    # The JPEG twin's O has its own histogram, and so its own reference.
    assert twin.quality is not None and twin.reference is not case.reference
