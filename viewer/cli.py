"""``aarecovery view``: the interactive viewer (needs the ``viewer`` extra: glfw, imgui-bundle)."""

import argparse
import os
import warnings

from aarecovery import PARAMETERS

# Only the table of views: the GUI packages are imported inside run().
from .keys import VIEW_MODES as _VIEW_NAMES

__all__ = ["register", "run"]

_DESCRIPTION = """\
Open a window showing the recovered image R with live sliders for sigma_d, sigma_e and the
iteration count, a split view, flicker, a |R - F| heat-map and the intermediate maps.
With ORIGINAL alone, F is made with a built-in filter (--filter); with no image at all, the
bundled sample is shown. Press H in the window for the keys."""

_EPILOG = """\
examples:
  aarecovery view photo.png thresholded.png
  aarecovery view photo.png --filter threshold
  aarecovery view                                   the bundled sample
  aarecovery view --bench                           frame time and slider latency (docs/performance.md)
  aarecovery view o.png f.png --screenshot shot.png save the first frames' picture and exit
"""


def register(subparsers):
    """Add the ``view`` subcommand to an argparse subparsers object."""
    parser = subparsers.add_parser(
        "view", help="interactive viewer with live parameters and comparisons",
        description=_DESCRIPTION, epilog=_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("original", metavar="ORIGINAL", nargs="?", help="the image before the filter")
    parser.add_argument("filtered", metavar="FILTERED", nargs="?",
                        help="the same image after the filter; omit it to use --filter")
    parser.add_argument("--filter", metavar="NAME", dest="filter_name",
                        help="built-in filter that makes F from ORIGINAL when FILTERED is not given "
                             "(see the panel's list; default posterize)")
    for spec in PARAMETERS.values():
        default = f"default: {spec.automatic}" if spec.automatic else "default %(default)s"
        parser.add_argument(spec.option, type=spec.kind, default=spec.default, metavar="N" if spec.kind is int else "X",
                            help=f"initial {spec.label} ({spec.minimum:g} to {spec.maximum:g}; {default})")
    parser.add_argument("--view", choices=[mode for mode, _, _ in _VIEW_NAMES], default="result",
                        help="what the window shows first (keys 1 to 9 switch; default %(default)s)")
    parser.add_argument("--size", default="1280x720", metavar="WxH", help="window size (default %(default)s)")
    parser.add_argument("--max-image-memory", type=float, metavar="GB",
                        help="largest decoded size of one image, checked before decoding (default: that of "
                             "'aarecovery recover'); sets AARECOVERY_MAX_IMAGE_MEMORY for the session")
    parser.add_argument("--screenshot", metavar="PNG",
                        help="render a few frames, write the window's picture to PNG and exit")
    parser.add_argument("--bench", action="store_true",
                        help="measure frame time and slider-to-frame latency, print them and exit")
    parser.add_argument("--bench-size", default="1920x1080", metavar="WxH",
                        help="image size of the generated pair --bench uses without files (default %(default)s)")
    parser.set_defaults(run=run)
    return parser


def _size(text, option):
    from aarecovery import InputError
    try:
        width, height = (int(part) for part in text.lower().split("x"))
    except ValueError:
        raise InputError(f"{option} must look like 1280x720, got {text!r}") from None
    if width < 1 or height < 1:
        raise InputError(f"{option} must be positive, got {text!r}")
    return width, height


def run(args):
    """Open the viewer (or run --bench / --screenshot); returns the exit status."""
    # Without the viewer extra this raises ImportError, which the command line turns into
    # one line saying how to install the extra.
    import glfw  # (first: it decides which GLFW library loads)
    import imgui_bundle  # noqa: F401
    from aarecovery import InputError

    from .app import ViewerApp, WindowError
    from .settings import RecoverySettings
    from .sources import SAMPLE_FILTER, PairSource, sample_source

    if args.max_image_memory is not None:
        if not args.max_image_memory > 0:
            raise InputError(f"--max-image-memory takes a positive number of GB, got {args.max_image_memory:g}")
        # read_image's documented setting, for every image the session opens.
        os.environ["AARECOVERY_MAX_IMAGE_MEMORY"] = str(args.max_image_memory)
    window_size = _size(args.size, "--size")
    if args.filtered and args.filter_name:
        raise InputError("give either FILTERED or --filter, not both")
    settings = RecoverySettings.defaults().with_values(
        **{name: spec.check(getattr(args, name)) for name, spec in PARAMETERS.items()})
    # GLFW's own warnings repeat the reason that the one-line error gives (no GL 3.3 window).
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", glfw.GLFWError)
        if args.bench:
            from .bench import run_bench
            try:
                return run_bench(args.original, args.filtered, args.filter_name,
                                 _size(args.bench_size, "--bench-size"), window_size)
            except WindowError as error:
                raise InputError(str(error)) from None
        if args.original:
            source = PairSource(args.original, args.filtered,
                                None if args.filtered else args.filter_name or SAMPLE_FILTER)
        else:
            source = sample_source()
        try:
            app = ViewerApp(source, settings=settings, size=window_size)
        except WindowError as error:
            raise InputError(str(error)) from None
    try:
        app.comparison.set_view_mode(args.view)
        if source is None:
            app.messages.error("the bundled sample is not in this install; open files from the panel")
        if args.screenshot:
            return _screenshot(app, args.screenshot)
        app.run()
    finally:
        app.close()
    return 0


def _screenshot(app, path):
    from aarecovery import write_image
    for _ in range(4):  # ImGui lays windows out over the first frames
        app.step()
    app.step(capture=True)
    write_image(path, app.last_screenshot)
    print(f"wrote {path} ({app.last_screenshot.shape[1]}x{app.last_screenshot.shape[0]})")
    return 0
