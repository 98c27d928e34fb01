"""``aarecovery recover``: repair one image pair from files."""

import argparse
import os

# Already imported with the package; the codecs and the engine's backends load in run().
from ..errors import InputError
from ..io.jpeg import read_quantization
from ..io.maps import MAP_SCALES, map_paths, maps_as_images
from ..params import BACKENDS, BLEND_SPACES, GL_PATHS, PARAMETERS
from ..tiling import DEFAULT_TILES, SENSIBLE_TILE
from .inputs import add_image_memory_option
from .text import printable

__all__ = ["register", "run", "summary_line", "add_recovery_options", "add_parameter_options", "MAP_SCALES"]

_DESCRIPTION = """\
Repair the antialiased edges of FILTERED (the image after a nonlinear filter) using the
edges of ORIGINAL (the image before it). The result has FILTERED's size, layout and bit
depth; OUTPUT's extension picks the file format."""

_EPILOG = """\
formats:
  read:  PNG 8/16-bit, TIFF 8/16-bit and 32-bit float, NumPy .npy, and as 8-bit JPEG, WebP,
         BMP, GIF and the other formats Pillow reads
  write: .png .tif .tiff .npy .jpg .jpeg .webp .bmp; 16-bit and float results written to
         .png are 16-bit, to .tif keep their depth (float stays 32-bit float), to JPEG, WebP
         and BMP become 8-bit

maps (--maps DIR), 16-bit grey PNGs, white = 1:
  alpha.png          coverage of the first extreme colour, as is
  beta.png           confidence, 0 keeps FILTERED, 1 imposes ORIGINAL's blend, as is
  edge_strength.png  sqrt(edge strength): the geometric mean of the Sobel magnitudes of
                     ORIGINAL and FILTERED (a black/white edge ~0.87; sigma-e 0.01 ~0.1)
  residual.png       10 x distance of ORIGINAL's colour from its two-colour blend
                     (white at 0.1, the default sigma-d)
  strength.png       the strength that multiplied the confidence at each pixel: the safe
                     default's per-region map (full where text and drawings, the
                     calibrated strength on a photo), as is

examples:
  aarecovery recover photo.png thresholded.png -o repaired.png
  aarecovery recover scan.tif posterised.tif -o repaired.tif --sigma-e 0.02 --maps maps/
  aarecovery recover o.png f.png -o f.png --overwrite       replace FILTERED with the result
  aarecovery recover o.npy f.npy -o r.npy --backend numpy --iterations 5
"""


