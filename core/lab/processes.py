"""``aarecovery bench --process``: whole processes file to file, the product against what users run instead.

On two kinds of 8-bit RGB PNG pair (:data:`PAIRS`), each command runs as a process of its
own, as a user runs it, timed with its peak resident memory:

* ``safe``: ``aarecovery recover O F -o R``, the default;
* ``paper``: the same with ``--paper``, the published method;
* ``gegl``: GIMP's Filters > Enhance > Antialias, ``gegl:antialias`` on F alone through the
  ``gegl`` command (Debian's ``gegl`` package; skipped with a message when absent);
* ``numpy-paper``: :mod:`aarecovery.lab.paper_numpy`, the paper's method as straightforward
  NumPy.

The machines are shared, so the commands run in turn (safe, paper, gegl, numpy-paper, then
again) and each figure is the median of its runs: the ratios then hold while the load
drifts. The CPU seconds of each process (all its threads) are reported beside the wall
seconds: on a loaded machine they move less. The NumPy program is slow and runs once per
pair unless more runs are asked for.
"""

import os
import statistics
import sys
import tempfile
import time
from shutil import which

import numpy as np

from ..colour import luma
from .scale import measure_command

__all__ = ["PAIRS", "COMMANDS", "RATIOS", "thin_features_pair", "bench_processes"]

#: The commands timed, in the order they run.
COMMANDS = ("safe", "paper", "gegl", "numpy-paper")
#: The ratios printed: (name, numerator, denominator), of median seconds.
RATIOS = (("safe/paper", "safe", "paper"), ("safe/gegl", "safe", "gegl"), ("numpy-paper/safe", "numpy-paper", "safe"))
_GEGL_MISSING = "gegl is not installed (Debian package gegl): gegl:antialias skipped"


