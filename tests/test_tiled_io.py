"""TIFF files read and written in pieces (``aarecovery.io.tiled``), and the analysis window."""

import os

import numpy as np
import pytest
import tifffile

import aarecovery
from aarecovery import read_image, write_image
from aarecovery.io.tiled import TiledTiffWriter, tiff_regions
from aarecovery.sample import analysis_sample, analysis_windows, array_sample
from aarecovery.stream import open_pair

RNG = np.random.default_rng(3)


def random_image(shape, dtype):
    if np.dtype(dtype).kind == "f":
        return RNG.random(shape, np.float32)
    return RNG.integers(0, np.iinfo(dtype).max, shape, endpoint=True).astype(dtype)


REGIONS = [(slice(0, 70), slice(0, 90)), (slice(13, 37), slice(29, 61)), (slice(63, 70), slice(0, 1)),
           (slice(5, 6), slice(40, 90))]

LAYOUTS = {
    "rgb8 tiles": (dict(shape=(70, 90, 3), dtype=np.uint8), dict(tile=(16, 32), photometric="rgb")),
    "rgb16 strips": (dict(shape=(70, 90, 3), dtype=np.uint16), dict(rowsperstrip=7, photometric="rgb")),
    "rgb8 planar": (dict(shape=(70, 90, 3), dtype=np.uint8),
                    dict(tile=(32, 16), photometric="rgb", planarconfig="separate")),
    "grey float": (dict(shape=(70, 90), dtype=np.float32), dict(tile=(16, 16), photometric="minisblack")),
    "rgba8": (dict(shape=(70, 90, 4), dtype=np.uint8), dict(tile=(48, 48), photometric="rgb",
                                                              extrasamples=("unassalpha",))),
    "grey+alpha16 premultiplied": (dict(shape=(70, 90, 2), dtype=np.uint16),
                                   dict(tile=(16, 16), photometric="minisblack", extrasamples=("assocalpha",))),
}


@pytest.mark.parametrize("layout", LAYOUTS)
def test_a_region_equals_the_same_region_of_the_whole_image(tmp_path, layout):
    made, options = LAYOUTS[layout]
    image = random_image(made["shape"], made["dtype"])
    if "premultiplied" in layout:
        image[..., 0] = np.minimum(image[..., 0], image[..., 1])
    stored = np.moveaxis(image, -1, 0) if options.get("planarconfig") == "separate" else image
    tifffile.imwrite(tmp_path / "x.tif", stored, compression="zlib", metadata=None, **options)
    whole = read_image(tmp_path / "x.tif")
    with tiff_regions(tmp_path / "x.tif") as regions:
        assert regions.shape == whole.shape and regions.dtype == whole.dtype
        for rows, cols in REGIONS:
            np.testing.assert_array_equal(regions.read(rows, cols), whole[rows, cols])


def test_files_that_cannot_be_read_in_pieces_are_read_whole(tmp_path):
    image = random_image((40, 40, 3), np.uint8)
    write_image(tmp_path / "x.png", image)
    tifffile.imwrite(tmp_path / "one-strip.tif", image, rowsperstrip=40, photometric="rgb")
    tifffile.imwrite(tmp_path / "palette.tif", image[..., 0], photometric="palette", tile=(16, 16),
                     colormap=np.tile(np.arange(256, dtype=np.uint16) * 257, (3, 1)))
    for name in ("x.png", "one-strip.tif", "palette.tif"):
        assert tiff_regions(tmp_path / name) is None, name


def test_a_corrupt_tile_is_a_clear_error(tmp_path):
    image = random_image((64, 64, 3), np.uint8)
    tifffile.imwrite(tmp_path / "x.tif", image, tile=(32, 32), compression="zlib", photometric="rgb")
    with tifffile.TiffFile(tmp_path / "x.tif") as tif:
        offset = tif.pages.first.dataoffsets[3]
    with open(tmp_path / "x.tif", "r+b") as file:
        file.seek(offset)
        file.write(b"\xff" * 16)
    with tiff_regions(tmp_path / "x.tif") as regions:
        regions.read(slice(0, 32), slice(0, 64))
        with pytest.raises(aarecovery.InputError, match="could not decode .*x.tif as TIFF"):
            regions.read(slice(32, 64), slice(32, 64))


