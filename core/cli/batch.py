"""``aarecovery batch``: many image pairs, or originals and a filter, with one engine."""

import argparse
import logging
import os
import signal
import sys
import time

from ..errors import InputError
from .inputs import add_image_memory_option, memory_limit
from .recover import add_recovery_options
from .text import printable

__all__ = ["register", "run"]

_DESCRIPTION = """\
Repair many images with one engine. Give two folders (pairs are matched by relative path)
or two quoted glob patterns (matched by what their wildcards match), or ORIGINALS alone
with --filter or --filter-cmd to make each filtered image. Results keep their relative
paths, formats and bit depths under OUTPUT. A bad file or a failing filter command does
not stop the batch: it is reported at the end and the exit status is 1. Every result is
written atomically, and a re-run skips results that are complete and newer than their
inputs, so an interrupted batch resumes where it stopped (--force redoes everything).
Pairs of TIFF files that can be read in pieces (tiled or in strips) are streamed tile by
tile, in memory bounded by the tile size."""

_EPILOG = """\
examples:
  aarecovery batch originals/ filtered/ -o repaired/
  aarecovery batch 'scans/*.png' 'bw/*-bw.png' -o repaired/
  aarecovery batch scans/ -o repaired/ --filter threshold level=0.5
  aarecovery batch scans/ -o repaired/ --filter-cmd 'convert {in} -threshold 50% {out}' --keep-filtered bw/
  aarecovery batch icons/ -o repaired/ --filter-cmd 'gmic {in} -quantize 4 -o {out}' --report report.csv
  aarecovery batch maps/ -o repaired/ --filter-cmd 'gegl {in} -o {out} -- gegl:levels in-high=0.6'
  aarecovery batch originals/ filtered/ -o repaired/ --dask tcp://scheduler:8786

filter commands: the template is split into words like a shell would (no shell runs it);
{in} is a temporary copy of the original, {out} the file the tool must write: lossless, in
the original's format when that is lossless (PNG, TIFF, ...), else PNG (for a JPEG, WebP or
GIF original), unless written with an extension ({out}.jpg). A filtered image the batch
keeps (--keep-filtered) is lossless the same way. ImageMagick 6 is 'convert', ImageMagick 7
'magick'. For pipes or redirection run a shell: 'sh -c "..."'.
"""


