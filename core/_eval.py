"""``aarecovery eval``: every filter on every scene against supersampled ground truth.

For each scene (rendered at ``k`` times the target size), antialiasing space and filter it
builds O, F and the reference (:mod:`aarecovery._groundtruth`), recovers R with the safe
default and with the paper's method, runs the peer tools on F, and measures PSNR and SSIM
against the reference over the whole image and over the edge band
(:func:`aarecovery._metrics.edge_band`), plus the edge-band error reduction
``1 - MSE(R) / MSE(F)``.
"""

import os
import sys
import time
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Suite", "QUICK", "FULL", "CaseResult", "run_suite", "summarize", "format_table", "write_report",
           "register"]

#: Quality thresholds of the safe default (issue 3), asserted by the tests on the quick suite.
MAX_LOSS_DB = 0.1
MIN_MEAN_REDUCTION = 0.75
# A case whose F already matches the reference to within half an 8-bit step (edge-band
# RMSE below 0.5/255, PSNR above 54.2 dB) has no error to reduce: 1 - MSE(R)/MSE(F) is 0/0
# there, and was counted as 0 (the grey star under colour replacement, MSE(F) = 0) or as
# the ratio of float rounding noise (the grey star under colour to grey, MSE(F) ~ 2e-10,
# "+0.90"). Such cases are left out of the mean; the no-loss check still covers them.
_NO_ERROR_PSNR_DB = float(10 * np.log10((255 / 0.5) ** 2))


@dataclass(frozen=True)
class Suite:
    """Which cases an evaluation runs.

    Attributes
    ----------
    scenes : tuple of str
        Keys of :data:`aarecovery._scenes.SCENES`.
    filters : tuple of str
        Keys of :data:`aarecovery.filters.FILTERS`.
    width : int
        Target width in pixels.
    k : int
        Supersampling factor.
    """

    scenes: tuple
    filters: tuple
    width: int
    k: int = 4


def _all_filters():
    from .filters import FILTERS
    return tuple(FILTERS)


# The quick suite keeps one scene of each kind that matters (text, colour shapes, thin
# lines, a photo) at 80 pixels: it runs in about 40 s on 2 cores with the NumPy backend.
QUICK = Suite(("text", "shapes", "lines", "astronaut"), _all_filters(), 80)
FULL = Suite(("text", "lines", "chart", "star", "shapes", "astronaut", "coffee", "chelsea"), _all_filters(), 128)


@dataclass
class CaseResult:
    """Measurements of one case.

    Attributes
    ----------
    scene, space, filter_name : str
    kind : {"synthetic", "photo"}
    band_fraction : float
        Share of pixels in the edge band.
    psnr, ssim, psnr_band, ssim_band : dict of str to float
        Per method: ``"F"``, ``"R"`` (safe default), ``"paper"`` and each installed peer.
    reduction : dict of str to float
        Edge-band error reduction per method (not for ``"F"``).
    plan : str
        What the safe default decided.
    images : dict of str to ndarray
        O, F, reference and every result, kept for the report's crops.
    """

    scene: str
    space: str
    filter_name: str
    kind: str
    band_fraction: float = 0.0
    psnr: dict = field(default_factory=dict)
    ssim: dict = field(default_factory=dict)
    psnr_band: dict = field(default_factory=dict)
    ssim_band: dict = field(default_factory=dict)
    reduction: dict = field(default_factory=dict)
    plan: str = ""
    images: dict = field(default_factory=dict)


class _Progress:
    """A one-line progress bar on stderr, shown only on a terminal or when forced."""

    def __init__(self, total, enabled):
        self.total, self.done, self.enabled = total, 0, enabled
        self.start = time.perf_counter()

    def step(self, label):
        self.done += 1
        if not self.enabled:
            return
        width = 30
        filled = int(width * self.done / max(1, self.total))
        elapsed = time.perf_counter() - self.start
        sys.stderr.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {self.done}/{self.total} "
                         f"{elapsed:5.1f}s {label[:40]:40s}")
        sys.stderr.flush()

    def close(self):
        if self.enabled:
            sys.stderr.write("\n")
            sys.stderr.flush()


