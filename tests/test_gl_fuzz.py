"""GL against the NumPy specification on random scenes, sizes, tiles, paths and modes.

Each case is drawn from its own seed: a scene (straight edges, thin lines, noise, flat areas,
or all of them), a size from 1 pixel up (odd, tiny, thin), a dtype (8-bit, 16-bit, float),
grey or colour with or without alpha, a filter, a mode (paper or safe), 0, 1 or the default
iterations and a tile size (the backend's, the smallest the iterations allow, or one between);
both GL paths run it. R and the maps must agree within ``tests/parity.py``'s table.

CI runs a few cases; ``--parity-cases N`` (or ``AARECOVERY_PARITY_CASES=N``) runs more, and
``--parity-seed S`` starts elsewhere. A failure names its seed: ``-k 'seed-1234'`` reruns it.
"""

import warnings

import numpy as np
import pytest

import aarecovery
from aarecovery.filters import apply
from aarecovery.params import ITERATIONS
from aarecovery.tiling import halo_for, smallest_tile
from parity import assert_maps_agree, assert_results_agree

pytestmark = pytest.mark.gl

FILTERS = ("threshold", "gamma", "posterize", "gradientmap", "tonemap", "equalize", "unsharp")
SIDES = (1, 2, 3, 4, 5, 7, 16, 17, 33, 63, 64, 65, 97, 130)


def _scene(rng, height, width):
    """Float RGB in [0, 1]: analytic box-filtered edges and lines, noise, or a flat field."""
    kind = rng.choice(["edges", "lines", "noise", "flat", "all"])
    image = np.broadcast_to(rng.random(3, dtype=np.float32), (height, width, 3)).copy()
    y, x = np.mgrid[0:height, 0:width].astype(np.float32)
    if kind in ("edges", "all"):
        for _ in range(rng.integers(1, 4)):
            angle, offset = rng.random() * np.pi, rng.random() * (height + width) / 2
            coverage = np.clip(np.cos(angle) * x + np.sin(angle) * y - offset + 0.5, 0, 1)[..., None]
            image += coverage * (rng.random(3, dtype=np.float32) - image)
    if kind in ("lines", "all"):
        for _ in range(rng.integers(1, 5)):
            angle, offset, line_width = rng.random() * np.pi, rng.random() * (height + width) / 2, rng.uniform(0.3, 2)
            distance = np.abs(np.cos(angle) * x + np.sin(angle) * y - offset)
            coverage = np.clip(line_width / 2 + 0.5 - distance, 0, 1)[..., None]
            image += coverage * (rng.random(3, dtype=np.float32) - image)
    if kind in ("noise", "all"):
        image += rng.normal(0, rng.uniform(0.005, 0.1), image.shape).astype(np.float32)
    if kind == "flat" and rng.random() < 0.5:
        image[rng.integers(height), rng.integers(width)] = rng.random(3)
    return str(kind), np.clip(image, 0, 1)


def _in_layout(rng, image):
    """`image` as grey, RGB or RGBA, in 8-bit, 16-bit or float."""
    channels = int(rng.choice([1, 3, 3, 4]))
    if channels == 1:
        image = image.mean(axis=-1)
    elif channels == 4:
        alpha = rng.choice([1.0, 0.0, 0.5]) if rng.random() < 0.7 else rng.random(image.shape[:2])
        image = np.concatenate([image, np.broadcast_to(np.float32(1) * alpha, image.shape[:2])[..., None]], -1)
    dtype = rng.choice(["uint8", "uint8", "uint16", "float32"])
    if dtype == "float32":
        return image.astype(np.float32)
    top = np.iinfo(dtype).max
    return np.rint(image * top).astype(dtype)


def _tile_size(rng, iterations, height, width, most_tiles=64):
    """None (the backend's own), the smallest tile the iterations allow, or one between, made
    large enough that the image takes at most `most_tiles` tiles (each a run of the passes)."""
    smallest = smallest_tile(iterations)
    tile = rng.choice([None, smallest, int(rng.integers(smallest, 80))])
    if tile is None:
        return None
    while -(-height // (tile - 2 * halo_for(iterations))) * -(-width // (tile - 2 * halo_for(iterations))) > most_tiles:
        tile += 1
    return int(tile)


def case(seed):
    """The pair and the recovery arguments of case `seed`."""
    rng = np.random.default_rng(seed)
    height, width = int(rng.choice(SIDES)), int(rng.choice(SIDES))
    kind, image = _scene(rng, height, width)
    original = _in_layout(rng, image)
    filter_name = str(rng.choice(FILTERS))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        filtered = apply(filter_name, original)
    iterations = int(rng.choice([0, 1, ITERATIONS.default]))
    arguments = dict(mode=str(rng.choice(["paper", "safe"])), iterations=iterations,
                     tile_size=_tile_size(rng, iterations, height, width))
    label = f"{kind} {original.shape} {original.dtype} {filter_name} {arguments}"
    return original, filtered, arguments, label


def pytest_generate_tests(metafunc):
    if "seed" in metafunc.fixturenames:
        start = metafunc.config.getoption("--parity-seed")
        count = metafunc.config.getoption("--parity-cases")
        metafunc.parametrize("seed", range(start, start + count), ids=lambda seed: f"seed-{seed}")


@pytest.fixture(scope="module")
def gl_engine(gl_path):
    engine = aarecovery.Engine(backend="gl", gl_path=gl_path)
    yield engine
    engine.release()


def test_gl_agrees_with_numpy(gl_engine, seed):
    original, filtered, arguments, label = case(seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # tiny tiles and order doubts warn; both backends alike
        expected, expected_maps = aarecovery.recover(original, filtered, backend="numpy", return_maps=True,
                                                     **arguments)
        actual, maps = aarecovery.recover(original, filtered, engine=gl_engine, return_maps=True, **arguments)
    assert_results_agree(actual, expected, label)
    assert_maps_agree(maps, expected_maps, message=label)
