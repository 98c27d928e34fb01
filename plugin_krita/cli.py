"""``aarecovery krita install|remove|status``: manage the Krita 5 plug-in."""

import sys

from . import InstallError

__all__ = ["register", "run"]


def register(subparsers):
    """Add the ``krita`` subcommand to the ``aarecovery`` command line."""
    parser = subparsers.add_parser(
        "krita", help="install, remove or check the Krita 5 plug-in",
        description="Manage the Krita 5 plug-in (Tools > Scripts > Repair antialiasing). It goes "
                    "into pykrita in Krita's resource folder (the Flatpak Krita's with --flatpak) "
                    "and is enabled in kritarc. Restart Krita afterwards.")
    parser.add_argument("action", choices=("install", "remove", "status"))
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--resource-dir", metavar="DIR",
                       help="a Krita resource folder (default: the user's, ~/.local/share/krita on Linux)")
    where.add_argument("--flatpak", action="store_true",
                       help="the Flatpak Krita's folder, ~/.var/app/org.kde.krita/data/krita")
    parser.add_argument("--kritarc", metavar="FILE",
                        help="with --resource-dir: the kritarc to enable the plug-in in")
    parser.add_argument("--python", metavar="PATH",
                        help="install: the Python with aarecovery that the plug-in falls back to when "
                             "Krita's own Python cannot import it (default: this Python)")
    parser.set_defaults(run=run)


def run(args):
    """Carry out ``args.action``; return the exit status. Errors are one line on stderr."""
    from .install import choose_profile
    try:
        profile, note = choose_profile(args.resource_dir, args.kritarc, args.flatpak)
        if note:
            print(note)
        return {"install": _install, "remove": _remove, "status": _status}[args.action](args, profile)
    except (InstallError, OSError) as error:
        print(f"aarecovery: error: {error}", file=sys.stderr)
        return 1


def _install(args, profile):
    from .install import install
    # The Flatpak's Krita cannot start a Python outside its sandbox: record none there.
    python = args.python if args.python else ("" if profile.kind == "flatpak" else None)
    folder = install(profile, python)
    print(f"installed {folder}")
    print(f"enabled it in {profile.kritarc}" if profile.kritarc else
          "no kritarc given: tick it in Settings > Configure Krita > Python Plugin Manager")
    print("restart Krita; the entries are under Tools > Scripts > Repair antialiasing")
    return 0


def _remove(args, profile):
    from .install import PLUGIN_NAME, remove
    folder = profile.pykrita / PLUGIN_NAME
    print(f"removed {folder}" if remove(profile) else f"not installed: {folder}")
    return 0


def _status(args, profile):
    from .install import find_profiles, status
    print("Krita resource folders on this machine:")
    for found in find_profiles():
        state = "plug-in installed" if (found.pykrita / "aarecovery_krita").is_dir() else "no plug-in"
        print(f"  {found.kind:8} {found.resource_dir} ({state}{'' if found.found else ', Krita not found'})")
    info = status(profile)
    print(f"plug-in folder:  {info['folder']}")
    print(f"installed:       {'yes' if info['installed'] else 'no'}")
    if info["installed"]:
        print(f"up to date:      {'yes' if info['current'] else 'no'}")
        if info["enabled"] is not None:
            print(f"enabled:         {'yes' if info['enabled'] else 'NO'} ({profile.kritarc})")
        ok = "imports aarecovery" if info["python_ok"] else "CANNOT import aarecovery"
        print(f"fallback Python: {info['python'] or '(none)'} ({ok})")
    for problem in info["problems"]:
        print(f"problem: {problem}")
    return 0 if not info["problems"] else 1