def _spaces_for(kind):
    # Photos are camera images: their antialiasing happened optically, in linear light.
    return ("linear",) if kind == "photo" else ("linear", "srgb")


def run_suite(suite, *, backend="numpy", peers=True, progress=False, keep_images=False):
    """Run an evaluation suite.

    Parameters
    ----------
    suite : Suite
    backend : {"numpy", "gl", "auto"}
        Recovery backend.
    peers : bool
        Also run the installed peer tools.
    progress : bool
        Draw a progress bar on stderr.
    keep_images : bool
        Keep every case's images (for :func:`write_report`).

    Returns
    -------
    results : list of CaseResult
    missing : list of Peer
        Peer tools that are not installed (their columns are absent).
    """
    from . import _scenes
    from ._groundtruth import make_case
    from ._metrics import edge_band, error_reduction, psnr, ssim_map
    from ._peers import available_peers
    from ._recover import recover
    from ._safeguards import plan_recovery

    installed, missing = available_peers() if peers else ([], [])
    cases = [(scene, space, name) for scene in suite.scenes for space in _spaces_for(_scenes.SCENES[scene].kind)
             for name in suite.filters]
    bar = _Progress(len(cases) + (1 if installed else 0), progress)
    results, triples = [], []
    rendered = {}
    for scene, space, name in cases:
        if scene not in rendered:
            rendered = {scene: _scenes.render(scene, suite.width, suite.k)}
        case = make_case(rendered[scene], name, suite.k, space)
        o, f, ref = case.original, case.filtered, case.reference
        band = edge_band(o, f, ref)
        result = CaseResult(scene, space, name, _scenes.SCENES[scene].kind, float(band.mean()))
        outputs = {"F": f,
                   "R": recover(o, f, backend=backend, mode="safe"),
                   "paper": recover(o, f, backend=backend, mode="paper")}
        if keep_images:  # the reason is only shown in reports; planning again costs ~0.1 s a case
            opaque = np.ones(o.shape[:2] + (1,), np.float32)
            result.plan = plan_recovery(np.concatenate([o, opaque], -1), np.concatenate([f, opaque], -1)).reason
        for method, image in outputs.items():
            _measure(result, method, image, ref, band, f, psnr, ssim_map, error_reduction)
        if keep_images:
            result.images = {"O": o, "reference": ref, **outputs}
        results.append(result)
        triples.append((f, ref, band))
        bar.step(f"{scene} {space} {name}")
    for peer in installed:
        outputs = peer.run([f for f, _, _ in triples])
        for result, (f, ref, band), image in zip(results, triples, outputs):
            # Peers read 8-bit PNG; their change is added to F so that the quantisation of
            # their input costs them nothing (it cost up to 13 dB where F is near-perfect).
            image = np.clip(f + (image - np.rint(np.clip(f, 0, 1) * 255) / 255), 0, 1).astype(np.float32)
            _measure(result, peer.name, image, ref, band, f, psnr, ssim_map, error_reduction)
            if keep_images:
                result.images[peer.name] = image
    if installed:
        bar.step("peer tools")
    bar.close()
    return results, missing


def _measure(result, method, image, reference, band, filtered, psnr, ssim_map, error_reduction):
    result.psnr[method] = psnr(image, reference)
    similarity = ssim_map(image, reference)
    result.ssim[method] = float(similarity.mean())
    result.ssim_band[method] = float(similarity[band].mean()) if band.any() else 1.0
    result.psnr_band[method] = psnr(image, reference, band)
    if method != "F":
        result.reduction[method] = error_reduction(image, filtered, reference, band)


def _methods(results):
    order = ["F", "R", "paper", "gimp", "gmic"]
    present = set().union(*(r.psnr_band for r in results)) if results else set()
    return [m for m in order if m in present]


