"""JPEG-aware evidence: O's compression noise from its file or its pixels, kept out of F's flat areas."""

import io

import numpy as np
import pytest
from PIL import Image

import aarecovery
from aarecovery.cli import main
from aarecovery.plan.compression import (NO_COMPRESSION, NOISE_CONTRAST_SIGMAS, compression_evidence,
                                         detect_block_grid, noise_from_tables)
from jpeg_scans import haze, scan_page, threshold


def _encoded(pixels):
    return pixels.astype(np.float32) / 255


def _tables(quality):
    buffer = io.BytesIO()
    Image.new("RGB", (16, 16), (200, 190, 170)).save(buffer, format="JPEG", quality=quality)
    buffer.seek(0)
    with Image.open(buffer) as image:
        return [list(table) for table in image.quantization.values()]


def test_noise_bound_falls_with_quality():
    noises = [noise_from_tables(_tables(quality)) for quality in (75, 85, 95, 98)]
    assert noises == sorted(noises, reverse=True)
    # libjpeg's q 85 table: about 5.8 levels of noise per pixel.
    assert 5.0 < noises[1] * 255 < 6.5


@pytest.mark.parametrize("quality", [75, 85, 95])
def test_block_grid_is_found_in_a_decoded_jpeg_at_its_phase(quality):
    _, jpeg, _ = scan_page(3, quality)
    found = compression_evidence(_encoded(jpeg))
    assert found.source == "block grid" and found.phase == (0, 0)
    # The analysis window need not start on the grid.
    shifted = compression_evidence(_encoded(jpeg[3:, 5:]))
    assert shifted.source == "block grid" and shifted.phase == (5, 3)
    # The table the grid's steps give is the file's within a factor of two.
    bound = noise_from_tables(_tables(quality))
    assert bound / 2 <= found.noise <= bound * 2
    assert found.noise == noise_from_tables([detect_block_grid(_encoded(jpeg))[2]])


@pytest.mark.parametrize("textured", [False, True])
def test_lossless_pixels_show_no_compression(textured):
    png, _, _ = scan_page(4, 85, textured=textured)
    evidence = compression_evidence(_encoded(png))
    assert evidence.source == NO_COMPRESSION.source and evidence.noise == 0 and not evidence.compressed
    assert detect_block_grid(_encoded(png))[1] < detect_block_grid(_encoded(scan_page(4, 95)[1]))[1]
    # Undecided, the search measures no table (no caller reads one then).
    assert detect_block_grid(_encoded(png))[2] is None


def test_quantization_tables_are_read_from_jpeg_files_only(tmp_path):
    png, jpeg, data = scan_page(5, 85)
    (tmp_path / "o.jpg").write_bytes(data)
    Image.fromarray(png).save(tmp_path / "o.png")
    tables = aarecovery.read_quantization(tmp_path / "o.jpg")
    assert tables is not None and len(tables[0]) == 64
    assert aarecovery.read_quantization(tmp_path / "o.png") is None
    assert aarecovery.read_quantization(tmp_path / "missing.jpg") is None
    evidence = compression_evidence(_encoded(jpeg), tables)
    assert evidence.source == "quantization tables"
    assert evidence.noise == pytest.approx(noise_from_tables(_tables(85)))


def test_the_command_line_passes_a_jpeg_files_tables_to_the_plan(tmp_path, capsys, monkeypatch):
    import aarecovery.pipeline as pipeline
    _, jpeg, data = scan_page(7, 75)
    (tmp_path / "o.jpg").write_bytes(data)
    Image.fromarray(threshold(jpeg)).save(tmp_path / "f.png")
    tables = aarecovery.read_quantization(tmp_path / "o.jpg")
    plans = []

    def make_plan(*args, **kwargs):
        plan = real_make_plan(*args, **kwargs)
        plans.append((kwargs.get("quantization"), plan))
        return plan

    real_make_plan = pipeline.make_plan
    monkeypatch.setattr(pipeline, "make_plan", make_plan)
    assert main(["recover", str(tmp_path / "o.jpg"), str(tmp_path / "f.png"), "-o", str(tmp_path / "r.png"),
                 "--backend", "numpy"]) == 0
    passed, plan = plans[0]
    assert passed == tables and plan.decision == aarecovery.Decision.POINTWISE_HARD_EDGED_COMPRESSED
    # The tables' noise (9.7 levels at q 75) sets the least contrast of a thin feature.
    from_tables = compression_evidence(_encoded(jpeg), tables)
    assert from_tables.source == "quantization tables"
    assert plan.pure_colours.noise_contrast == pytest.approx(from_tables.contrast)
    engine = aarecovery.Engine("numpy")
    try:
        engine.set_images(jpeg, threshold(jpeg), quantization=tables)
        assert engine.plan().pure_colours.noise_contrast == pytest.approx(from_tables.contrast)
        engine.set_images(jpeg, threshold(jpeg))
        assert engine.plan().decision == aarecovery.Decision.POINTWISE_HARD_EDGED_COMPRESSED
        assert compression_evidence(_encoded(jpeg)).source == "block grid"
    finally:
        engine.release()


