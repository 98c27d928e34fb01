"""What ``aarecovery bench --batch`` and ``--gigapixel`` measure: the batch and the streamed path.

``--batch N``: N pairs of 1920 x 1080 PNG files through one ``aarecovery batch`` command,
against N separate ``aarecovery recover`` commands, in images per second, from the same
run; and ``batch`` with 1 to 4 workers, and on a Dask ``LocalCluster`` where Dask is
installed. ``--gigapixel WxH``: a pair of tiled TIFFs
through ``aarecovery recover``, streamed tile by tile, its time and peak resident memory.
Every figure is of a command in its own process, as a user runs it.
"""

import importlib.util
import math
import os
import subprocess
import sys
import time

import numpy as np

from .bench import bench_image_pair

__all__ = ["write_tiled_pair", "write_png_pairs", "measure_command", "bench_batch", "bench_gigapixel"]

# The generated gigapixel pair: a 4096 x 4096 photo-like pair, thresholded, repeated across
# the image mirrored (every other copy flipped), so that the content runs on without seams.
# It is written in tiles of 512, each compressed once per block and orientation (zstd,
# level 1) and written as it is: a 50000 x 50000 pair (2.5 gigapixels, 7.5 GB per image
# uncompressed) is written at disk speed and never held in memory.
_GIGAPIXEL_TILE = 512
_GIGAPIXEL_BASE = 4096


# Runs a command and prints its peak resident memory (bytes), wall seconds and CPU seconds
# (user and system, all its threads and children). In a small Python of its own: a child
# forked from this (large) process would count this process's pages.
_MEASURE = """
import resource, subprocess, sys, time
start = time.perf_counter()
subprocess.run(sys.argv[1:], check=True, stdout=subprocess.DEVNULL)
seconds = time.perf_counter() - start
usage = resource.getrusage(resource.RUSAGE_CHILDREN)
peak = usage.ru_maxrss
print(peak if sys.platform == "darwin" else peak * 1024, seconds, usage.ru_utime + usage.ru_stime)
"""


def measure_command(command, env=None, cpu=False):
    """Peak resident memory (bytes) and wall seconds of `command` (a list), run in its own
    process; with `cpu`, also its CPU seconds (a figure the machine's other jobs move less)."""
    measured = subprocess.run([sys.executable, "-c", _MEASURE, *command], check=True, capture_output=True,
                              text=True, env=env)
    peak, seconds, cpu_seconds = measured.stdout.split()
    return (int(peak), float(seconds), float(cpu_seconds)) if cpu else (int(peak), float(seconds))


def _mirrored(start, tile, side):
    """Where the tile at `start` (along one axis) comes from in the base: first index and step."""
    copy, offset = divmod(start, side)
    return (offset, 1) if copy % 2 == 0 else (side - offset - tile, -1)


def _mirrored_tiles(image, width, height):
    """The compressed tiles of the mirrored repetition of `image`, in row-major order.

    Tiles are always whole (pre-compressed tiles cannot be cut), and each distinct one is
    compressed once.
    """
    import imagecodecs

    tile, side = _GIGAPIXEL_TILE, _GIGAPIXEL_BASE
    encoded = {}
    for top in range(0, height, tile):
        for left in range(0, width, tile):
            key = _mirrored(top, tile, side) + _mirrored(left, tile, side)
            if key not in encoded:
                rows, row_step, cols, col_step = key
                piece = image[rows:rows + tile, cols:cols + tile][::row_step, ::col_step]
                encoded[key] = imagecodecs.zstd_encode(np.ascontiguousarray(piece), level=1)
            yield encoded[key]


def write_tiled_pair(folder, width, height, seed=0):
    """Write a photo-like 8-bit RGB pair (original, thresholded) as tiled TIFFs, tile by tile.

    Returns
    -------
    original, filtered : str
        The two paths (``o.tif`` and ``f.tif`` in `folder`), BigTIFF when over 4 GB.
    """
    import tifffile

    base = bench_image_pair(_GIGAPIXEL_BASE, _GIGAPIXEL_BASE, "threshold", seed=seed)
    paths = [os.path.join(folder, name) for name in ("o.tif", "f.tif")]

    for path, image in zip(paths, base):
        with tifffile.TiffWriter(path, bigtiff=width * height * 3 > 2**32 - 2**25) as tif:
            tif.write(_mirrored_tiles(image, width, height), shape=(height, width, 3), dtype=np.uint8,
                      tile=(_GIGAPIXEL_TILE, _GIGAPIXEL_TILE), photometric="rgb",
                      compression="zstd", metadata=None)
    return paths[0], paths[1]


