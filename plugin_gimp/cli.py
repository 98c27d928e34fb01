"""``aarecovery gimp install|uninstall|status``: manage the GIMP 3 plug-in."""

import sys
import time

from . import InstallError

__all__ = ["register", "run"]


def register(subparsers):
    """Add the ``gimp`` subcommand to the ``aarecovery`` command line."""
    parser = subparsers.add_parser(
        "gimp", help="install, remove or check the GIMP 3 plug-in",
        description="Manage the GIMP 3 plug-in (Filters > Enhance > Antialiasing Recovery). "
                    "The plug-in goes into GIMP 3's user plug-ins folder (the Flatpak GIMP's "
                    "with --flatpak); set GIMP3_DIRECTORY or use --plugins-dir for another "
                    "profile. --bundle puts the core and its compiled packages, for the "
                    "Python GIMP runs, next to the plug-in, so that GIMP needs no other Python.")
    parser.add_argument("action", choices=("install", "uninstall", "status"))
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--plugins-dir", metavar="DIR",
                       help="a GIMP plug-ins folder (default: the user's GIMP 3 plug-ins folder)")
    where.add_argument("--flatpak", action="store_true",
                       help="the Flatpak GIMP's profile, ~/.var/app/org.gimp.GIMP/config/GIMP/3.0 "
                            "(implies --bundle)")
    parser.add_argument("--python", metavar="PATH",
                        help="install: the Python with aarecovery that the plug-in falls back to "
                             "when GIMP's own Python cannot import it (default: this Python)")
    bundling = parser.add_argument_group(
        "bundle (install)", "GIMP's Python is asked for its version and platform, unless "
                            "--python-version and --platform say them")
    bundling.add_argument("--bundle", action="store_true",
                          help="bundle the core, NumPy and moderngl for GIMP's Python (pip "
                               "downloads the wheels, about 17 MB)")
    bundling.add_argument("--gimp-python", metavar="PATH",
                          help="the Python GIMP runs plug-ins with, to ask (implies --bundle)")
    bundling.add_argument("--python-version", metavar="X.Y",
                          help="the Python version GIMP runs, e.g. 3.12 (implies --bundle)")
    bundling.add_argument("--platform", metavar="TAG",
                          help="the wheels' platform tag, e.g. manylinux_2_28_x86_64, "
                               "macosx_11_0_arm64 (implies --bundle)")
    bundling.add_argument("--wheel-dir", metavar="DIR",
                          help="keep the downloaded wheels in DIR and reuse them next time")
    parser.set_defaults(run=run)


def run(args):
    """Carry out ``args.action``; return the exit status. Errors are one line on stderr."""
    try:
        return {"install": _install, "uninstall": _uninstall, "status": _status}[args.action](args)
    except (InstallError, OSError) as error:   # python -m aarecovery.gimp has no other handler
        print(f"aarecovery: error: {error}", file=sys.stderr)
        return 1


def _profile(args):
    from .profiles import choose_profile
    profile, note = choose_profile(args.plugins_dir, args.flatpak)
    if note:
        print(note)
    return profile


def _gimp_target(args, profile):
    """A callable that finds the target of `profile`'s GIMP the way the options say."""
    from .gimp_python import target_for
    return lambda: target_for(profile.kind, args.gimp_python, args.python_version, args.platform)


def _install(args):
    from . import install as inst
    from .bundle import folder_size
    from .gimp_python import caveat

    profile = _profile(args)
    wants_bundle = bool(args.bundle or args.gimp_python or args.python_version or args.platform)
    if profile.kind == "flatpak" and not wants_bundle:
        print("the Flatpak GIMP cannot start a Python outside its sandbox, so the core is bundled")
        wants_bundle = True
    target = _gimp_target(args, profile)() if wants_bundle else None
    if target is not None and caveat(target):
        print(f"note: {caveat(target)}")
    # The Flatpak's GIMP could not run a recorded Python; record none there.
    python = args.python if args.python else ("" if profile.kind == "flatpak" else None)
    start = time.monotonic()
    script = inst.install(profile.plugins_dir, python=python, target=target,
                          wheel_dir=args.wheel_dir)
    print(f"installed {script}")
    if target is not None:
        site = script.parent / inst.BUNDLE_FOLDER
        print(f"bundled the core for CPython {target.python} on {target.platform} in {site} "
              f"({folder_size(site) / 1e6:.0f} MB, {time.monotonic() - start:.0f} s)")
    print("restart GIMP; the entries are under Filters > Enhance > Antialiasing Recovery")
    return 0


def _uninstall(args):
    from . import install as inst
    profile = _profile(args)
    folder = profile.plugins_dir / inst.PLUGIN_NAME
    removed = inst.uninstall(profile.plugins_dir)
    print(f"removed {folder}" if removed else f"not installed: {folder}")
    return 0


def _status(args):
    from . import install as inst
    from .profiles import find_profiles

    print("GIMP profiles on this machine:")
    for found in find_profiles():
        state = "plug-in installed" if (found.plugins_dir / inst.PLUGIN_NAME).is_dir() else \
            "no plug-in"
        gimp = "" if found.found else ", GIMP not found"
        print(f"  {found.kind:8} {found.plugins_dir} ({state}{gimp})")
    profile = _profile(args)
    info = inst.status(profile.plugins_dir, gimp_target=_gimp_target(args, profile))
    print(f"plug-in folder: {info['folder']}")
    print(f"installed:      {'yes' if info['installed'] else 'no'}")
    if info["installed"]:
        print(f"executable:     {'yes' if info['executable'] else 'NO'}")
        print(f"up to date:     {'yes' if info['current'] else 'no'}")
    if info["bundle"]:
        manifest = info["bundle"]
        packages = ", ".join(f"{k} {v}" for k, v in manifest.get("packages", {}).items())
        print(f"bundle:         CPython {manifest.get('python')} on {manifest.get('platform')}: "
              f"{packages} ({'up to date' if info['bundle_current'] else 'OUT OF DATE'})")
        print(f"GIMP's Python:  {info['gimp_python']}")
    if info["installed"] and info["python"]:
        ok = "imports aarecovery" if info["python_ok"] else "CANNOT import aarecovery"
        print(f"fallback Python: {info['python']} ({ok})")
    for problem in info["problems"]:
        print(f"problem: {problem}")
    return 0 if not info["problems"] else 1
