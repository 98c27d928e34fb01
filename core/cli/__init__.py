"""The ``aarecovery`` command: ``main(argv=None) -> int``.

Each subcommand lives in its own module, which provides ``register(subparsers)``; that adds
an argparse parser whose defaults hold ``run=callable(args) -> int``. Heavy imports stay
inside ``run`` so that ``aarecovery --help`` is instant.
"""

import argparse
import sys

from .. import __version__
from ..errors import InputError
from ..gimp import cli as gimp_command
from ..viewer import cli as view_command
from . import batch as batch_command
from . import bench as bench_command
from . import demo as demo_command
from . import eval as eval_command
from . import filters as filters_command
from . import recover as recover_command

__all__ = ["main", "build_parser"]

#: Subcommand modules, in the order ``--help`` lists them.
COMMANDS = (recover_command, batch_command, bench_command, filters_command, eval_command, demo_command, gimp_command,
            view_command)

_EPILOG = """\
examples:
  aarecovery demo                                   repair a bundled sample, write a comparison sheet
  aarecovery recover photo.png thresholded.png -o repaired.png
  aarecovery recover o.tif f.tif -o r.tif --sigma-e 0.02 --maps maps/
  aarecovery batch originals/ filtered/ -o repaired/ --report report.csv
  aarecovery bench                                  throughput of each backend

Run 'aarecovery COMMAND --help' for the options of one command.
"""


class _Parser(argparse.ArgumentParser):
    """Usage errors as one line, like every other error of the command."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def build_parser():
    parser = _Parser(
        prog="aarecovery",
        description="Repair antialiased edges damaged by nonlinear image filters, "
                    "given the image before and after the filter.",
        epilog=_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"aarecovery {__version__}")
    subparsers = parser.add_subparsers(title="commands", metavar="COMMAND", parser_class=_Parser)
    for module in COMMANDS:
        module.register(subparsers)
    return parser


def main(argv=None):
    """Run the command line; return the exit status (0 on success)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not hasattr(args, "run"):
        parser.print_help()
        return 2
    try:
        return int(args.run(args) or 0)
    except (InputError, OSError) as error:
        print(f"aarecovery: error: {error}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("aarecovery: interrupted; no output was written", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
