"""``aarecovery bench``: each stage of a recovery per GL path and NumPy, and whole ``recover`` processes."""

import argparse
import json
import sys

from ..errors import InputError
from ..lab.bench import CONFIGS, DEFAULT_CONFIGS, DEFAULT_SIZES

__all__ = ["register", "run"]


def _size(text):
    try:
        parts = [int(v) for v in text.lower().split("x")]
        width, height = parts * 2 if len(parts) == 1 else parts
    except ValueError:
        raise InputError(f"a size is WIDTHxHEIGHT, such as 1920x1080, or one side of a square; got {text!r}") from None
    if width < 1 or height < 1:
        raise InputError(f"a size needs at least one pixel each way, got {text!r}")
    return width, height


def _configs(text):
    configs = text.split(",")
    unknown = [config for config in configs if config not in CONFIGS]
    if unknown:
        raise InputError(f"unknown configuration {unknown[0]!r}; choose from {', '.join(CONFIGS)}")
    return configs


def _write_json(report, where):
    if where == "-":
        print(json.dumps(report, indent=2))
        return
    with open(where, "w") as out:
        json.dump(report, out, indent=2)


def _log_to(args):
    """Where the human-readable lines go: stderr when the JSON report takes stdout."""
    stream = sys.stderr if args.json == "-" else sys.stdout
    return lambda line: print(line, file=stream, flush=True)


def run(args):
    """Run ``aarecovery bench`` with parsed arguments; return the exit status."""
    if args.runs < 1:
        raise InputError(f"--runs must be at least 1, got {args.runs}")
    if args.batch is not None or args.gigapixel:
        return _run_scale(args)
    if args.process:
        return _run_processes(args)
    from ..lab.bench import run_bench

    report = run_bench([_size(size) for size in args.sizes.split(",")], _configs(args.configs),
                       args.filters.split(","), args.runs, passes=args.passes, log=_log_to(args))
    if args.json:
        _write_json(report, args.json)
    return 0


def _run_processes(args):
    from ..lab.bench import machine
    from ..lab.processes import PAIRS, bench_processes

    width, height = _size(args.process)
    pairs = args.pairs.split(",")
    unknown = [pair for pair in pairs if pair not in PAIRS]
    if unknown:
        raise InputError(f"unknown pair {unknown[0]!r}; choose from {', '.join(PAIRS)}")
    log = _log_to(args)
    report = {"machine": machine()}
    log(f"machine: {report['machine']}")
    report["process"] = bench_processes(width, height, args.runs, numpy_runs=args.numpy_runs, pairs=pairs, log=log)
    if args.json:
        _write_json(report, args.json)
    return 0


def register(subparsers):
    parser = subparsers.add_parser(
        "bench", help="measure each stage of a recovery, per GL path and NumPy; batches; gigapixel pairs",
        description="Times the stages of a file-to-file recovery (decode, plan, upload, classify, passes, "
                    "readback, encode) on a generated photo-like 8-bit RGB pair, and the end-to-end throughput "
                    "of each engine configuration in megapixels per second (the paper's method and the safe "
                    "default), medians of several runs after a warm-up; ratios come from one run. --process, "
                    "--batch and --gigapixel measure whole processes, batches and streamed pairs instead.",
        epilog="examples:\n  aarecovery bench\n  aarecovery bench --sizes 3840x2160 --filters gamma --configs gl-compute\n"
               "  aarecovery bench --process --json bench.json\n  aarecovery bench --process 256 --runs 1 --json\n"
               "  aarecovery bench --batch 100\n  aarecovery bench --gigapixel 50000x50000 --folder /scratch",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", default=",".join(f"{w}x{h}" for w, h in DEFAULT_SIZES),
                        help="comma-separated WIDTHxHEIGHT list (default %(default)s)")
    parser.add_argument("--configs", default=",".join(DEFAULT_CONFIGS),
                        help=f"comma-separated, from {', '.join(CONFIGS)} (default %(default)s; gl-compute-shared "
                             "keeps the fit's neighbourhoods in shared memory)")
    parser.add_argument("--filters", default="threshold,gamma",
                        help="threshold (flat F away from edges) and/or gamma (every pixel fitted); "
                             "default %(default)s")
    parser.add_argument("--passes", action="store_true",
                        help="also time each GL pass on its own, waited for before and after: the device's time "
                             "per pass, for the paper's method and the safe default")
    parser.add_argument("--runs", type=int, default=5, help="timed runs per figure; NumPy gets a third "
                        "(default %(default)s)")
    parser.add_argument("--process", metavar="WxH", nargs="?", const="4096x4096",
                        help="instead: whole processes file to file on PNG pairs of this size (WxH, or one side of "
                             "a square), run in turn: 'aarecovery recover' (safe default), '--paper', GIMP's "
                             "gegl:antialias on F (when the gegl command is installed) and the paper's method as "
                             "straightforward NumPy; medians, peak memory and their ratios (default when given "
                             "without a value: 4096x4096)")
    parser.add_argument("--pairs", default="thin,photo",
                        help="with --process: thin (thin features, pure colours) and/or photo (photo-like), "
                             "default %(default)s")
    parser.add_argument("--numpy-runs", type=int, default=1,
                        help="with --process: runs of the NumPy program, at most --runs; 0 leaves it out "
                             "(default %(default)s)")
    parser.add_argument("--batch", metavar="N", type=int, nargs="?", const=100,
                        help="instead: N pairs of 1920x1080 PNGs through one 'aarecovery batch' (with 1 to 4 "
                             "workers) against N separate 'aarecovery recover' calls, in images per second "
                             "(default when given without a value: 100)")
    parser.add_argument("--gigapixel", metavar="WxH", nargs="?", const="20000x20000",
                        help="instead: time and peak memory of 'aarecovery recover' streaming a tiled-TIFF pair of "
                             "this size, generated tile by tile (default when given without a value: 20000x20000)")
    parser.add_argument("--folder", metavar="DIR",
                        help="where --batch and --gigapixel write their files (default: a temporary folder; a "
                             "50000x50000 pair takes about 6 GB)")
    parser.add_argument("--json", metavar="FILE", nargs="?", const="-",
                        help="also write the figures as JSON to FILE, or to stdout when no FILE is given (the "
                             "readable lines then go to stderr)")
    parser.set_defaults(run=run)
    return parser


def _run_scale(args):
    import tempfile

    from ..lab.scale import bench_batch, bench_gigapixel

    if args.batch is not None and args.batch < 1:
        raise InputError(f"--batch needs at least 1 pair, got {args.batch}")
    report = {}
    with tempfile.TemporaryDirectory(dir=args.folder, prefix="aarecovery-bench-") as folder:
        log = _log_to(args)
        if args.batch is not None:
            report["batch"] = bench_batch(folder, args.batch, log=log)
        if args.gigapixel:
            width, height = _size(args.gigapixel)
            report["gigapixel"] = bench_gigapixel(folder, width, height, log=log)
    if args.json:
        _write_json(report, args.json)
    return 0