def write_png_pairs(folder, count, width=1920, height=1080):
    """`count` different photo-like pairs as PNG files in ``folder/originals`` and ``folder/filtered``."""
    from ..io import write_image

    for sub in ("originals", "filtered"):
        os.makedirs(os.path.join(folder, sub), exist_ok=True)
    # Generating a pair costs more than recovering it; 8 distinct pairs, shifted and
    # flipped, give every file different pixels.
    bases = [bench_image_pair(width, height, "threshold", seed=seed) for seed in range(min(count, 8))]
    names = []
    for index in range(count):
        original, filtered = bases[index % len(bases)]
        shift = (index // len(bases)) * 37
        flip = slice(None, None, -1 if (index // len(bases)) % 2 else 1)
        name = f"image{index:04d}.png"
        for sub, image in (("originals", original), ("filtered", filtered)):
            write_image(os.path.join(folder, sub, name), np.roll(image, shift, axis=1)[:, flip])
        names.append(name)
    return names


def _command(*args):
    return [sys.executable, "-m", "aarecovery", *args]


def bench_batch(folder, count, workers=(1, 2, 3, 4), log=print):
    """Images per second of ``batch`` (with each number of workers) and of separate ``recover`` calls.

    Returns
    -------
    dict
        ``separate`` and ``batch`` (the default workers) images per second, ``ratio``, and
        ``workers``: images per second per worker count.
    """
    import tempfile

    names = write_png_pairs(folder, count)
    originals, filtered = os.path.join(folder, "originals"), os.path.join(folder, "filtered")
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(dir=folder) as out:
        for name in names:
            subprocess.run(_command("recover", os.path.join(originals, name), os.path.join(filtered, name),
                                    "-o", os.path.join(out, name)), check=True, stdout=subprocess.DEVNULL)
    separate = count / (time.perf_counter() - start)
    log(f"{count} separate 'aarecovery recover' calls: {separate:.2f} images/s")
    report = {"count": count, "separate": separate, "workers": {}}
    runs = [(None, []), *((number, ["--workers", str(number)]) for number in workers)]
    if importlib.util.find_spec("distributed") is not None:
        runs.append(("dask", ["--dask", "local"]))
    for label, extra in runs:
        with tempfile.TemporaryDirectory(dir=folder) as out:
            _, seconds = measure_command(_command("batch", originals, filtered, "-o", out, *extra))
        rate = count / seconds
        if label is None:
            report["batch"], report["ratio"] = rate, rate / separate
            log(f"one 'aarecovery batch' (default workers): {rate:.2f} images/s, {rate / separate:.2f}x")
        elif label == "dask":
            report["dask_local"] = rate
            log(f"  batch --dask local (a LocalCluster on this machine): {rate:.2f} images/s")
        else:
            report["workers"][label] = rate
            log(f"  batch --workers {label}: {rate:.2f} images/s")
    return report


def bench_gigapixel(folder, width, height, log=print):
    """Time and peak memory of ``aarecovery recover`` streaming a tiled-TIFF pair of this size."""
    start = time.perf_counter()
    original, filtered = write_tiled_pair(folder, width, height)
    log(f"wrote a {width}x{height} tiled TIFF pair in {time.perf_counter() - start:.1f} s")
    output = os.path.join(folder, "r.tif")
    # A genuine pair over the decode limit (50000 x 50000 RGB: 7.5 GB per image) raises it, as a user would.
    declared_gigabytes = math.ceil(width * height * 3 / 1e9) + 1
    peak, seconds = measure_command(_command("recover", original, filtered, "-o", output, "--max-image-memory",
                                             str(declared_gigabytes)))
    log(f"'aarecovery recover' streamed it in {seconds:.1f} s ({width * height / seconds / 1e6:.1f} MP/s), "
        f"peak memory {peak / 2**30:.2f} GiB")
    os.unlink(output)
    return {"size": f"{width}x{height}", "seconds": seconds, "peak_bytes": peak}