def summarize(results):
    """The three quality checks of the safe default, and per-filter means.

    Returns
    -------
    dict
        ``worst_loss_db``: the largest edge-band PSNR loss of R against F (and its case);
        ``mean_reduction``: per antialiasing space, mean edge-band error reduction of R and
        of the paper's method over synthetic scenes, Gaussian blur excluded, and cases
        where F already matches the reference within half an 8-bit step (no error to
        reduce: the ratio is undefined) excluded;
        ``per_filter``: per filter, mean edge-band PSNR gain over F of each method;
        ``beats_peers``: per filter (blur excluded), whether R's mean gain beats every peer's.
    """
    summary = {}
    losses = [(r.psnr_band["F"] - r.psnr_band["R"], f"{r.scene}/{r.space}/{r.filter_name}") for r in results]
    summary["worst_loss_db"] = max(losses) if losses else (0.0, "")
    reductions = {}
    for space in ("linear", "srgb"):
        picked = [r for r in results if r.kind == "synthetic" and r.space == space and r.filter_name != "blur"
                  and r.psnr_band["F"] < _NO_ERROR_PSNR_DB]
        if picked:
            reductions[space] = {m: float(np.mean([r.reduction[m] for r in picked])) for m in ("R", "paper")
                                 if all(m in r.reduction for r in picked)}
    summary["mean_reduction"] = reductions
    methods = [m for m in _methods(results) if m != "F"]
    per_filter = {}
    for name in dict.fromkeys(r.filter_name for r in results):
        picked = [r for r in results if r.filter_name == name]
        per_filter[name] = {m: float(np.mean([r.psnr_band[m] - r.psnr_band["F"] for r in picked]))
                            for m in methods}
    summary["per_filter"] = per_filter
    peers = [m for m in methods if m in ("gimp", "gmic")]
    summary["beats_peers"] = {name: all(gains["R"] > gains[p] for p in peers)
                              for name, gains in per_filter.items() if name != "blur"}
    return summary


def format_table(results, missing=()):
    """Plain-text tables, one per filter, and the summary: what ``aarecovery eval`` prints."""
    methods = _methods(results)
    lines = []
    for peer in missing:
        lines.append(f"!! {peer.label} is NOT installed (`{peer.command}` not found; Debian package "
                     f"'{peer.package}'): its column is missing from every table below")
    names = list(dict.fromkeys(r.filter_name for r in results))
    head = (f"{'scene':10s} {'aa':6s} | " + " ".join(f"{m:>6s}" for m in methods) + " | "
            + " ".join(f"{m:>6s}" for m in methods) + " | " + " ".join(f"{m:>6s}" for m in methods[1:])
            + " | " + f"{'psnr F':>6s} {'R':>6s} {'ssim F':>6s} {'R':>6s}")
    for name in names:
        lines.append("")
        lines.append(f"== {name}: edge-band PSNR (dB) | edge-band SSIM | edge-band error reduction | whole image")
        lines.append(head)
        for r in (r for r in results if r.filter_name == name):
            lines.append(f"{r.scene:10s} {r.space:6s} | "
                         + " ".join(f"{r.psnr_band[m]:6.2f}" for m in methods) + " | "
                         + " ".join(f"{r.ssim_band[m]:6.4f}"[:6] for m in methods) + " | "
                         + " ".join(f"{r.reduction[m]:+6.3f}"[:6] for m in methods[1:]) + " | "
                         + f"{r.psnr['F']:6.2f} {r.psnr['R']:6.2f} {r.ssim['F']:6.4f} {r.ssim['R']:6.4f}")
    summary = summarize(results)
    lines.append("")
    lines.append("== summary: mean edge-band PSNR gain over F (dB)")
    others = methods[1:]
    lines.append(f"{'filter':14s} " + " ".join(f"{m:>7s}" for m in others) + "  R beats peers")
    for name, gains in summary["per_filter"].items():
        verdict = "" if name == "blur" else ("yes" if summary["beats_peers"].get(name) else "NO")
        lines.append(f"{name:14s} " + " ".join(f"{gains[m]:+7.2f}" for m in others) + f"  {verdict}")
    loss, where = summary["worst_loss_db"]
    lines.append("")
    lines.append(f"worst edge-band loss of R against F: {loss:+.2f} dB ({where}); "
                 f"limit {MAX_LOSS_DB} dB: {'ok' if loss <= MAX_LOSS_DB else 'FAILED'}")
    for space, values in summary["mean_reduction"].items():
        verdict = "ok" if values["R"] >= MIN_MEAN_REDUCTION else "FAILED"
        paper = f" (paper {values['paper']:.3f})" if "paper" in values else ""
        lines.append(f"mean edge-band error reduction, synthetic, {space} antialiasing, blur excluded: "
                     f"R {values['R']:.3f}{paper}; target {MIN_MEAN_REDUCTION}: {verdict}")
    return "\n".join(lines)


