"""What ``aarecovery bench`` measures: each stage of a recovery, throughput per GL path and NumPy.

For each generated pair (:func:`bench_image_pair`) it times the stages a file-to-file run goes
through: decode (both PNG files, in parallel as ``aarecovery recover`` does), plan (the safe
default's analysis; the paper's method needs none), upload, classify (the active blocks, on
the GPU), passes, readback (into F's layout), encode (the PNG file). Each engine
configuration (:data:`CONFIGS`) also gets an end-to-end figure, as a caller waits for it:
``set_images``, the passes and ``result``, uninstrumented, for the paper's method and the
safe default (the plan made beforehand). Whole processes file to file are
:mod:`aarecovery.lab.processes`.

Each figure is the median of several runs after a warm-up run; ratios come from one run of
the command, because the machines are shared and two runs of the same code differ by 15-20%.
"""

import os
import platform
import statistics
import tempfile
import time
from collections import defaultdict
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ..colour import luma
from ..errors import InputError

__all__ = ["DEFAULT_SIZES", "CONFIGS", "STAGES", "bench_image_pair", "machine", "run_bench"]

DEFAULT_SIZES = ((1920, 1080), (4096, 4096))
#: Engine configurations: the GL backend on each path (and the compute path with its fit's
#: neighbourhoods in shared memory, off by default), and NumPy.
CONFIGS = {"gl-fragment": dict(backend="gl", gl_path="fragment"), "gl-compute": dict(backend="gl", gl_path="compute"),
           "gl-compute-shared": dict(backend="gl", gl_path="compute", shared_tile=True),
           "numpy": dict(backend="numpy")}
DEFAULT_CONFIGS = ("gl-fragment", "gl-compute", "numpy")
#: The stages of a file-to-file recovery, in order.
STAGES = ("decode", "plan", "upload", "classify", "passes", "readback", "encode")


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


def _median_seconds(work, runs):
    """Median seconds of `runs` calls of `work` after a warm-up call, and its last result."""
    result = work()
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        result = work()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result


class _StageClock:
    """Adds up the seconds between the marks a backend makes (``GLBackend.stage_clock``)."""

    def __init__(self):
        self.seconds = defaultdict(float)
        self._last = None

    def start(self):
        self._last = time.perf_counter()

    def __call__(self, name):
        now = time.perf_counter()
        self.seconds[name] += now - self._last
        self._last = now


def _make_engine(config):
    from ..engine import Engine
    options = dict(CONFIGS[config])
    shared_tile = options.pop("shared_tile", False)
    engine = Engine(**options)
    if shared_tile:
        engine._impl.shared_tile = True
    return engine


def _stages(engine, original, filtered, plan, runs):
    """Median seconds per stage of ``set_images + run + result``, each stage waited for."""
    clock = _StageClock()
    instrumented = hasattr(engine._impl, "stage_clock")
    if instrumented:
        engine._impl.stage_clock = clock
    per_run = []
    try:
        for run in range(runs + 1):
            clock.seconds.clear()
            clock.start()
            engine.set_images(original, filtered, blend_space=plan.blend_space)
            if not instrumented:
                clock("upload")
            clock.start()
            engine.run(plan)
            if not instrumented:
                clock("passes")
            clock.start()
            engine.result()
            clock("readback")
            if run:
                per_run.append(dict(clock.seconds))
    finally:
        if instrumented:
            engine._impl.stage_clock = None
    return {stage: statistics.median(seconds.get(stage, 0.0) for seconds in per_run)
            for stage in ("upload", "classify", "passes", "readback")}


def _passes(engine, original, filtered, plan, runs):
    """Median milliseconds of each GL pass of ``run(plan)``, each waited for on its own
    (``GLBackend.pass_clock``): the device's time per pass, without what issuing them costs."""
    per_run = []
    seconds = defaultdict(float)
    engine._impl.pass_clock = lambda label, taken: seconds.__setitem__(label, seconds[label] + taken)
    try:
        for run in range(runs + 1):
            seconds.clear()
            engine.set_images(original, filtered, blend_space=plan.blend_space)
            engine.run(plan)
            if run:
                per_run.append(dict(seconds))
    finally:
        engine._impl.pass_clock = None
    return {label: statistics.median(times.get(label, 0.0) for times in per_run) * 1000 for label in per_run[0]}


def _end_to_end(engine, original, filtered, plan, runs):
    def recover():
        engine.set_images(original, filtered, blend_space=plan.blend_space)
        engine.run(plan)
        return engine.result()
    return _median_seconds(recover, runs)


def _file_stages(original, filtered, runs):
    """Median seconds to decode the pair's PNG files (in parallel) and to encode one."""
    from ..io import read_image, write_image
    with tempfile.TemporaryDirectory() as folder:
        paths = [os.path.join(folder, name) for name in ("o.png", "f.png")]
        encode, _ = _median_seconds(lambda: write_image(paths[1], filtered), runs)
        write_image(paths[0], original)

        def decode():
            with ThreadPoolExecutor(max_workers=2) as pool:
                return list(pool.map(read_image, paths))
        decode_seconds, _ = _median_seconds(decode, runs)
    return decode_seconds, encode