def test_a_batch_reads_the_tables_of_jpeg_originals(tmp_path):
    _, jpeg, data = scan_page(7, 75)
    (tmp_path / "o.jpg").write_bytes(data)
    Image.fromarray(threshold(jpeg)).save(tmp_path / "f.png")
    from_file, from_array = aarecovery.recover_many([(tmp_path / "o.jpg", tmp_path / "f.png", "file.png"),
                                                     (jpeg, threshold(jpeg), "array.png")], backend="numpy")
    assert from_file.decision == from_array.decision == "pointwise-hard-edged-compressed"
    # The report says which evidence the plan read: the file's tables, or the grid in the array.
    assert "JPEG (quantization tables" in from_file.reason
    assert "JPEG (block grid" in from_array.reason


def _pages(count, seed):
    rng = np.random.default_rng(seed)
    for index in range(count):
        yield int(rng.integers(1 << 30)), int(rng.integers(75, 96)), bool(index % 2)


@pytest.mark.parametrize("page_seed, quality, textured", list(_pages(8, 19)))
def test_no_paper_grain_reaches_fs_flat_background(page_seed, quality, textured):
    # Random JPEG scans of text on tinted or textured paper, thresholded: where F is white
    # and the clean page is bare paper, R must stay white (within 10 levels).
    png, jpeg, _ = scan_page(page_seed, quality, textured=textured)
    filtered = threshold(jpeg)
    recovered = aarecovery.recover(jpeg, filtered, backend="numpy")
    assert haze(recovered, filtered, png) == 0


def test_without_the_noise_contrast_the_grain_does_reach_the_background(monkeypatch):
    # The property above is not vacuous: with the contrast floor of lossless inputs alone,
    # the ringing next to the letters is extended to ink on the same kind of page.
    import aarecovery.plan.compression as compression
    png, jpeg, _ = scan_page(7, 75)
    filtered = threshold(jpeg)
    assert NOISE_CONTRAST_SIGMAS > 0
    monkeypatch.setattr(compression, "NOISE_CONTRAST_SIGMAS", 0.0)
    monkeypatch.setattr(compression, "MIN_NOISE_CONTRAST", 0.0)
    assert haze(aarecovery.recover(jpeg, filtered, backend="numpy"), filtered, png) > 100


def _jpeg_round_trip(pixels, quality):
    buffer = io.BytesIO()
    Image.fromarray(pixels).save(buffer, format="JPEG", quality=quality)
    buffer.seek(0)
    with Image.open(buffer) as decoded:
        return np.asarray(decoded.convert("RGB"))


@pytest.mark.parametrize("quality", [75, 90])
def test_a_jpeg_drawing_is_hard_edged_and_a_jpeg_photo_textured(quality):
    # The pixel grain reads a JPEG page's ringing as texture; the edge-free blocks of its
    # grid are flat, where a photo's keep their shading.
    from importlib import resources

    from aarecovery.lab.realtools import render_family
    from aarecovery.plan.resample import box_downsample
    from aarecovery.plan.texture import grain, is_textured
    page = np.rint(box_downsample(render_family("serif", 96), 8, "linear") * 255).astype(np.uint8)
    page = _encoded(_jpeg_round_trip(page, quality))
    evidence = compression_evidence(page)
    assert grain(page) > 0.05
    assert is_textured(page, 0.0, evidence) == (False, is_textured(page, 0.0, evidence)[1])
    with resources.files("aarecovery").joinpath("data/photo_camera.png").open("rb") as handle:
        photo = np.asarray(Image.open(handle).convert("RGB"))[:256, :256]
    photo = _encoded(_jpeg_round_trip(np.ascontiguousarray(photo[::2, ::2]), quality))
    evidence = compression_evidence(photo)
    assert evidence.compressed
    assert is_textured(photo, 0.0, evidence)[0]