# ----------------------------------------------------------------------------- report


def _crop_box(result, size=32):
    """The size x size window where F is furthest from the reference."""
    error = np.abs(result.images["F"] - result.images["reference"]).max(axis=-1)
    h, w = error.shape
    size = min(size, h, w)
    integral = np.pad(error, ((1, 0), (1, 0))).cumsum(0).cumsum(1)
    sums = integral[size:, size:] - integral[:-size, size:] - integral[size:, :-size] + integral[:-size, :-size]
    top, left = np.unravel_index(np.argmax(sums), sums.shape)
    return int(top), int(left), size


def _magnified(image, zoom):
    return np.repeat(np.repeat(image, zoom, axis=0), zoom, axis=1)


def _crop_strip(result, methods, zoom=6):
    top, left, size = _crop_box(result)
    panels = [_magnified(result.images[m][top:top + size, left:left + size], zoom) for m in methods]
    gap = np.ones((size * zoom, 4, 3), np.float32)
    pieces = []
    for panel in panels:
        pieces += [panel, gap]
    return np.concatenate(pieces[:-1], axis=1)


def write_report(results, folder, missing=(), command="aarecovery eval"):
    """Write ``report.md`` with tables, bar charts (matplotlib, optional) and magnified crops.

    Parameters
    ----------
    results : list of CaseResult
        From :func:`run_suite` with ``keep_images=True``.
    folder : str
        Created if missing.
    missing : list of Peer
    command : str
        The command line, quoted in the report.

    Returns
    -------
    str
        Path of the Markdown file.
    """
    from PIL import Image
    os.makedirs(folder, exist_ok=True)
    methods = _methods(results)
    lines = ["# aarecovery evaluation", "", f"Command: `{command}`", ""]
    for peer in missing:
        lines.append(f"> **{peer.label} is not installed** (`{peer.command}`; Debian package `{peer.package}`): "
                     "it is missing from every table and chart.")
    lines += ["", "Columns: F (the filtered image), R (the safe default), paper (Yang et al. 2011 exactly)"
              + "".join(f", {m}" for m in methods if m in ("gimp", "gmic")) + ". All numbers are against the "
              "supersampled reference; the band is the edge band.", "", "```", format_table(results, missing), "```",
              ""]
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        plt = None
        lines += ["> Bar charts need matplotlib (`pip install aarecovery[eval]`); they were skipped.", ""]
    for name in dict.fromkeys(r.filter_name for r in results):
        picked = [r for r in results if r.filter_name == name]
        lines += [f"## {name}", ""]
        if plt is not None:
            figure, axes = plt.subplots(figsize=(max(4, 0.9 * len(picked) + 1), 2.8))
            width = 0.8 / len(methods)
            x = np.arange(len(picked))
            for i, method in enumerate(methods):
                axes.bar(x + i * width, [r.psnr_band[method] for r in picked], width, label=method)
            axes.set_xticks(x + 0.4 - width / 2, [f"{r.scene}\n{r.space}" for r in picked], fontsize=7)
            axes.set_ylabel("edge-band PSNR (dB)")
            low = min(min(r.psnr_band.values()) for r in picked)
            axes.set_ylim(max(0, low - 3), None)
            axes.legend(fontsize=7, ncol=len(methods))
            figure.tight_layout()
            chart = f"{name}-psnr.png"
            figure.savefig(os.path.join(folder, chart), dpi=90)
            plt.close(figure)
            lines += [f"![edge-band PSNR, {name}]({chart})", ""]
        worst = max(picked, key=lambda r: r.psnr_band["R"] - r.psnr_band["F"])
        shown = ["O", "F", "R", "reference"] + [m for m in ("paper", "gimp", "gmic") if m in worst.images]
        crop = f"{name}-crop.png"
        strip = _crop_strip(worst, shown)
        Image.fromarray(np.rint(np.clip(strip, 0, 1) * 255).astype(np.uint8)).save(os.path.join(folder, crop))
        lines += [f"Crop of {worst.scene} ({worst.space}), magnified 6x with nearest neighbour, left to right: "
                  + ", ".join(shown) + f". Safe default: {worst.plan}.", "", f"![{name} crop]({crop})", ""]
    path = os.path.join(folder, "report.md")
    with open(path, "w", encoding="utf-8") as handle:
        handle.write("\n".join(lines))
    return path