def register(subparsers):
    """Add the ``recover`` subcommand to an argparse subparsers object."""
    parser = subparsers.add_parser(
        "recover", help="repair one image pair from files",
        description=_DESCRIPTION, epilog=_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("original", metavar="ORIGINAL", help="the image before the filter")
    parser.add_argument("filtered", metavar="FILTERED", help="the same image after the filter, same size")
    parser.add_argument("-o", "--output", metavar="OUTPUT", required=True,
                        help="where to write the result; its folder must exist")
    add_recovery_options(parser)
    parser.add_argument("--maps", metavar="DIR",
                        help="also write alpha, beta, edge_strength, residual and strength maps as 16-bit PNGs "
                             "into DIR (created if missing); scales below")
    parser.add_argument("--overwrite", action="store_true",
                        help="allow OUTPUT to replace ORIGINAL or FILTERED (any other existing file "
                             "is always replaced)")
    add_image_memory_option(parser)
    parser.set_defaults(run=run)
    return parser


def add_recovery_options(parser):
    """The recovery's options, shared by ``recover`` and ``batch``: parameters, backend, mode, tiles."""
    add_parameter_options(parser)
    parser.add_argument("--backend", choices=BACKENDS, default="auto",
                        help="auto uses OpenGL and falls back to NumPy (default %(default)s)")
    parser.add_argument("--gl-path", choices=GL_PATHS, default="auto",
                        help="how the GL backend runs its passes: fragment shaders (OpenGL 3.3) or compute "
                             "shaders (OpenGL 4.3); auto picks the faster for the device (default %(default)s)")
    parser.add_argument("--linear", action="store_true",
                        help="the images hold linear-light values (default: sRGB-encoded)")
    parser.add_argument("--blend-space", choices=BLEND_SPACES, default=None,
                        help="where the blend model is fitted and imposed (default: chosen per image; "
                             "linear with --paper)")
    parser.add_argument("--paper", action="store_true",
                        help="the published method exactly, without the safeguards that keep the "
                             "result from being worse than FILTERED on blurred or textured images")
    parser.add_argument("--tile-size", type=int, metavar="N",
                        help="largest tile side in pixels; larger images are processed in overlapping "
                             f"tiles with the same result (default: {DEFAULT_TILES['gl']} on a GPU, "
                             f"{DEFAULT_TILES['gl-software']} on a CPU renderer, {DEFAULT_TILES['numpy']} on "
                             f"NumPy; at least {SENSIBLE_TILE}); tiled TIFFs are streamed in tiles of this size")


def add_parameter_options(parser):
    """``--sigma-d``, ``--sigma-e``, ``--iterations`` and ``--strength``, from ``aarecovery.params``."""
    for spec in PARAMETERS.values():
        default = f"default: {spec.automatic}" if spec.automatic else "default %(default)s"
        parser.add_argument(spec.option, type=spec.kind, default=spec.default, metavar="N" if spec.kind is int else "X",
                            help=f"{spec.help} ({spec.minimum:g} to {spec.maximum:g}; {default})")


def _reads_whole(args):
    """Whether the pair is read whole: anything but a TIFF that can be read in pieces, which
    may stream tile by tile once the engine has said its tile size."""
    from ..io.tiled import tiff_regions

    if args.maps is not None:
        return True
    regions = tiff_regions(args.original)
    if regions is None:
        return True
    regions.close()
    return False


def _largest_tile(args):
    """The largest tile side the chosen backend may use, known before its engine is made."""
    from ..tiling import DEFAULT_TILES

    return args.tile_size or DEFAULT_TILES["numpy" if args.backend == "numpy" else "gl"]


def _start_reading(pool, args):
    """Decode both images in two threads of `pool` (the codecs release the GIL), once the
    recovery's peak is known to fit the image memory limit: with the largest tile the
    backend may use, as the engine that says its tile is made while the images decode."""
    from ..memory import check_pair_files
    from .inputs import memory_limit, read_input

    paths = (args.original, args.filtered)
    check_pair_files(*paths, _largest_tile(args), maps=args.maps is not None, max_bytes=memory_limit(args))
    return [pool.submit(read_input, path, args) for path in paths]


def _finish_reading(reads, args):
    from .inputs import check_pair_size

    original, filtered = (read.result() for read in reads)
    check_pair_size(original, filtered, (args.original, args.filtered))
    return original, filtered


def run(args):
    """Run ``aarecovery recover`` with parsed arguments; return the exit status."""
    from concurrent.futures import ThreadPoolExecutor

    from ..io import check_output_path
    from ..params import Parameters
    from ..tiling import check_tile_size
    from .outputs import check_destinations, remove_stale_parts_of

    params = Parameters(args.sigma_d, args.sigma_e, args.iterations, args.strength)
    if args.tile_size is not None:
        check_tile_size(args.tile_size, params.iterations, name="--tile-size")
    check_output_path(args.output)
    inputs = {"original": args.original, "filtered": args.filtered}
    outputs = [args.output]
    if args.maps is not None:
        if os.path.exists(args.maps) and not os.path.isdir(args.maps):
            raise InputError(f"--maps {args.maps} is a file; give a folder to write the maps into")
        outputs += map_paths(args.maps).values()
    # Every destination before anything is read, computed or written.
    check_destinations(outputs, inputs, overwrite=args.overwrite, folders=[args.maps] if args.maps else [])
    remove_stale_parts_of(outputs)

    pool = ThreadPoolExecutor(max_workers=2)
    try:
        return _recover_files(args, params, pool)
    finally:
        pool.shutdown(wait=False, cancel_futures=True)


def _recover_files(args, params, pool):
    """The pair read, recovered and written, with `pool`'s two threads for the files."""
    import dataclasses
    import time

    from ..engine import Engine
    from ..io import check_output_path, write_images
    from ..outcome import count_changed_pixels
    from ..pipeline import recover
    from ..sample import array_window

    # A pair read whole decodes while the engine makes its GL context; when it cannot (no
    # OpenGL), the error comes without waiting for the decoding.
    reads = _start_reading(pool, args) if _reads_whole(args) else None
    engine = Engine(args.backend, gl_path=args.gl_path)
    try:
        pair = None if reads is not None else _open_streamed(args, params, engine)
        if pair is not None:
            with pair:
                for line in _recover_streamed(args, params, pair, engine):
                    print(printable(line))
            return 0
        original, filtered = _finish_reading(reads or _start_reading(pool, args), args)
        reads = None  # the futures hold the decoded pair too
        # Before the recovery, so that a long run does not end in a refusal.
        check_output_path(args.output, filtered.shape)
        start = time.perf_counter()
        result = recover(original, filtered, sigma_d=params.sigma_d, sigma_e=params.sigma_e,
                         iterations=params.iterations, linear=args.linear, blend_space=args.blend_space,
                         return_maps=args.maps is not None, tile_size=args.tile_size, engine=engine,
                         mode="paper" if args.paper else "safe", strength=params.strength,
                         quantization=read_quantization(args.original))
        seconds = time.perf_counter() - start
        backend = engine.backend
        plan = engine.last_plan
    finally:
        engine.release()
    maps = None
    if args.maps is not None:
        result, maps = result
    # The summary reads O only in the window the plan analysed (chosen here for --paper, as
    # the summary would): that crop is kept and the rest freed before the encoder makes its
    # buffer of filtered rows, where the process peaked (docs/performance.md).
    if plan.window is None:
        plan = dataclasses.replace(plan, window=array_window(original))
    original_window, original = original[plan.window].copy(), None
    images = {args.output: result}
    if maps is not None:
        os.makedirs(args.maps, exist_ok=True)
        images.update(maps_as_images(args.maps, maps))
    # The changed pixels are counted while the encoder writes (both release the GIL; the
    # count needs a few MB, the rest of the summary 20 MB at 4096 x 4096, so it comes after).
    counting = pool.submit(count_changed_pixels, filtered, result)
    # All or none: a failure while writing any map leaves the result unwritten too.
    write_images(images)
    message = (f"wrote {args.output} ({result.shape[1]}x{result.shape[0]}, {result.dtype}) "
               f"with the {backend} backend in {seconds:.2f} s")
    if args.maps is not None:
        message += f"; maps in {args.maps}"
    print(printable(message))
    print(summary_line(plan, original, filtered, result, linear=args.linear, changed_pixels=counting.result(),
                       original_window=original_window))
    return 0


def summary_line(plan, original=None, filtered=None, recovered=None, linear=False, changed_pixels=None,
                 original_window=None):
    """What the recovery did, in the command line's words (the plan alone for a streamed pair)."""
    from ..outcome import RecoverySummary, summarize_recovery

    summary = (RecoverySummary(plan, None, None) if recovered is None
               else summarize_recovery(plan, original, filtered, recovered, linear, changed_pixels=changed_pixels,
                                       original_window=original_window))
    return summary.line(force="--strength 1")


def _open_streamed(args, params, engine):
    """A pair of TIFFs that can be read in pieces and is larger than a tile, else None."""
    from ..io import warn_if_orientations_differ
    from ..stream import open_pair, resolve_tile
    from .inputs import memory_limit

    pair = open_pair(args.original, args.filtered, resolve_tile(engine.capabilities, args.tile_size),
                     params.iterations, max_bytes=memory_limit(args))
    if pair is not None:
        warn_if_orientations_differ(args.original, args.filtered)
    return pair


def _recover_streamed(args, params, pair, engine):
    """Recover a pair of TIFFs tile by tile from file to file; return the lines to print."""
    import time

    from ..io import check_output_path
    from ..stream import check_room, plan_pair, recover_pair

    check_output_path(args.output, pair.result_shape)
    check_room(pair, args.output)
    start = time.perf_counter()
    plan = plan_pair(pair, params, mode="paper" if args.paper else "safe", linear=args.linear,
                     blend_space=args.blend_space)
    recover_pair(pair, args.output, plan, engine=engine, tile=args.tile_size, linear=args.linear)
    return (f"wrote {args.output} ({pair.width}x{pair.height}, {pair.result_dtype}) with the {engine.backend} "
            f"backend in {time.perf_counter() - start:.2f} s, streamed in tiles", summary_line(plan))