def _page(family, space, quality):
    from aarecovery.lab.realtools import render_family
    from aarecovery.plan.resample import box_downsample
    page = np.rint(box_downsample(render_family(family, 96), 8, space) * 255).astype(np.uint8)
    return _encoded(page if quality is None else _jpeg_round_trip(page, quality))


def _rgba(encoded):
    return np.concatenate([encoded, np.ones_like(encoded[..., :1])], axis=-1)


def test_a_jpeg_drawing_without_a_visible_grid_has_flat_blocks_and_a_photo_not():
    # At q 98 the serif page's grid is not found in its pixels and its ringing reads as
    # grain; its edge-free blocks are flat at some phase, a JPEG photo's are not.
    from importlib import resources

    from aarecovery.plan.compression import hidden_compression
    from aarecovery.plan.texture import is_textured
    page = _page("serif", "linear", 98)
    assert not compression_evidence(page).compressed
    assert is_textured(page, 0.0, NO_COMPRESSION)[0]
    hidden = hidden_compression(page)
    assert hidden.source == "flat blocks" and hidden.noise > 0
    assert not is_textured(page, 0.0, hidden)[0]
    with resources.files("aarecovery").joinpath("data/photo_camera.png").open("rb") as handle:
        photo = np.asarray(Image.open(handle).convert("RGB"))[:256, :256]
    photo = _encoded(_jpeg_round_trip(np.ascontiguousarray(photo[::2, ::2]), 98))
    assert hidden_compression(photo) == NO_COMPRESSION


def _screentone_page():
    """512 x 512 px of a comic page: three framed panels, dots of screentone (6 px apart) over
    part of each, white paper between; antialiased at 4 x 4, grey."""
    y, x = np.mgrid[0:2048, 0:2048] / 4.0
    ink = np.ones((2048, 2048), np.float32)
    for top, left, height, width in ((20, 20, 220, 230), (20, 270, 220, 220), (270, 20, 220, 470)):
        inside = (y >= top) & (y < top + height) & (x >= left) & (x < left + width)
        dots = (np.mod(x, 6) - 3) ** 2 + (np.mod(y, 6) - 3) ** 2 < 1.6 ** 2
        ink[inside & dots & (x < left + 0.6 * width)] = 0.15
        ink[inside & ~((y >= top + 3) & (y < top + height - 3) & (x >= left + 3) & (x < left + width - 3))] = 0.0
    page = np.rint(ink.reshape(512, 4, 512, 4).mean(axis=(1, 3)) * 255).astype(np.uint8)
    return np.repeat(page[..., None], 3, axis=2)


def test_a_lossless_page_flat_at_every_phase_is_no_hidden_jpeg(monkeypatch):
    """A lossless page's edge-free blocks are flat at every phase of the 8 x 8 grid, a JPEG's
    only near its own (LOSSLESS_PHASE_GAP): on a 512 x 512 window, with its 64 phases, the PNG
    page is no JPEG drawing, its JPEG twins at q 75-90 (no grid seen in their pixels) are."""
    from aarecovery.plan.compression import LOSSLESS_PHASE_GAP, hidden_compression
    page = _screentone_page()
    assert hidden_compression(_encoded(page)) == NO_COMPRESSION
    for quality in (75, 90):
        jpeg = _encoded(_jpeg_round_trip(page, quality))
        assert not compression_evidence(jpeg).compressed, quality
        assert hidden_compression(jpeg).source == "flat blocks", quality
    # Without the test of the phases the PNG page read as a JPEG drawing.
    import aarecovery.plan.compression as compression
    assert LOSSLESS_PHASE_GAP > 0
    monkeypatch.setattr(compression, "LOSSLESS_PHASE_GAP", -1.0)
    assert hidden_compression(_encoded(page)).source == "flat blocks"


