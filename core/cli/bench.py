"""``aarecovery bench``: end-to-end throughput of each backend, and the peak memory of ``recover``."""

import argparse
import json

from ..errors import InputError
from ..lab.bench import DEFAULT_SIZES

__all__ = ["register", "run"]


def _size(text):
    try:
        width, height = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise InputError(f"a size is WIDTHxHEIGHT, such as 1920x1080; got {text!r}") from None
    if width < 1 or height < 1:
        raise InputError(f"a size needs at least one pixel each way, got {text!r}")
    return width, height


def run(args):
    """Run ``aarecovery bench`` with parsed arguments; return the exit status."""
    if args.batch is not None or args.gigapixel:
        return _run_scale(args)
    from ..lab.bench import run_bench

    report = run_bench([_size(size) for size in args.sizes.split(",")], args.backends.split(","),
                       args.filters.split(","), args.runs, safe=args.safe,
                       memory=_size(args.memory) if args.memory else None,
                       log=lambda line: print(line, flush=True))
    if args.json:
        with open(args.json, "w") as out:
            json.dump(report, out, indent=2)
    return 0


def register(subparsers):
    parser = subparsers.add_parser(
        "bench", help="measure the throughput of each backend",
        description="End-to-end throughput (upload, passes, readback) of each backend in megapixels "
                    "per second: the median of several runs after a warm-up, on a generated photo-like "
                    "8-bit RGB pair, with the GL/NumPy ratio from the same run.",
        epilog="examples:\n  aarecovery bench\n  aarecovery bench --sizes 1920x1080 --backends gl --runs 9\n"
               "  aarecovery bench --memory 4096x4096 --json bench.json\n"
               "  aarecovery bench --batch 100\n  aarecovery bench --gigapixel 50000x50000 --folder /scratch",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", default=",".join(f"{w}x{h}" for w, h in DEFAULT_SIZES),
                        help="comma-separated WIDTHxHEIGHT list (default %(default)s)")
    parser.add_argument("--backends", default="gl,numpy", help="comma-separated (default %(default)s)")
    parser.add_argument("--filters", default="threshold,gamma",
                        help="threshold (flat F away from edges) and/or gamma (every pixel fitted); "
                             "default %(default)s")
    parser.add_argument("--runs", type=int, default=5, help="timed GL runs per size; NumPy gets half "
                        "(default %(default)s)")
    parser.add_argument("--safe", action="store_true",
                        help="also time the default mode, whose per-image analysis runs in NumPy")
    parser.add_argument("--memory", metavar="WxH", nargs="?", const="4096x4096",
                        help="also measure the peak memory of 'aarecovery recover' on a pair of this size "
                             "(default when given without a value: 4096x4096)")
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
