"""What ``aarecovery bench`` measures: end-to-end throughput of each backend, and peak memory of ``recover``.

End to end means what a caller waits for: upload of O and F, every pass, and the readback of
R. Each figure is the median of several runs after a warm-up run, in megapixels per second;
the GL/NumPy ratio comes from the same run of the command, because the machines are shared
and two runs of the same code differ by 15-20%.
"""

import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

from ..colour import luma
from ..errors import InputError

__all__ = ["DEFAULT_SIZES", "bench_image_pair", "measure_throughput", "run_bench"]

DEFAULT_SIZES = ((1920, 1080), (4096, 4096))


def bench_image_pair(width, height, filter_name="threshold", seed=0):
    """A photo-like 8-bit RGB pair: antialiased shapes and strokes over a soft gradient with
    sensor noise, and its filtered version.

    Parameters
    ----------
    width, height : int
    filter_name : {"threshold", "gamma"}
        ``"threshold"`` leaves F flat away from edges (the method's main use, where flat F
        is skipped); ``"gamma"`` keeps the noise in F, so every pixel is fitted: the worst case.

    Returns
    -------
    original, filtered : ndarray of uint8, shape (height, width, 3)
    """
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:height, 0:width].astype(np.float32)
    base = np.stack([x / width, y / height, 0.5 + 0.3 * np.sin(x / 97.0) * np.cos(y / 131.0)], -1)
    image = (0.25 + 0.5 * base).astype(np.float32)
    coverage = np.zeros((height, width), np.float32)
    for _ in range(max(8, width * height // 40000)):
        cx, cy = rng.random() * width, rng.random() * height
        radius = 4 + rng.random() * min(width, height) / 12
        top, bottom = int(max(0, cy - radius - 2)), int(min(height, cy + radius + 2))
        left, right = int(max(0, cx - radius - 2)), int(min(width, cx + radius + 2))
        distance = np.hypot(x[top:bottom, left:right] - cx, y[top:bottom, left:right] - cy)
        # The distance to the circle gives an analytic box-filter coverage within a pixel.
        inside = np.clip(radius - distance + 0.5, 0, 1)
        colour = rng.random(3).astype(np.float32)
        patch = image[top:bottom, left:right]
        patch += inside[..., None] * (colour - patch)
        coverage[top:bottom, left:right] = np.maximum(coverage[top:bottom, left:right], inside)
    image += rng.normal(0, 1.5 / 255, image.shape).astype(np.float32)
    original = np.rint(np.clip(image, 0, 1) * 255).astype(np.uint8)
    if filter_name == "threshold":
        filtered = np.where(luma(original.astype(np.float32))[..., None] > 127.5, 255, 0).astype(np.uint8).repeat(3, -1)
    elif filter_name == "gamma":
        filtered = np.rint(255 * (original / np.float32(255)) ** 2.2).astype(np.uint8)
    else:
        raise ValueError(f"unknown bench filter {filter_name!r}; use threshold or gamma")
    return original, filtered


def measure_throughput(engine, original, filtered, runs, mode="paper"):
    """Median end-to-end seconds of ``set_images + compute + result`` after one warm-up run."""
    times = []
    for run in range(runs + 1):
        start = time.perf_counter()
        engine.set_images(original, filtered)
        engine.compute(mode=mode)
        engine.result()
        if run:
            times.append(time.perf_counter() - start)
    return statistics.median(times)


# Runs a command and prints the peak resident memory of its process tree. It runs in a small
# Python of its own: a child forked from this (large) process would count this process's
# pages in its own peak until it executes the command.
_MEASURE = """
import resource, subprocess, sys
subprocess.run(sys.argv[1:], check=True, stdout=subprocess.DEVNULL)
peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
print(peak if sys.platform == "darwin" else peak * 1024)
"""


def _peak_memory_of_recover(width, height):
    """Peak resident memory (bytes) and seconds of ``aarecovery recover`` on a width x height RGB pair."""
    from ..io import write_image
    original, filtered = bench_image_pair(width, height)
    with tempfile.TemporaryDirectory() as folder:
        paths = [os.path.join(folder, name) for name in ("o.png", "f.png", "r.png")]
        write_image(paths[0], original)
        write_image(paths[1], filtered)
        del original, filtered
        start = time.perf_counter()
        measured = subprocess.run([sys.executable, "-c", _MEASURE, sys.executable, "-m", "aarecovery", "recover",
                                   paths[0], paths[1], "-o", paths[2]], check=True, capture_output=True, text=True)
        seconds = time.perf_counter() - start
    return int(measured.stdout.strip()), seconds


def _machine():
    cores = os.cpu_count()
    try:
        with open("/proc/cpuinfo") as info:
            model = next(line.split(":", 1)[1].strip() for line in info if line.startswith("model name"))
    except (OSError, StopIteration):
        model = platform.processor() or platform.machine()
    return f"{model}, {cores} cores, Python {platform.python_version()}"


def run_bench(sizes, backends, filters, runs, *, safe=False, memory=None, log=print):
    """Measure each backend on generated pairs; return the report printed line by line to `log`.

    Parameters
    ----------
    sizes : list of (int, int)
        ``(width, height)`` pairs.
    backends : list of str
        Backend names; one that cannot start is reported, not fatal.
    filters : list of str
        ``"threshold"`` and/or ``"gamma"`` (see :func:`bench_image_pair`).
    runs : int
        Timed GL runs per size; NumPy gets half.
    safe : bool
        Also time the default mode.
    memory : (int, int), optional
        Also measure the peak memory of ``aarecovery recover`` at this size.

    Returns
    -------
    dict
        ``machine``, ``gl_renderer``, ``results`` (one row per filter and size, MP/s per
        backend and the GL/NumPy ratio) and ``memory``.
    """
    from ..engine import Engine
    report = {"machine": _machine(), "results": []}
    log(f"machine: {report['machine']}")
    engines = {}
    for name in backends:
        try:
            engines[name] = Engine(backend=name)
        except InputError as error:  # a missing backend is reported, not fatal while another runs
            if len(backends) == 1 or (not engines and name == backends[-1]):
                raise
            log(f"{name}: not available: {error}")
    if "gl" in engines:
        info = engines["gl"].context.info
        report["gl_renderer"] = f"{info['GL_RENDERER']} / {info['GL_VERSION']}"
        log(f"gl: {report['gl_renderer']}")
    for filter_name in filters:
        for width, height in sizes:
            original, filtered = bench_image_pair(width, height, filter_name)
            row = {"filter": filter_name, "size": f"{width}x{height}"}
            for name, engine in engines.items():
                timed = runs if name == "gl" else max(1, runs // 2)
                seconds = measure_throughput(engine, original, filtered, timed, mode="paper")
                row[name] = width * height / seconds / 1e6
                if name == "gl" and safe:
                    safe_seconds = measure_throughput(engine, original, filtered, max(1, timed // 2), mode="safe")
                    row["gl_safe"] = width * height / safe_seconds / 1e6
            if "gl" in row and "numpy" in row:
                row["ratio"] = row["gl"] / row["numpy"]
            report["results"].append(row)
            cells = "  ".join(f"{key} {value:7.2f}" + (" MP/s" if key != "ratio" else "x")
                              for key, value in row.items() if isinstance(value, float))
            log(f"{filter_name:9s} {width}x{height:<6d} {cells}")
    for engine in engines.values():
        engine.release()
    if memory:
        width, height = memory
        peak, seconds = _peak_memory_of_recover(width, height)
        report["memory"] = {"size": f"{width}x{height}", "peak_bytes": peak, "seconds": seconds}
        log(f"peak memory of 'aarecovery recover' on a {width}x{height} RGB pair: {peak / 2**30:.2f} GiB "
            f"({seconds:.1f} s)")
    return report