def test_an_unsharp_mask_on_a_jpeg_drawing_is_repaired():
    # Read by its flat blocks, the q 98 page is hard-edged content under an unsharp mask (F
    # was kept as a textured image's), repaired at full strength; the star burst at q 85 (grid
    # found) is repaired at a repair-to-error ratio below the bar a smoothing filter needs on
    # compressed content, at the lower strength a sharpening filter gets there, and its PNG
    # twin at full strength.
    from aarecovery.filters.spatial import unsharp_mask
    from aarecovery.plan.analysis import analyse
    from aarecovery.plan.compression import COMPRESSED_REPAIR_TO_ERROR, COMPRESSED_SHARPENED_STRENGTH
    from aarecovery.plan.model_error import repair_to_error_ratio
    assert COMPRESSED_SHARPENED_STRENGTH < 1.0
    for family, quality, strength in (("serif", 98, 1.0), ("starburst", 85, COMPRESSED_SHARPENED_STRENGTH),
                                      ("starburst", None, 1.0)):
        page = _page(family, "linear", quality)
        filtered = np.clip(unsharp_mask(page, radius=1.5, amount=1.5), 0, 1).astype(np.float32)
        analysis = analyse(_rgba(page), _rgba(filtered))
        assert analysis.decision == aarecovery.Decision.NEIGHBOURHOOD_HARD_EDGED, analysis.reason
        assert analysis.strength == strength, (family, quality, analysis.reason)
        if quality == 85:
            assert compression_evidence(page).source == "block grid"
            ratio = repair_to_error_ratio(_rgba(page), _rgba(filtered), linear_input=False,
                                          blend_space=analysis.blend_space, sigma_d=aarecovery.params.SIGMA_D.default,
                                          sigma_e=aarecovery.params.SIGMA_E.default)
            assert ratio < COMPRESSED_REPAIR_TO_ERROR
            assert f"strength {COMPRESSED_SHARPENED_STRENGTH:g}" in analysis.reason


@pytest.mark.parametrize("family", ["serif"])
def test_a_sharpening_filter_on_a_jpeg_drawing_blends_in_srgb_values(backend, family):
    # Drawn in linear light, saved at q 85, sharpened: the repair blends in sRGB values, where
    # the compression's noise lies (COMPRESSED_SHARPENED_BLEND_SPACE); the PNG twin keeps the
    # space its colour lines tell. Measured (both backends): serif 0.619 -> 0.792 of the error.
    # The manga page gained as much (0.592 -> 0.926) until O's seen inks (PureColourPrior.inks)
    # extended its strokes' near-whole pixels to their black: now 0.943 blended in linear
    # light, 0.937 in sRGB values.
    from aarecovery.filters import apply
    from aarecovery.lab.groundtruth import make_case
    from aarecovery.lab.metrics import error_reduction
    from aarecovery.lab.realtools import render_family
    from aarecovery.plan.compression import COMPRESSED_SHARPENED_BLEND_SPACE
    case = make_case(render_family(family, 96), "unsharp", 8, "linear")
    pixels = np.rint(np.clip(case.original, 0, 1) * 255).astype(np.uint8)
    spaces = {}
    with aarecovery.Engine(backend) as engine:
        for quality in (None, 85):
            original = _encoded(pixels if quality is None else _jpeg_round_trip(pixels, quality))
            filtered = np.clip(apply("unsharp", original), 0, 1).astype(np.float32)
            result = aarecovery.recover(original, filtered, engine=engine)
            spaces[quality] = engine.last_plan.blend_space
            assert engine.last_plan.decision == aarecovery.Decision.NEIGHBOURHOOD_HARD_EDGED, engine.last_plan.reason
        in_linear = aarecovery.recover(original, filtered, engine=engine, blend_space="linear")
    assert spaces == {None: "linear", 85: COMPRESSED_SHARPENED_BLEND_SPACE} and COMPRESSED_SHARPENED_BLEND_SPACE == "srgb"
    assert (error_reduction(result, filtered, case.reference, None)
            > error_reduction(in_linear, filtered, case.reference, None) + 0.1)