@pytest.mark.parametrize("shape, dtype", [((100, 70, 3), np.uint8), ((100, 70), np.float32),
                                          ((50, 33, 4), np.uint16)])
def test_the_tiled_writer_writes_what_write_image_writes(tmp_path, shape, dtype):
    image = random_image(shape, dtype)
    TiledTiffWriter(tmp_path / "tiled.tif", shape, dtype, 32).write(
        image[top:top + 32, left:left + 32] for top in range(0, shape[0], 32) for left in range(0, shape[1], 32))
    write_image(tmp_path / "whole.tif", image)
    np.testing.assert_array_equal(read_image(tmp_path / "tiled.tif"), read_image(tmp_path / "whole.tif"))
    with tifffile.TiffFile(tmp_path / "tiled.tif") as tif:
        page = tif.pages.first
        assert page.is_tiled and page.tilewidth == 32 and page.compression == tifffile.COMPRESSION.ADOBE_DEFLATE


def test_an_interrupted_tiled_write_leaves_the_destination_and_no_temporary_file(tmp_path):
    write_image(tmp_path / "r.tif", np.zeros((8, 8), np.uint8))
    before = (tmp_path / "r.tif").read_bytes()

    def tiles():
        yield np.zeros((32, 32, 3), np.uint8)
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        TiledTiffWriter(tmp_path / "r.tif", (64, 64, 3), np.uint8, 32).write(tiles())
    assert (tmp_path / "r.tif").read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["r.tif"]


def test_a_pair_of_different_sizes_is_refused_naming_both(tmp_path):
    for name, shape in (("o.tif", (64, 80, 3)), ("f.tif", (64, 81, 3))):
        tifffile.imwrite(tmp_path / name, np.zeros(shape, np.uint8), tile=(16, 16), photometric="rgb")
    with pytest.raises(aarecovery.InputError, match="original is 80x64 but filtered is 81x64"):
        open_pair(tmp_path / "o.tif", tmp_path / "f.tif", 32, 3)


def test_small_images_are_analysed_whole():
    assert analysis_windows(300, 500) == [(slice(0, 300), slice(0, 500))]


def test_the_analysis_window_is_the_one_with_most_edges_and_spans_the_image():
    height, width = 3000, 4100
    windows = analysis_windows(height, width)
    assert windows[0] == (slice(1244, 1756), slice(1794, 2306))  # the central crop comes first
    assert max(w[0].stop for w in windows) == height and max(w[1].stop for w in windows) == width
    assert min(w[0].start for w in windows) == 0 and min(w[1].start for w in windows) == 0
    original = np.full((height, width), 128, np.uint8)
    filtered = original.copy()
    original[2700:2900, 100:400:3] = 0  # stripes near a corner, the only edges
    o, f = array_sample(original, filtered)
    assert (o == 0).sum() == (original == 0).sum()
    # Without edges anywhere, the central window, as the analysis always read.
    flat = np.full((height, width), 7, np.uint8)
    reads = []
    sample = analysis_sample(lambda r, c: reads.append((r, c)) or flat[r, c], lambda r, c: flat[r, c], height, width)
    assert reads[-1] == windows[0] and sample[0].shape == (512, 512)


def test_a_long_streamed_write_keeps_its_part_while_another_run_tidies_the_folder(tmp_path):
    """A gigapixel write takes minutes; a batch or recover beside it removes stale parts of
    writers that are gone. The streamed writer's part is locked, so it is not taken for one."""
    import time

    from aarecovery.io.parts import is_part_name, remove_stale_parts
    image = random_image((64, 48, 3), np.uint8)
    removed = []

    def pieces():
        for top in range(0, 64, 16):
            for left in range(0, 48, 16):
                if (top, left) == (32, 0):
                    (part,) = [p for p in tmp_path.iterdir() if is_part_name(p.name)]
                    old = time.time() - 3600  # older than any age rule
                    os.utime(part, (old, old))
                    removed.extend(remove_stale_parts(tmp_path))
                yield image[top:top + 16, left:left + 16]

    TiledTiffWriter(tmp_path / "r.tif", image.shape, image.dtype, 16).write(pieces())
    assert removed == []
    np.testing.assert_array_equal(read_image(tmp_path / "r.tif"), image)
    assert [p.name for p in tmp_path.iterdir()] == ["r.tif"]