def machine():
    cores = os.cpu_count()
    try:
        with open("/proc/cpuinfo") as info:
            model = next(line.split(":", 1)[1].strip() for line in info if line.startswith("model name"))
    except (OSError, StopIteration):
        model = platform.processor() or platform.machine()
    return f"{model}, {cores} cores, Python {platform.python_version()}"


def _log_row(log, config, figures, pixels):
    stages = figures["stages"]
    cells = "  ".join(f"{stages[stage] * 1000:8.1f}" for stage in ("upload", "classify", "passes", "readback"))
    log(f"  {config:18s}{cells}  {figures['passes_mps']:9.1f}  {figures['paper_mps']:8.2f}  "
        f"{figures['safe_mps']:8.2f}")


def _log_passes(log, config, mode, milliseconds, pixels):
    total = sum(milliseconds.values())
    cells = ", ".join(f"{label} {value:.2f}" for label, value in milliseconds.items())
    log(f"  {config} {mode}, each pass waited for (ms): {cells}; sum {total:.2f} ms, {pixels / total / 1e3:.1f} MP/s")


def run_bench(sizes, configs, filters, runs, *, passes=False, log=print):
    """Measure every stage and configuration on generated pairs; return the report.

    Parameters
    ----------
    sizes : list of (int, int)
        ``(width, height)`` pairs.
    configs : list of str
        Keys of :data:`CONFIGS`; one that cannot start (no GL 4.3 for the compute path) is
        reported, not fatal.
    filters : list of str
        ``"threshold"`` and/or ``"gamma"`` (see :func:`bench_image_pair`).
    runs : int
        Timed runs per figure after a warm-up; NumPy gets a third.
    passes : bool
        Also time each GL pass on its own, waited for before and after, for the paper's
        method and the safe default (the device's time per pass: the stage figures add what
        issuing the passes costs).
    log : callable
        Gets the report line by line.

    Returns
    -------
    dict
        ``machine``, ``gl_renderer``, ``results`` (per filter and size: the decode, plan and
        encode seconds, and per configuration the stage seconds, the passes' megapixels per
        second (classify and passes) and end-to-end megapixels per second for the paper's
        method and the safe default; with `passes`, ``passes_ms``: per mode each pass's
        milliseconds).
    """
    from ..params import Parameters
    from ..plan import make_plan
    report = {"machine": machine(), "results": []}
    log(f"machine: {report['machine']}")
    engines = {}
    for config in configs:
        try:
            engines[config] = _make_engine(config)
        except InputError as error:  # a missing backend or path is reported, not fatal while another runs
            if len(configs) == 1 or (not engines and config == configs[-1]):
                raise
            log(f"{config}: not available ({error})")
    gl = next((engine for engine in engines.values() if engine.backend == "gl"), None)
    if gl is not None:
        info = gl.context.info
        report["gl_renderer"] = f"{info['GL_RENDERER']} / {info['GL_VERSION']}"
        log(f"gl: {report['gl_renderer']}")
    for filter_name in filters:
        for width, height in sizes:
            pixels = width * height
            original, filtered = bench_image_pair(width, height, filter_name)
            plan_seconds, safe = _median_seconds(
                lambda: make_plan(original, filtered, Parameters(), mode="safe"), max(1, runs // 2))
            paper = make_plan(original, filtered, Parameters(), mode="paper")
            decode, encode = _file_stages(original, filtered, max(1, runs // 2))
            row = {"filter": filter_name, "size": f"{width}x{height}", "decode_s": decode, "plan_s": plan_seconds,
                   "encode_s": encode, "safe_plan": safe.reason, "configs": {}}
            log(f"{filter_name} {width}x{height}: decode {decode:.3f} s, safe plan {plan_seconds:.3f} s "
                f"({safe.blend_space}, strength {safe.strength:g}), encode {encode:.3f} s")
            log(f"  {'ms (safe default)':18s}{'upload':>8s}  {'classify':>8s}  {'passes':>8s}  {'readback':>8s}  "
                f"{'passes MP/s':>11s}  {'paper MP/s':>10s}  {'safe MP/s':>9s}")
            for config, engine in engines.items():
                timed = runs if engine.backend == "gl" else max(1, runs // 3)
                stages = _stages(engine, original, filtered, safe, timed)
                paper_seconds, _ = _end_to_end(engine, original, filtered, paper, timed)
                safe_seconds, _ = _end_to_end(engine, original, filtered, safe, timed)
                figures = {"stages": stages, "passes_mps": pixels / (stages["classify"] + stages["passes"]) / 1e6,
                           "paper_mps": pixels / paper_seconds / 1e6, "safe_mps": pixels / safe_seconds / 1e6}
                row["configs"][config] = figures
                _log_row(log, config, figures, pixels)
                if passes and engine.backend == "gl":
                    figures["passes_ms"] = {mode: _passes(engine, original, filtered, plan, timed)
                                            for mode, plan in (("paper", paper), ("safe", safe))}
                    for mode, milliseconds in figures["passes_ms"].items():
                        _log_passes(log, config, mode, milliseconds, pixels)
            report["results"].append(row)
    for engine in engines.values():
        engine.release()
    return report
