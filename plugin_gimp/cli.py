"""``aarecovery gimp install|uninstall|status``: manage the GIMP 3 plug-in."""

__all__ = ["register", "run"]


def register(subparsers):
    """Add the ``gimp`` subcommand to the ``aarecovery`` command line."""
    parser = subparsers.add_parser(
        "gimp", help="install, remove or check the GIMP 3 plug-in",
        description="Manage the GIMP 3 plug-in (Filters > Enhance > Antialiasing Recovery). "
                    "The plug-in goes into GIMP 3's user plug-ins folder; set GIMP3_DIRECTORY "
                    "or use --plugins-dir for another profile.")
    parser.add_argument("action", choices=("install", "uninstall", "status"))
    parser.add_argument("--plugins-dir", metavar="DIR",
                        help="a GIMP plug-ins folder (default: the user's GIMP 3 plug-ins folder)")
    parser.add_argument("--python", metavar="PATH",
                        help="install: the Python with aarecovery that the plug-in falls back to "
                             "when GIMP's own Python cannot import it (default: this Python)")
    parser.set_defaults(run=run)


def run(args):
    """Carry out ``args.action``; return the exit status."""
    from . import install as inst

    if args.action == "install":
        script = inst.install(args.plugins_dir, python=args.python)
        print(f"installed {script}")
        print("restart GIMP; the entries are under Filters > Enhance > Antialiasing Recovery")
        return 0
    if args.action == "uninstall":
        folder = inst.status(args.plugins_dir)["folder"]
        print(f"removed {folder}" if inst.uninstall(args.plugins_dir) else f"not installed: {folder}")
        return 0
    info = inst.status(args.plugins_dir)
    print(f"plug-in folder: {info['folder']}")
    print(f"installed:      {'yes' if info['installed'] else 'no'}")
    if info["installed"]:
        print(f"executable:     {'yes' if info['executable'] else 'NO'}")
        print(f"up to date:     {'yes' if info['current'] else 'no'}")
        ok = "imports aarecovery" if info["python_ok"] else "CANNOT import aarecovery"
        print(f"fallback Python: {info['python']} ({ok})")
    for problem in info["problems"]:
        print(f"problem: {problem}")
    return 0 if not info["problems"] else 1
