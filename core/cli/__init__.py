"""The ``aarecovery`` command: ``main(argv=None) -> int``.

Each subcommand lives in its own module, which provides ``register(subparsers)``; that adds
an argparse parser whose defaults hold ``run=callable(args) -> int``. Heavy imports stay
inside ``run`` so that ``aarecovery --help`` is instant.
"""

import argparse
import contextlib
import signal
import sys
import threading
import warnings

from .. import __version__
from ..errors import AarecoveryWarning, InputError, NotEnoughMemory
from ..extras import extra_for, missing_extra
from ..gimp import cli as gimp_command
from ..io import os_error_line
from ..krita import cli as krita_command
from ..viewer import cli as view_command
from . import batch as batch_command
from . import bench as bench_command
from . import demo as demo_command
from . import eval as eval_command
from . import filters as filters_command
from . import recover as recover_command
from .text import printable

__all__ = ["main", "build_parser"]

#: Subcommand modules, in the order ``--help`` lists them.
COMMANDS = (recover_command, batch_command, bench_command, filters_command, eval_command, demo_command, gimp_command,
            krita_command, view_command)

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
    for command in subparsers.choices.values():
        command.set_defaults(prog=command.prog)
    return parser


class Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP, raised where Python is running so that it unwinds like Ctrl+C:
    ``write_image`` then removes its temporary file on the way out."""

    def __init__(self, signum):
        super().__init__(signum)
        self.signum = signum


def _raise_terminated(signum, frame):
    raise Terminated(signum)


@contextlib.contextmanager
def _terminating_signals_interrupt():
    """SIGTERM (a killed job) and SIGHUP (a closed terminal) interrupt like SIGINT while the
    command runs. A signal already ignored (``nohup``) stays ignored."""
    previous = {}
    if threading.current_thread() is threading.main_thread():
        for name in ("SIGTERM", "SIGHUP"):
            number = getattr(signal, name, None)
            if number is not None and signal.getsignal(number) is not signal.SIG_IGN:
                previous[number] = signal.signal(number, _raise_terminated)
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)


@contextlib.contextmanager
def _warnings_as_lines():
    """aarecovery's own warnings as ``aarecovery: warning: ...``, each once per run."""
    with warnings.catch_warnings():
        shown = warnings.showwarning

        def show(message, category, filename, lineno, file=None, line=None):
            if issubclass(category, AarecoveryWarning):
                print(f"aarecovery: warning: {printable(message)}", file=sys.stderr, flush=True)
            else:
                shown(message, category, filename, lineno, file, line)

        warnings.showwarning = show
        warnings.filterwarnings("default", category=AarecoveryWarning)
        yield


def _memory_advice(args):
    """What may help a command that ran out of memory: only the options it has, and the
    backend only where it recovers (``filter`` without ``--recover`` does not)."""
    advice = []
    if getattr(args, "tile_size", False) is not False:
        advice.append("a smaller --tile-size")
    if getattr(args, "backend", "numpy") != "numpy" and getattr(args, "recover", True):
        advice.append("--backend numpy")
    return ", ".join(advice + ["closing other programs or a machine with more memory"])


def main(argv=None):
    """Run the command line; return the exit status (0 on success, 128 + N after signal N)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not hasattr(args, "run"):
        parser.print_help()
        return 2
    try:
        with _terminating_signals_interrupt(), _warnings_as_lines():
            return int(args.run(args) or 0)
    except ImportError as error:
        extra = extra_for(error)
        if extra is None:
            raise
        print(f"aarecovery: error: {printable(missing_extra(args.prog, extra, error))}", file=sys.stderr)
        return 1
    except InputError as error:
        print(f"aarecovery: error: {printable(error)}", file=sys.stderr)
        return 1
    except OSError as error:
        print(f"aarecovery: error: {printable(os_error_line(error))}", file=sys.stderr)
        return 1
    except MemoryError as error:
        # The core says how much it needed where it can (NotEnoughMemory); anything else is bare.
        advice = "" if isinstance(error, NotEnoughMemory) else f"; try {_memory_advice(args)}"
        print(f"aarecovery: error: {printable(str(error) or 'out of memory')}{advice}", file=sys.stderr)
        return 1
    except KeyboardInterrupt as interruption:
        number = getattr(interruption, "signum", signal.SIGINT)
        print(f"aarecovery: interrupted ({signal.Signals(number).name}); no half-written file was left",
              file=sys.stderr)
        return 128 + number


if __name__ == "__main__":
    sys.exit(main())
