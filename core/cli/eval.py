"""``aarecovery eval``: quality against supersampled ground truth, beside the peer tools."""

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
                    "default), the paper's method and the installed peer tools against a supersampled reference.")
    parser.add_argument("--quick", action="store_true", help="the small suite (under a minute on 2 cores)")
    parser.add_argument("--k", type=int, choices=(4, 8), default=4, help="supersampling factor (default 4)")
    parser.add_argument("--width", type=int, help="target width in pixels (default 80 quick, 128 full)")
    parser.add_argument("--scenes", help="comma-separated scenes (default: the suite's)")
    parser.add_argument("--filters", help="comma-separated filters (default: all)")
    parser.add_argument("--backend", choices=BACKENDS, default="numpy",
                        help="recovery backend (default numpy, the specification)")
    parser.add_argument("--no-peers", action="store_true", help="skip GIMP and G'MIC")
    parser.add_argument("--report", metavar="DIR", help="also write DIR/report.md with charts and crops")
    parser.set_defaults(run=run)


def run(args):
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
    suite = Suite(scenes, filters, width, args.k)
    # The summary names the suite: the quick and full suites' figures differ, and one quoted
    # without its suite cannot be compared.
    name = "quick" if args.quick else "full"
    label = (f"the {name} suite" if suite == Suite(base.scenes, base.filters, base.width, 4)
             else f"a custom suite ({len(scenes)} scenes, {len(filters)} filters, {width} px, k={args.k})")
    start = time.perf_counter()
    results, missing = run_suite(suite, backend=args.backend, peers=not args.no_peers,
                                 progress=sys.stderr.isatty(), keep_images=bool(args.report))
    print(format_table(results, missing, label))
    print(f"\n{len(results)} cases in {time.perf_counter() - start:.1f} s")
    if args.report:
        command = "aarecovery eval" + (" --quick" if args.quick else "")
        print(f"report: {write_report(results, args.report, missing, command, label)}")
    return 0