def thin_features_pair(width, height, seed=0):
    """Random filled shapes and strokes, antialiased by drawing at 2x and box-downsampling,
    then thresholded: the pair where the safe default picks pure colours of thin features.

    Returns
    -------
    original, filtered : ndarray of uint8, shape (height, width, 3)
    """
    from PIL import Image, ImageDraw
    rng = np.random.default_rng(seed)
    big_width, big_height = 2 * width, 2 * height
    image = Image.new("RGB", (big_width, big_height), (255, 255, 255))
    draw = ImageDraw.Draw(image)
    for i in range(max(8, width * height // 20000)):
        colour = tuple(int(v) for v in rng.integers(0, 256, 3))
        cx, cy = rng.uniform(0, big_width), rng.uniform(0, big_height)
        size = rng.uniform(4, 0.05 * min(big_width, big_height) + 4)
        kind = i % 4
        if kind == 0:
            draw.ellipse((cx - size, cy - size * rng.uniform(0.3, 1), cx + size, cy + size), fill=colour)
        elif kind == 1:
            angles = np.sort(rng.uniform(0, 2 * np.pi, 5))
            draw.polygon([(cx + size * np.cos(a), cy + size * np.sin(a)) for a in angles], fill=colour)
        else:
            # Strokes 1-6 px wide at 2x: lines of 0.5-3 px once downsampled, the thin features.
            dx, dy = size * np.cos(rng.uniform(0, np.pi)), size * np.sin(rng.uniform(0, np.pi))
            draw.line((cx - dx, cy - dy, cx + dx, cy + dy), fill=colour, width=int(rng.integers(1, 7)))
    big = np.asarray(image)
    total = big[0::2, 0::2].astype(np.uint16) + big[1::2, 0::2] + big[0::2, 1::2] + big[1::2, 1::2]
    original = ((total + 2) // 4).astype(np.uint8)
    filtered = np.where(luma(original.astype(np.float32))[..., None] > 127.5, 255, 0).astype(np.uint8).repeat(3, -1)
    return original, filtered


def _photo_pair(width, height):
    from .bench import bench_image_pair
    return bench_image_pair(width, height, "threshold")


#: The pairs: name -> (what it is, a function of width and height returning O and F).
PAIRS = {"thin": ("random filled shapes and strokes, antialiased at 2x, thresholded (pure colours)",
                  thin_features_pair),
         "photo": ("photo-like: shapes over a noisy gradient, thresholded", _photo_pair)}


def _command_lines(original, filtered, output):
    python = [sys.executable, "-m"]
    lines = {"safe": python + ["aarecovery", "recover", original, filtered, "-o", output],
             "paper": python + ["aarecovery", "recover", original, filtered, "-o", output, "--paper"],
             "gegl": ["gegl", "--", "gegl:load", f"path={filtered}", "gegl:antialias", "gegl:png-save",
                      f"path={output}", "bitdepth=8"],
             "numpy-paper": python + ["aarecovery.lab.paper_numpy", original, filtered, "-o", output]}
    if which("gegl") is None:
        del lines["gegl"]
    return lines


def _load():
    try:
        return round(os.getloadavg()[0], 2)
    except OSError:
        return None


def _time_pair(name, width, height, runs, numpy_runs, folder, log):
    what, make = PAIRS[name]
    from ..io import write_image
    original, filtered = make(width, height)
    paths = [os.path.join(folder, f"{name}-{part}.png") for part in ("o", "f", "r")]
    write_image(paths[0], original)
    write_image(paths[1], filtered)
    del original, filtered
    lines = _command_lines(*paths)
    if numpy_runs <= 0:
        del lines["numpy-paper"]
    measured = {command: [] for command in lines}
    load_before = _load()
    for run in range(runs):
        for command, line in lines.items():
            if command == "numpy-paper" and run >= numpy_runs:
                continue
            measured[command].append(measure_command(line, cpu=True))
    rows = {}
    for command, results in measured.items():
        seconds = [result[1] for result in results]
        rows[command] = {"seconds": statistics.median(seconds), "runs": seconds,
                         "cpu_seconds": statistics.median(result[2] for result in results),
                         "peak_bytes": max(result[0] for result in results),
                         "mps": width * height / statistics.median(seconds) / 1e6}
    ratios, cpu_ratios = ({label: rows[top][key] / rows[bottom][key]
                           for label, top, bottom in RATIOS if top in rows and bottom in rows}
                          for key in ("seconds", "cpu_seconds"))
    report = {"pair": name, "what": what, "size": f"{width}x{height}", "rows": rows, "ratios": ratios,
              "cpu_ratios": cpu_ratios, "load": [load_before, _load()]}
    log(f"{name} {width}x{height}: {what} (load {load_before} -> {report['load'][1]})")
    for command, row in rows.items():
        spread = ", ".join(f"{s:.2f}" for s in row["runs"])
        log(f"  {command:12s} {row['seconds']:7.2f} s  {row['mps']:7.2f} MP/s  CPU {row['cpu_seconds']:6.2f} s  "
            f"peak {row['peak_bytes'] / 2**30:.2f} GiB  (runs: {spread})")
    log("  ratios: " + ", ".join(f"{label} {value:.2f}x" for label, value in ratios.items()))
    log("  CPU-time ratios: " + ", ".join(f"{label} {value:.2f}x" for label, value in cpu_ratios.items()))
    return report


def bench_processes(width, height, runs, *, numpy_runs=1, pairs=tuple(PAIRS), log=print):
    """Time whole processes file to file on each pair; return the report.

    Parameters
    ----------
    width, height : int
    runs : int
        Runs of each command, in turn.
    numpy_runs : int
        Runs of the NumPy program (at most `runs`); 0 leaves it out.
    pairs : sequence of str
        Keys of :data:`PAIRS`.
    log : callable
        Gets the report line by line.

    Returns
    -------
    dict
        ``pairs``: per pair its rows (median wall seconds, each run's, megapixels per second,
        median CPU seconds and peak bytes per command), its ratios of wall seconds and of CPU
        seconds and the load average before and after; ``skipped``: commands not run and why.
    """
    report = {"pairs": [], "skipped": {}}
    if which("gegl") is None:
        report["skipped"]["gegl"] = _GEGL_MISSING
        log(_GEGL_MISSING)
    log(f"whole processes file to file, medians of {runs} runs in turn (numpy-paper: {min(runs, numpy_runs)}); "
        "peak = peak resident memory of the process")
    started = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="aarecovery-process-") as folder:
        for name in pairs:
            report["pairs"].append(_time_pair(name, width, height, runs, numpy_runs, folder, log))
    report["seconds"] = time.perf_counter() - started
    return report
