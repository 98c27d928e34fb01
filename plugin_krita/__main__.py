"""``python -m aarecovery.krita install|remove|status``: the same as ``aarecovery krita ...``."""

import argparse
import sys

from .cli import register


def main(argv=None):
    """Run the ``krita`` subcommand on its own; return the exit status."""
    parser = argparse.ArgumentParser(prog="python -m aarecovery.krita")
    register(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(["krita", *(sys.argv[1:] if argv is None else argv)])
    return args.run(args)


if __name__ == "__main__":
    sys.exit(main())