# ----------------------------------------------------------------------------- command line


def register(subparsers):
    """Add ``aarecovery eval``."""
    parser = subparsers.add_parser(
        "eval", help="measure recovery against supersampled ground truth, beside GIMP and G'MIC",
        description="Run every filter on every scene, recover, and print PSNR/SSIM tables of F, R (the safe "
                    "default), the paper's method and the installed peer tools against a supersampled reference.")
    parser.add_argument("--quick", action="store_true", help="the small suite (under a minute on 2 cores)")
    parser.add_argument("--k", type=int, choices=(4, 8), default=4, help="supersampling factor (default 4)")
    parser.add_argument("--width", type=int, help="target width in pixels (default 80 quick, 128 full)")
    parser.add_argument("--scenes", help="comma-separated scenes (default: the suite's)")
    parser.add_argument("--filters", help="comma-separated filters (default: all)")
    parser.add_argument("--backend", choices=("numpy", "gl", "auto"), default="numpy",
                        help="recovery backend (default numpy, the specification)")
    parser.add_argument("--no-peers", action="store_true", help="skip GIMP and G'MIC")
    parser.add_argument("--report", metavar="DIR", help="also write DIR/report.md with charts and crops")
    parser.set_defaults(run=_run_command)


def _run_command(args):
    from . import _scenes
    from .filters import FILTERS
    from ._errors import InputError
    base = QUICK if args.quick else FULL
    scenes = tuple(args.scenes.split(",")) if args.scenes else base.scenes
    filters = tuple(args.filters.split(",")) if args.filters else base.filters
    for scene in scenes:
        if scene not in _scenes.SCENES:
            raise InputError(f"unknown scene {scene!r}; the scenes are: {', '.join(_scenes.SCENES)}")
    for name in filters:
        if name not in FILTERS:
            raise InputError(f"unknown filter {name!r}; the filters are: {', '.join(FILTERS)}")
    width = args.width or base.width
    if width < 16:
        raise InputError(f"--width must be at least 16 pixels, got {width}")
    suite = Suite(scenes, filters, width, args.k)
    start = time.perf_counter()
    results, missing = run_suite(suite, backend=args.backend, peers=not args.no_peers,
                                 progress=sys.stderr.isatty(), keep_images=bool(args.report))
    print(format_table(results, missing))
    print(f"\n{len(results)} cases in {time.perf_counter() - start:.1f} s")
    if args.report:
        command = "aarecovery eval" + (" --quick" if args.quick else "")
        print(f"report: {write_report(results, args.report, missing, command)}")
    return 0
