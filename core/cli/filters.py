"""``aarecovery filter`` and ``aarecovery filters``: run the test filters from the command line."""

import argparse
import ast

from ..errors import InputError
from ..params import BACKENDS, STRENGTH
from .inputs import add_image_memory_option
from .text import printable

__all__ = ["register", "parse_params"]

_EPILOG = """\
examples:
  aarecovery filters                                        list filters and parameters
  aarecovery filter threshold scan.png -o bw.png --param level=0.45
  aarecovery filter posterize photo.png -o poster.png --param steps=3 --recover
  aarecovery filter gradientmap photo.png -o mapped.png --recover --paper
  aarecovery filter threshold photo.png -o bw.png --recover --strength 0.5
"""


def register(subparsers):
    """Add ``filter`` and ``filters``."""
    parser = subparsers.add_parser(
        "filter", help="apply one of the test filters (optionally with recovery)",
        description="Apply a nonlinear filter to INPUT and write OUTPUT; with --recover, repair the filtered "
                    "image's antialiased edges from INPUT in the same run.",
        epilog=_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("name", metavar="NAME", help="filter name (see 'aarecovery filters')")
    parser.add_argument("input", metavar="INPUT", help="image to filter")
    parser.add_argument("-o", "--output", metavar="OUTPUT", required=True, help="where to write the result")
    parser.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                        help="a filter parameter, repeatable (e.g. --param level=0.4)")
    parser.add_argument("--recover", action="store_true", help="repair the filtered image's edges from INPUT")
    parser.add_argument("--paper", action="store_true", help="with --recover: the paper's method exactly, "
                                                             "without the safe default's safeguards")
    parser.add_argument("--backend", choices=BACKENDS, default="auto",
                        help="recovery backend (default auto)")
    strength = STRENGTH
    parser.add_argument(strength.option, type=strength.kind, metavar="X",
                        help=f"with --recover: {strength.help} ({strength.minimum:g} to {strength.maximum:g}; "
                             f"default: {strength.automatic})")
    add_image_memory_option(parser)
    parser.add_argument("--overwrite", action="store_true",
                        help="allow OUTPUT to replace INPUT (the original that --recover, or a later "
                             "'aarecovery recover', needs)")
    parser.set_defaults(run=_run_filter)
    listing = subparsers.add_parser("filters", help="list the test filters and their parameters",
                                    description="List the filters of 'aarecovery filter' with their parameters.")
    listing.set_defaults(run=_run_list)


def parse_params(pairs, spec):
    """Turn ``["level=0.4", ...]`` into keyword arguments of a filter.

    Values are Python literals (numbers, tuples such as ``((0,0,0),(1,1,1))``).

    Raises
    ------
    InputError
        On a malformed pair, an unknown name or a value that is not a literal.
    """
    known = {p.name for p in spec.parameters}
    params = {}
    for pair in pairs:
        name, sep, text = pair.partition("=")
        name = name.strip().replace("-", "_")
        if not sep or not name:
            raise InputError(f"--param takes NAME=VALUE, got {pair!r}; for example --param level=0.4")
        if name not in known:
            raise InputError(f"filter {spec.name!r} has no parameter {name!r}; its parameters are: "
                             f"{', '.join(sorted(known)) or 'none'}")
        try:
            params[name] = ast.literal_eval(text.strip())
        except (ValueError, SyntaxError):
            raise InputError(f"--param {name}: {text!r} is not a number or tuple; write e.g. {name}=0.5") from None
    return params


def _run_list(args):
    from ..filters import FILTERS
    for spec in FILTERS.values():
        kind = "point-wise" if spec.pointwise else "neighbourhood"
        print(f"{spec.name:14s} {spec.summary} ({kind})")
        for p in spec.parameters:
            default = "the image's own" if p.default is None else repr(p.default)
            unit = " [scaled with resolution]" if p.spatial else ""
            print(f"    {p.name:16s} default {default}: {p.help}{unit}")
    return 0


def _run_filter(args):
    from .. import filters
    from ..io import write_image
    from .inputs import read_input
    from .outputs import check_destinations, remove_stale_parts_of
    spec = filters.get_filter(args.name)
    params = parse_params(args.param, spec)
    if args.paper and not args.recover:
        raise InputError("--paper only applies with --recover; add --recover or drop --paper")
    if args.strength is not None and not args.recover:
        raise InputError("--strength only applies with --recover; add --recover or drop --strength")
    STRENGTH.check(args.strength)
    check_destinations([args.output], {"input": args.input}, overwrite=args.overwrite)
    remove_stale_parts_of([args.output])
    image = read_input(args.input, args)
    filtered = filters.apply(spec.name, image, **params)
    summary = None
    if args.recover:
        from ..engine import Engine
        from ..pipeline import recover
        from .recover import summary_line
        engine = Engine(args.backend)
        try:
            recovered = recover(image, filtered, engine=engine, mode="paper" if args.paper else "safe",
                                strength=args.strength)
            plan = engine.last_plan
        finally:
            engine.release()
        summary = summary_line(plan, image, filtered, recovered)
        filtered = recovered
    write_image(args.output, filtered)
    print(f"wrote {printable(args.output)}")
    if summary is not None:
        print(summary)
    return 0
