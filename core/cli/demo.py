"""``aarecovery demo``: filter a sample (or the user's image), recover it, write a comparison sheet."""

import os
import time

from ..params import BACKENDS
from .inputs import add_image_memory_option

__all__ = ["register", "run"]


def register(subparsers):
    """Add ``aarecovery demo``."""
    parser = subparsers.add_parser(
        "demo", help="filter a sample (or IMAGE), recover it and write a comparison sheet",
        description="Apply threshold, posterize and gradient map to a bundled sample or to IMAGE, recover each, "
                    "and write O, F, R and a side-by-side sheet with magnified insets.")
    parser.add_argument("image", nargs="?", metavar="IMAGE", help="your image (default: the bundled sample)")
    parser.add_argument("-o", "--output", default="aarecovery-demo", metavar="DIR",
                        help="output folder (default %(default)s)")
    parser.add_argument("--backend", choices=BACKENDS, default="auto",
                        help="recovery backend (default auto)")
    parser.add_argument("--paper", action="store_true", help="the paper's method, without the safe default")
    add_image_memory_option(parser)
    parser.set_defaults(run=run)


def run(args):
    image = None
    if args.image:
        from .inputs import read_input
        image = read_input(args.image, args)
    from ..lab.demo import run_demo

    start = time.perf_counter()
    outcome = run_demo(image, args.output, backend=args.backend, paper=args.paper)
    if image is not None and outcome["shrunk"] is not None:
        from ..lab.demo import MIN_SCENE_SIDE, SCENE_FACTOR
        width, height = outcome["shrunk"]
        print(f"{args.image} ({image.shape[1]}x{image.shape[0]}) was shrunk {SCENE_FACTOR}x to {width}x{height} "
              f"for O: the demo treats an image of {MIN_SCENE_SIDE} px or more a side as a supersampled scene, "
              "whose full-size filtering is the reference the gains below are measured against")
    print(f"wrote {len(outcome['files'])} images to {os.path.abspath(outcome['folder'])}/ "
          f"in {time.perf_counter() - start:.1f} s")
    print(f"comparison sheet: {os.path.abspath(outcome['sheet'])}")
    print(f"{'filter':12s} {'F':>8s} {'R':>8s} {'gain':>8s}   (edge-band PSNR against the reference, dB)")
    for name, gain in outcome["gains"].items():
        if gain is None:
            print(f"{name:12s} {'-':>8s} {'-':>8s} {'-':>8s}   (image under 256 px: no reference)")
        else:
            print(f"{name:12s} {gain[0]:8.2f} {gain[1]:8.2f} {gain[1] - gain[0]:+8.2f}")
    return 0