def test_a_smoothing_filter_on_a_jpeg_colour_drawing_blends_in_srgb_values(backend):
    # Drawn in sRGB values, saved at q 85, smoothed by the built-in bilateral filter: the
    # repair at COMPRESSED_SMOOTHED_STRENGTH blends in sRGB values (COMPRESSED_SMOOTHED_BLEND_SPACE),
    # where the JPEG averaged the encoded values across the edges; a JPEG's edges do not vote,
    # so its colour lines read linear light. Measured (NumPy): 0.319 of the error against
    # 0.256 blended in linear light (q 75-95: +0.04 to +0.08; drawn in linear light +0.02).
    from aarecovery.filters import apply
    from aarecovery.lab.groundtruth import make_case
    from aarecovery.lab.metrics import error_reduction
    from aarecovery.lab.realtools import render_family
    from aarecovery.plan.compression import COMPRESSED_SMOOTHED_BLEND_SPACE, COMPRESSED_SMOOTHED_STRENGTH
    case = make_case(render_family("serif", 96), "bilateral", 8, "srgb")
    pixels = np.rint(np.clip(case.original, 0, 1) * 255).astype(np.uint8)
    original = _encoded(_jpeg_round_trip(pixels, 85))
    filtered = np.clip(apply("bilateral", original), 0, 1).astype(np.float32)
    with aarecovery.Engine(backend) as engine:
        result = aarecovery.recover(original, filtered, engine=engine)
        plan = engine.last_plan
        in_linear = aarecovery.recover(original, filtered, engine=engine, blend_space="linear")
    assert plan.decision == aarecovery.Decision.NEIGHBOURHOOD_HARD_EDGED, plan.reason
    assert plan.strength == COMPRESSED_SMOOTHED_STRENGTH and "smoothing filter above" in plan.reason
    assert plan.blend_space == COMPRESSED_SMOOTHED_BLEND_SPACE == "srgb"
    assert (error_reduction(result, filtered, case.reference, None)
            > error_reduction(in_linear, filtered, case.reference, None) + 0.04)


def _curve_case(family, space, quality, curve):
    """A real-tools drawing as a JPEG under an 8-bit curve: O, F, the reference and the band."""
    from test_safeguards import family_as_jpeg

    from aarecovery.lab.metrics import edge_band
    from aarecovery.lab.realtools import FAMILIES
    from aarecovery.plan.resample import box_downsample
    scene, clean, original = family_as_jpeg(family, 96, quality, space)
    reference = box_downsample(curve[scene].astype(np.float32) / 255, FAMILIES[family].k, space)
    band = edge_band(_encoded(clean), _encoded(curve[clean]), reference)
    return original, curve[original], reference, band


def _reduction(original, filtered, reference, band):
    from aarecovery.lab.metrics import error_reduction
    with aarecovery.Engine("numpy") as engine:
        engine.set_images(original, filtered)
        plan = engine.plan()
        recovered = aarecovery.recover(original, filtered, engine=engine)
    return error_reduction(_encoded(recovered), _encoded(filtered), reference, band), plan


_GAMMA = np.rint((np.arange(256) / 255.0) ** 2.2 * 255).astype(np.uint8)
_LEVELS = np.minimum(255, np.arange(256) * 2).astype(np.uint8)


def test_a_jpeg_drawing_without_a_visible_grid_is_a_compressed_drawing_under_a_pointwise_filter(monkeypatch):
    # The serif page at q 98 under a gamma curve: its flat edge-free blocks make it a drawing
    # from a JPEG (the calibrated strength, pure colours above the JPEG's noise), where its
    # ringing made it a photo. Measured: 0.603 of the edge error against 0.517.
    from aarecovery.plan import analysis
    case = _curve_case("serif", "srgb", 98, _GAMMA)
    drawing, plan = _reduction(*case)
    assert plan.decision == aarecovery.Decision.POINTWISE_HARD_EDGED_COMPRESSED, plan.reason
    assert plan.pure_colours is not None and plan.pure_colours.luma_purity > 0
    assert "flat blocks" in plan.reason
    monkeypatch.setattr(analysis, "hidden_compression", lambda encoded: NO_COMPRESSION)
    photo, plan = _reduction(*case)
    assert plan.decision == aarecovery.Decision.POINTWISE_CALIBRATED, plan.reason
    assert drawing > photo + 0.05


def test_a_jpegs_smeared_chroma_is_no_thin_feature(monkeypatch):
    # The star burst at q 98 under a levels curve: between its dark-blue spokes the tan paper
    # keeps its luma, but the JPEG's subsampled chroma gives it the spokes' blue; taken for a
    # thin feature's partial colour, it was extended to a pink that F never had (measured:
    # -0.151 of the edge error; with the luma purity +0.150). Measured where the repair blends
    # in linear light, where O's colour lines put the pair: blended in sRGB values
    # (COMPRESSED_HARD_EDGED_BLEND_SPACE), the extension does not reach that pink (+0.125).
    from aarecovery.plan import analysis
    monkeypatch.setattr(analysis, "COMPRESSED_HARD_EDGED_BLEND_SPACE", "linear")
    case = _curve_case("starburst", "srgb", 98, _LEVELS)
    with_luma, plan = _reduction(*case)
    assert plan.pure_colours is not None and plan.pure_colours.luma_purity > 0, plan.reason
    monkeypatch.setattr(analysis, "COMPRESSED_LUMA_PURITY", 0.0)
    without, _ = _reduction(*case)
    assert with_luma > 0.1 > 0 > without


