"""``aarecovery eval``: quality against supersampled ground truth, beside the peer tools.

Two suites: ``builtin`` (the project's filters on its own scenes) and ``realtools`` (GEGL,
G'MIC, ImageMagick, OpenCV and Pillow on drawings, comics, photos, graphics over photos and
scans of text, with PNG and JPEG originals), whose cases are split into a tuning half and a
held-out half (``--half``).
"""

import sys
import time

from ..errors import InputError
from ..params import BACKENDS

__all__ = ["register", "run"]


def register(subparsers):
    """Add ``aarecovery eval``."""
    parser = subparsers.add_parser(
        "eval", help="measure recovery against supersampled ground truth, beside GIMP and G'MIC",
        description="Run every filter on every scene, recover, and print PSNR/SSIM tables of F, R (the safe "
                    "default), the paper's method and the installed peer tools against a supersampled reference. "
                    "--suite realtools runs GEGL, G'MIC, ImageMagick, OpenCV and Pillow instead, on one half of a "
                    "fixed split.")
    parser.add_argument("--suite", choices=("builtin", "realtools"), default="builtin",
                        help="builtin: the project's filters on its scenes (default); realtools: GEGL, G'MIC, "
                             "ImageMagick, OpenCV and Pillow on drawings, photos, mixed content and scans, PNG and "
                             "JPEG originals")
    parser.add_argument("--half", help="realtools only: tune (default), heldout or all; choose thresholds on tune, "
                                       "report heldout")
    parser.add_argument("--quick", action="store_true", help="the small suite (under a minute on 2 cores)")
    parser.add_argument("--k", type=int, choices=(4, 8), help="builtin only: supersampling factor (default 4; "
                                                              "realtools: 8 for drawings, 4 for photos)")
    parser.add_argument("--width", type=int, help="target width in pixels (default 80 quick, 128 full; realtools: "
                                                  "64 quick, 96 full, for drawings)")
    parser.add_argument("--scenes", help="comma-separated scenes, or realtools families (default: the suite's)")
    parser.add_argument("--filters", help="comma-separated filters, or realtools tool filters (default: all)")
    parser.add_argument("--no-jpeg", action="store_true", help="realtools only: skip the JPEG originals")
    parser.add_argument("--jpeg-tables", action="store_true",
                        help="realtools only: give the recovery each JPEG original's quantization tables, as "
                             "'recover' reads them from a JPEG file (default: the decoded pixels only, as the "
                             "plug-ins and arrays)")
    parser.add_argument("--backend", choices=BACKENDS, default="numpy",
                        help="recovery backend (default numpy, the specification)")
    parser.add_argument("--no-peers", action="store_true", help="skip GIMP and G'MIC")
    parser.add_argument("--report", metavar="DIR", help="also write DIR/report.md with charts and crops, and "
                                                         "DIR/tables.md, the Markdown tables docs/quality.md includes")
    parser.set_defaults(run=run)


def run(args):
    if args.suite == "realtools":
        return _run_realtools(args)
    for option, given in (("--half", args.half), ("--no-jpeg", args.no_jpeg), ("--jpeg-tables", args.jpeg_tables)):
        if given:
            raise InputError(f"{option} applies to --suite realtools only; the built-in suite has no split "
                             "and no JPEG originals")
    from ..filters import FILTERS
    from ..lab import scenes as _scenes
    from ..lab.evaluate import FULL, QUICK, Suite, run_suite
    from ..lab.report import format_table, write_report
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
    suite = Suite(scenes, filters, width, args.k or 4)
    # The summary names the suite: the quick and full suites' figures differ, and one quoted
    # without its suite cannot be compared.
    name = "quick" if args.quick else "full"
    label = (f"the {name} suite" if suite == Suite(base.scenes, base.filters, base.width, 4)
             else f"a custom suite ({len(scenes)} scenes, {len(filters)} filters, {width} px, k={args.k or 4})")
    start = time.perf_counter()
    results, missing = run_suite(suite, backend=args.backend, peers=not args.no_peers,
                                 progress=sys.stderr.isatty(), keep_images=bool(args.report))
    print(format_table(results, missing, label))
    print(f"\n{len(results)} cases in {time.perf_counter() - start:.1f} s")
    if args.report:
        command = "aarecovery eval" + (" --quick" if args.quick else "") + (" --no-peers" if args.no_peers else "")
        print(f"report: {write_report(results, args.report, missing, command, label)}")
    return 0


def _chosen(given, default, known, half, kind, option):
    """Names from a comma-separated option, checked against the catalogue and the half."""
    names = tuple(given.split(",")) if given else tuple(n for n in default if half == "all" or known[n].half == half)
    for name in names:
        if name not in known:
            raise InputError(f"unknown {kind} {name!r}; the real-tools {kind}s are: {', '.join(known)}")
        if half != "all" and known[name].half != half:
            raise InputError(f"{kind} {name!r} belongs to the {known[name].half} half; run with --half "
                             f"{known[name].half} (or all), or leave {option} out")
    return names


def _run_realtools(args):
    from ..lab.realeval import run_realtools
    from ..lab.realreport import format_realtools, write_realtools_report
    from ..lab.realtools import FAMILIES, HALVES, REAL_FULL, REAL_QUICK, TOOL_FILTERS, RealToolsSuite
    half = args.half or "tune"
    if half not in HALVES:
        raise InputError(f"--half must be one of {', '.join(HALVES)}, got {half!r}")
    if args.k is not None:
        raise InputError("--k applies to the built-in suite only; the real-tools suite renders drawings at k = 8 "
                         "and box-downsamples photos by 4")
    base = REAL_QUICK if args.quick else REAL_FULL
    families = _chosen(args.scenes, base.families, FAMILIES, half, "family", "--scenes")
    filters = _chosen(args.filters, base.filters, TOOL_FILTERS, half, "filter", "--filters")
    width = args.width or base.width
    if width < 16:
        raise InputError(f"--width must be at least 16 pixels, got {width}")
    suite = RealToolsSuite(base.name, families, filters, width, base.spaces, base.jpeg_qualities)
    start = time.perf_counter()
    results, missing_tools, missing_peers = run_realtools(
        suite, half, backend=args.backend, peers=not args.no_peers, jpeg=not args.no_jpeg,
        progress=sys.stderr.isatty(), keep_images=bool(args.report), jpeg_tables=args.jpeg_tables)
    print(format_realtools(results, missing_tools, missing_peers, suite_name=suite.name, half=half))
    print(f"\n{len(results)} cases in {time.perf_counter() - start:.1f} s")
    if args.report:
        # The options that shape the tables, so that the block's command regenerates it.
        command = ("aarecovery eval --suite realtools" + (" --quick" if args.quick else "") + f" --half {half}"
                   + (" --no-peers" if args.no_peers else "") + (" --jpeg-tables" if args.jpeg_tables else ""))
        path = write_realtools_report(results, args.report, missing_tools, missing_peers, suite_name=suite.name,
                                      half=half, command=command)
        print(f"report: {path}")
    return 0
