"""``aarecovery bench``: each stage of a recovery per GL path and NumPy, and whole ``recover`` processes."""

import argparse
import json

from ..errors import InputError
from ..lab.bench import CONFIGS, DEFAULT_CONFIGS, DEFAULT_SIZES

__all__ = ["register", "run"]


def _size(text):
    try:
        width, height = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise InputError(f"a size is WIDTHxHEIGHT, such as 1920x1080; got {text!r}") from None
    if width < 1 or height < 1:
        raise InputError(f"a size needs at least one pixel each way, got {text!r}")
    return width, height


def _configs(text):
    configs = text.split(",")
    unknown = [config for config in configs if config not in CONFIGS]
    if unknown:
        raise InputError(f"unknown configuration {unknown[0]!r}; choose from {', '.join(CONFIGS)}")
    return configs


def run(args):
    """Run ``aarecovery bench`` with parsed arguments; return the exit status."""
    if args.batch is not None or args.gigapixel:
        return _run_scale(args)
    from ..lab.bench import run_bench

    if args.runs < 1:
        raise InputError(f"--runs must be at least 1, got {args.runs}")
    report = run_bench([_size(size) for size in args.sizes.split(",")], _configs(args.configs),
                       args.filters.split(","), args.runs, process=_size(args.process) if args.process else None,
                       log=lambda line: print(line, flush=True))
    if args.json:
        with open(args.json, "w") as out:
            json.dump(report, out, indent=2)
    return 0


def register(subparsers):
    parser = subparsers.add_parser(
        "bench", help="measure each stage of a recovery, per GL path and NumPy; batches; gigapixel pairs",
        description="Times the stages of a file-to-file recovery (decode, plan, upload, classify, passes, "
                    "readback, encode) on a generated photo-like 8-bit RGB pair, and the end-to-end throughput "
                    "of each engine configuration in megapixels per second (the paper's method and the safe "
                    "default), medians of several runs after a warm-up; ratios come from one run. --process "
                    "also times whole 'aarecovery recover' processes file to file, with their peak memory; "
                    "--batch and --gigapixel measure batches and streamed pairs instead.",
        epilog="examples:\n  aarecovery bench\n  aarecovery bench --sizes 3840x2160 --filters gamma --configs gl-compute\n"
               "  aarecovery bench --process --json bench.json\n"
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
    parser.add_argument("--runs", type=int, default=5, help="timed runs per figure; NumPy gets a third "
                        "(default %(default)s)")
    parser.add_argument("--process", metavar="WxH", nargs="?", const="4096x4096",
                        help="also time whole 'aarecovery recover' processes on a thresholded pair of PNG files "
                             "of this size, with peak memory (default when given without a value: 4096x4096)")
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
    parser.add_argument("--json", metavar="FILE", help="also write the figures as JSON")
    parser.set_defaults(run=run)
    return parser


def _run_scale(args):
    import tempfile

    from ..lab.scale import bench_batch, bench_gigapixel

    if args.batch is not None and args.batch < 1:
        raise InputError(f"--batch needs at least 1 pair, got {args.batch}")
    report = {}
    with tempfile.TemporaryDirectory(dir=args.folder, prefix="aarecovery-bench-") as folder:
        log = lambda line: print(line, flush=True)  # noqa: E731
        if args.batch is not None:
            report["batch"] = bench_batch(folder, args.batch, log=log)
        if args.gigapixel:
            width, height = _size(args.gigapixel)
            report["gigapixel"] = bench_gigapixel(folder, width, height, log=log)
    if args.json:
        with open(args.json, "w") as out:
            json.dump(report, out, indent=2)
    return 0