def register(subparsers):
    """Add ``aarecovery batch``."""
    parser = subparsers.add_parser(
        "batch", help="repair many images: two folders, two globs, or originals and a filter",
        description=_DESCRIPTION, epilog=_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("originals", metavar="ORIGINALS", help="a folder of originals, or a quoted glob")
    parser.add_argument("filtered", metavar="FILTERED", nargs="?",
                        help="a folder of filtered images, or a quoted glob (not with --filter/--filter-cmd)")
    parser.add_argument("-o", "--output", metavar="OUTPUT", required=True,
                        help="the folder for the results (created if missing)")
    making = parser.add_mutually_exclusive_group()
    making.add_argument("--filter", nargs="+", metavar=("NAME", "PARAM=VALUE"),
                        help="make each filtered image with a built-in filter ('aarecovery filters' lists them), "
                             "e.g. --filter threshold level=0.5")
    making.add_argument("--filter-cmd", metavar="TEMPLATE",
                        help="make each filtered image with a command-line tool: a template with {in} and {out}")
    parser.add_argument("--filter-timeout", type=float, metavar="SECONDS",
                        help="stop a filter command after this long and report the image as failed")
    parser.add_argument("--keep-filtered", metavar="DIR",
                        help="keep each filtered image the batch makes in DIR, under its relative path")
    add_recovery_options(parser)
    parser.add_argument("--maps", metavar="DIR",
                        help="also write each image's maps (as 'recover --maps') into DIR/NAME/; pairs are then "
                             "read whole")
    parser.add_argument("--overwrite", action="store_true",
                        help="allow a result to replace its original or filtered image")
    parser.add_argument("--format", metavar="EXT",
                        help="write every result in this format (png, tif, ...) instead of the filtered image's")
    parser.add_argument("--force", action="store_true",
                        help="redo results that are complete and newer than their inputs")
    parser.add_argument("--report", metavar="FILE",
                        help="write per image the time, size, plan (mode, blend space, strength, decision, reason) and "
                             "backend to FILE (.csv or .json)")
    parser.add_argument("--workers", type=int, metavar="N",
                        help="analysis processes beside the engine, and N + 1 threads that read, filter and "
                             "write (default: a measured rule, one per core of this machine)")
    parser.add_argument("--dask", metavar="ADDRESS",
                        help="run on a Dask cluster: a scheduler address (tcp://host:8786) or 'local'; paths must "
                             "be on storage every worker sees (needs pip install 'aarecovery[dask]')")
    add_image_memory_option(parser)
    parser.set_defaults(run=run)
    return parser


def _jobs(args, makes_filtered):
    from ..batch import find_images, find_pairs, make_jobs

    if makes_filtered:
        if args.filtered is not None:
            raise InputError("give ORIGINALS alone with --filter or --filter-cmd (the filter makes the filtered "
                             f"images), not also {args.filtered}")
        return make_jobs([(path, None, name) for name, path in find_images(args.originals)], True), []
    if args.filtered is None:
        raise InputError("give the FILTERED folder (or glob) after ORIGINALS, or make the filtered images with "
                         "--filter NAME or --filter-cmd TEMPLATE")
    return find_pairs(args.originals, args.filtered)


def _filter_options(args):
    if not args.filter:
        return {}
    from .. import filters
    from .filters import parse_params

    spec = filters.get_filter(args.filter[0])
    for word in args.filter[1:]:
        if "=" not in word:
            raise InputError(f"--filter {' '.join(args.filter)}: {word!r} is not PARAM=VALUE; --filter takes the "
                             "words up to the next option, so put it after ORIGINALS")
    return {"filter": spec.name, "filter_params": parse_params(args.filter[1:], spec)}


class _Progress:
    """A progress bar with rate and ETA (tqdm) on a terminal; silent otherwise."""

    def __init__(self, total):
        from tqdm import tqdm

        self.bar = tqdm(total=total, unit="image", file=sys.stderr, disable=None, dynamic_ncols=True,
                        smoothing=0.1)
        self.results = []

    def __call__(self, result, done, total):
        self.results.append(result)
        if result.status == "failed":
            self.bar.set_postfix(failed=sum(r.status == "failed" for r in self.results), refresh=False)
        self.bar.update(1)

    def close(self):
        self.bar.close()


class _DaskLogLines(logging.Handler):
    """Dask's log records as our one-line messages: ``aarecovery: dask: warning: ...``, the
    first line of each (Dask's own format is a time stamp, a logger name, and at times a
    traceback)."""

    def emit(self, record):
        lines = record.getMessage().strip().splitlines() or [""]
        more = f" (+{len(lines) - 1} lines)" if len(lines) > 1 else ""
        print(f"aarecovery: dask: {record.levelname.lower()}: {printable(lines[0])}{more}", file=sys.stderr)


def dask_logs_as_lines():
    """Route the ``distributed`` loggers of this process through :class:`_DaskLogLines`, and
    keep the worker processes it starts to errors (their stderr is this terminal too)."""
    try:
        import distributed  # noqa: F401  (configures its loggers, which are replaced here)
    except ImportError:
        return  # connect() says how to install it
    logger = logging.getLogger("distributed")
    for handler in list(logger.handlers):
        logger.removeHandler(handler)
    logger.addHandler(_DaskLogLines(logging.WARNING))  # its info lines are a cluster's chatter
    logger.propagate = False
    # Read by each worker process's Dask configuration as it starts (after this import).
    os.environ.setdefault("DASK_LOGGING__DISTRIBUTED", "error")


def _check_paths_for_a_cluster(args, is_url):
    """Refuse relative paths with a scheduler address: its workers resolve them from their own
    working folders, on their own machines, not from the folder this command runs in."""
    if not args.dask or args.dask == "local":
        return
    for option, path in (("ORIGINALS", args.originals), ("FILTERED", args.filtered), ("-o", args.output),
                         ("--keep-filtered", args.keep_filtered), ("--maps", args.maps)):
        if path is not None and not is_url(path) and not os.path.isabs(path):
            raise InputError(f"{option} {path!r} is a relative path, and the workers of the Dask cluster at "
                             f"{args.dask} resolve paths on their side, from their own working folders; give "
                             f"an absolute path on storage every worker sees, such as {os.path.abspath(path)!r}")


def run(args):
    """Run ``aarecovery batch`` with parsed arguments; return the exit status."""
    from ..batch import ImageResult, check_report_path, make_settings, run_jobs, summary, write_report
    from ..batch.destinations import check_batch_destinations
    from ..batch.jobs import source_folder
    from ..batch.storage import is_url

    _check_paths_for_a_cluster(args, is_url)
    if args.dask:
        dask_logs_as_lines()
    if args.workers is not None and args.workers < 1:
        raise InputError(f"--workers must be at least 1, got {args.workers}")
    if args.report:
        check_report_path(args.report)
    if args.filter_timeout is not None and args.filter_timeout <= 0:
        raise InputError(f"--filter-timeout must be a number of seconds above 0, got {args.filter_timeout:g}")
    settings = make_settings(
        output=args.output, filter_command=args.filter_cmd, filter_timeout=args.filter_timeout,
        keep_filtered=args.keep_filtered, maps=args.maps, format=args.format, force=args.force,
        overwrite=args.overwrite, sigma_d=args.sigma_d, sigma_e=args.sigma_e, iterations=args.iterations,
        strength=args.strength, gl_path=args.gl_path, backend=args.backend, linear=args.linear,
        blend_space=args.blend_space, tile_size=args.tile_size, mode="paper" if args.paper else "safe",
        max_bytes=memory_limit(args), **_filter_options(args))
    jobs, unmatched = _jobs(args, settings.filter is not None)
    # Every destination before anything is read, filtered or written.
    check_batch_destinations(jobs, settings, report=args.report,
                             sources=[source_folder(source) for source in (args.originals, args.filtered)
                                      if source is not None and not is_url(source)])
    missing = [ImageResult(os.path.relpath(path, args.originals) if os.path.isdir(args.originals) else path,
                           status="failed", error=f"no filtered image matches {path}") for path in unmatched]
    if not args.dask and not is_url(args.output):
        os.makedirs(args.output, exist_ok=True)
    engine = None
    if jobs and not args.dask:
        from ..engine import Engine
        # A missing OpenGL is said at once, in one line (GLUnavailable is an InputError).
        engine = Engine(settings.backend, gl_path=settings.gl_path)
    progress = _Progress(len(jobs))
    start = time.perf_counter()
    interrupted = None
    finished = []
    try:
        finished = run_jobs(jobs, settings, workers=args.workers, progress=progress, dask=args.dask, engine=engine)
    except KeyboardInterrupt as interruption:
        finished = progress.results
        # Ctrl+C, or SIGTERM / SIGHUP turned into an interruption by the command line.
        interrupted = getattr(interruption, "signum", signal.SIGINT)
    finally:
        progress.close()
        if engine is not None:
            engine.release()
    seconds = time.perf_counter() - start
    results = sorted(missing + list(finished), key=lambda result: result.name)
    for result in results:
        if result.status == "failed":
            print(f"aarecovery: failed: {printable(result.name)}: {printable(result.error)}", file=sys.stderr)
    if args.report:
        write_report(args.report, results)
    print(summary(results, seconds) + (f"; report in {printable(args.report)}" if args.report else ""))
    if interrupted is not None:
        print(f"aarecovery: interrupted ({signal.Signals(interrupted).name}) after {len(progress.results)} of "
              f"{len(jobs)} images; every result written is complete: run the same command again to finish",
              file=sys.stderr)
        return 128 + interrupted
    return 1 if any(result.status == "failed" for result in results) else 0