@pytest.mark.parametrize("options", [dict(quality=5), dict(quality=85, subsampling=0), dict(quality=100),
                                     dict(quality=70, progressive=True, icc_profile=b"x" * 70000)])
def test_the_tables_are_read_from_the_header_as_pillow_reads_them(tmp_path, options):
    pixels = (np.random.default_rng(1).random((40, 50, 3)) * 255).astype(np.uint8)
    path = tmp_path / "o.jpg"
    Image.fromarray(pixels).save(path, format="JPEG", **options)
    with Image.open(path) as image:
        expected = [list(image.quantization[number]) for number in sorted(image.quantization)]
    assert aarecovery.read_quantization(path) == expected
    Image.fromarray(pixels[..., 0]).save(path, format="JPEG", quality=60)      # grey: one table
    with Image.open(path) as image:
        assert aarecovery.read_quantization(path) == [list(image.quantization[0])]
    path.write_bytes(path.read_bytes()[:30])                                   # cut in its header
    assert aarecovery.read_quantization(path) is None


def test_the_tables_of_a_cameras_mpo_file_are_read(tmp_path):
    # Pillow names a JPEG followed by a second picture MPO; its first picture is what
    # read_image gives, compressed with these tables.
    pixels = (np.random.default_rng(2).random((32, 32, 3)) * 255).astype(np.uint8)
    Image.fromarray(pixels).save(tmp_path / "o.mpo", format="MPO", save_all=True,
                                 append_images=[Image.fromarray(pixels)], quality=80)
    with Image.open(tmp_path / "o.mpo") as image:
        assert image.format == "MPO"
        expected = [list(image.quantization[number]) for number in sorted(image.quantization)]
    assert aarecovery.read_quantization(tmp_path / "o.mpo") == expected


def test_the_tables_are_read_without_pillow(tmp_path):
    # Nothing is decoded: a pair read where Pillow is absent (the GIMP plug-in's bundle) or
    # unwanted still gets its tables.
    import subprocess
    import sys
    Image.new("RGB", (16, 16), (200, 120, 40)).save(tmp_path / "o.jpg", quality=90)
    script = ("import sys; sys.modules['PIL'] = None; import aarecovery; "
              f"print(len(aarecovery.read_quantization({str(tmp_path / 'o.jpg')!r})))")
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert run.returncode == 0 and run.stdout.strip() == "2", run.stderr


def test_a_jpeg_drawing_under_a_point_wise_filter_blends_in_srgb_values(backend):
    """A JPEG's quantized DCT and 4:2:0 chroma average the encoded values across an edge, so
    the edge pixels of a JPEG drawing are blends of encoded colour whatever space the drawing
    was antialiased in. Serif text antialiased in linear light, saved at q 90, under a
    threshold (measured, NumPy: 0.548 of the edge error blended in sRGB values, 0.430 in
    linear light, where its colour lines had put it)."""
    import dataclasses

    from test_safeguards import family_as_jpeg

    from aarecovery.lab.metrics import edge_band, error_reduction
    from aarecovery.lab.realtools import FAMILIES
    from aarecovery.plan.resample import box_downsample
    scene, clean, original = family_as_jpeg("serif", 96, 90, space="linear")
    table = np.where(np.arange(256) >= 128, 255, 0).astype(np.uint8)
    filtered = table[original]
    reference = box_downsample(table[scene].astype(np.float32) / 255, FAMILIES["serif"].k, "linear")
    band = edge_band(clean.astype(np.float32) / 255, table[clean].astype(np.float32) / 255, reference)
    reductions = {}
    with aarecovery.Engine(backend) as engine:
        engine.set_images(original, filtered)
        plan = engine.plan()
        assert plan.decision == aarecovery.Decision.POINTWISE_HARD_EDGED_COMPRESSED, plan.reason
        assert plan.blend_space == "srgb"
        for space in ("srgb", "linear"):
            engine.run(dataclasses.replace(plan, blend_space=space))
            reductions[space] = error_reduction(engine.result().astype(np.float32) / 255,
                                                filtered.astype(np.float32) / 255, reference, band)
    assert reductions["srgb"] > reductions["linear"] + 0.05, reductions
