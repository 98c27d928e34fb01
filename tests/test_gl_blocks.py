"""The block classification on the GPU gives exactly the NumPy block lists (``blocks.py``).

Both ways the backend classifies: compute shaders with indirect commands (GL 4.3), and a
fragment pass's block mask listed on the CPU (GL 3.3 to 4.2), forced on llvmpipe.
"""

import numpy as np
import pytest

import aarecovery
from aarecovery.backends.gl.blocks import LISTS, active_blocks, active_mask, block_lists, expand_runs
from gl_blocks import dispatch_sizes, gpu_lists
from parity import assert_results_agree

pytestmark = pytest.mark.gl


def _images():
    rng = np.random.default_rng(11)
    yield "flat", np.full((40, 56, 3), 90, np.uint8)
    for height, width in ((1, 1), (17, 33), (40, 16), (100, 3), (31, 47)):
        dots = (rng.random((height, width, 3)) > 0.97).astype(np.uint8) * 255
        yield f"dots-{height}x{width}", dots
    lone = np.zeros((64, 64), np.uint16)
    for y, x in ((0, 0), (17, 14), (18, 33), (47, 47), (63, 30), (30, 63), (15, 1)):
        lone[y, x] = 1000  # single pixels at block sides and corners: the margin decides
    yield "lone-pixels-uint16-grey", lone
    yield "noise-float-grey-alpha", rng.random((37, 29, 2)).astype(np.float32)
    ramp = np.tile(np.arange(70, dtype=np.uint8)[:, None, None], (1, 50, 4))
    ramp[:, 20:] = 7
    yield "ramp-rgba", ramp


IMAGES = list(_images())


def _uploaded(image):
    dtype = image.dtype if image.dtype in (np.uint8, np.uint16) else np.float32
    return np.ascontiguousarray(image.reshape(image.shape[0], image.shape[1], -1), dtype=dtype)


@pytest.fixture(scope="module", params=["compute-runs", "compute-blocks", "fragment-mask-runs", "fragment-mask-blocks"])
def classifying_engine(request):
    engine = aarecovery.Engine(backend="gl", gl_path="fragment")
    engine._impl._classifier.compute = request.param.startswith("compute")
    engine._impl._classifier.runs = request.param.endswith("runs")
    yield engine
    engine.release()


@pytest.mark.parametrize("name, image", IMAGES, ids=[name for name, _ in IMAGES])
def test_gpu_lists_equal_numpy_lists(classifying_engine, name, image):
    flat = np.zeros_like(image)
    classifying_engine.set_images(image, flat)
    impl = classifying_engine._impl
    with classifying_engine.context:
        found = {which: gpu_lists(impl, which, raw=True) for which in ("original", "filtered")}
        dispatches = dispatch_sizes(impl, "original")
    for which, pixels in (("original", image), ("filtered", flat)):
        expected = block_lists(active_mask(_uploaded(pixels)), runs=impl._classifier.runs)
        for list_name in LISTS:
            assert sorted(map(tuple, found[which][list_name])) == sorted(map(tuple, expected[list_name])), \
                (which, list_name)
    for list_name in LISTS:
        length = len(found["original"][list_name])
        assert dispatches[list_name] == (length, int(length > 0), 1)


def test_numpy_lists_are_consistent():
    # The dilated list holds every active block and its 8 neighbours; active and inactive split
    # the grid; runs hold the same blocks.
    image = _uploaded(IMAGES[2][1])
    mask = active_mask(image)
    lists = block_lists(mask)
    for name, runs in block_lists(mask, runs=True).items():
        assert sorted(map(tuple, expand_runs(runs))) == sorted(map(tuple, lists[name]))
    assert sorted(map(tuple, lists["active"])) == sorted(map(tuple, active_blocks(image)))
    assert len(lists["active"]) + len(lists["inactive"]) == mask.size
    dilated = set(map(tuple, lists["dilated"]))
    for column, row in lists["active"]:
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                if 0 <= row + dy < mask.shape[0] and 0 <= column + dx < mask.shape[1]:
                    assert (column + dx, row + dy) in dilated


@pytest.mark.parametrize("compute_classification", [True, False])
def test_long_lists_dispatch_in_rows(compute_classification):
    # A list longer than a dispatch row allows (65535 groups; 7 here) runs in rows of work
    # groups, spread evenly: fewer groups past the list's end than there are rows.
    from test_gl_parity import PAIRS
    engine = aarecovery.Engine(backend="gl", gl_path="compute")
    try:
        engine._impl._classifier.compute = compute_classification
        engine._impl._classifier.max_groups = 7
        for _, original, filtered in PAIRS:
            engine.set_images(original, filtered)
            with engine.context:
                sizes = dispatch_sizes(engine._impl, "filtered")
                entries = gpu_lists(engine._impl, "filtered", raw=True)
            assert any(size[1] > 1 for size in sizes.values())
            for name, (columns, rows, depth) in sizes.items():
                length = len(entries[name])
                assert columns <= 7 and depth == 1 and 0 <= columns * rows - length < max(rows, 1), (name, sizes)
            for mode in ("paper", "safe"):
                actual = aarecovery.recover(original, filtered, engine=engine, mode=mode)
                expected = aarecovery.recover(original, filtered, backend="numpy", mode=mode)
                assert_results_agree(actual, expected)
    finally:
        engine.release()
