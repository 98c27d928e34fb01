"""Recovering a pair of TIFF files tile by tile, from file to file, in bounded memory.

A pair of TIFFs that can be read in pieces (tiled, or in strips; ``aarecovery.io.tiled``)
and is larger than one tile never comes into memory whole: the plan is made once from the
window that ``aarecovery.sample`` picks from the whole image, then each tile with its halo
is read from both files, recovered, and its inner part written as one tile of a tiled TIFF
(or, for a PNG or JPEG output, which cannot be written in pieces, placed into the result
in memory). The tiles of ``aarecovery.tiling`` make the result equal the untiled one, so a
streamed pair gives exactly what ``aarecovery.recover`` gives on the same pixels.
"""

import os
import queue
import shutil
import threading

import numpy as np

from .contract import check_same_size, check_values, layout_of
from .errors import InputError
from .io import check_decoded_size, write_image
from .io.limits import format_bytes
from .io.formats import WRITE_FORMATS
from .io.tiled import TiledTiffWriter, tiff_regions
from .pipeline import recover_tiles
from .plan import make_plan
from .sample import analysis_sample
from .tiling import aligned_tiles, halo_for

__all__ = ["open_pair", "check_room", "resolve_tile", "stream_tile", "plan_pair", "recover_pair", "StreamedPair",
           "STREAM_TILE"]

#: The largest tile a streamed pair is recovered in when no tile size is given (the NumPy
#: backend's own 512 is smaller). Measured on 2 cores with GL on llvmpipe, an 8192 x 8192
#: tiled RGB pair, thresholded, safe mode: 1024 took 4.6 s at a peak of 0.74 GB, GL's
#: in-memory 2048 took 6.8 s at 1.26 GB (the passes' textures grow with the tile).
STREAM_TILE = 1024


def _shape_only(shape, dtype):
    """An array of `shape` and `dtype` that takes no memory, for the contract's shape checks."""
    return np.broadcast_to(np.zeros((), dtype), shape)


class StreamedPair:
    """Two TIFF files read region by region, checked to be a pair.

    Attributes
    ----------
    original, filtered : TiffRegions
    height, width : int
    """

    def __init__(self, original, filtered):
        check_same_size(layout_of(_shape_only(original.shape, original.dtype), "original"),
                        layout_of(_shape_only(filtered.shape, filtered.dtype), "filtered"))
        self.original, self.filtered = original, filtered
        self.height, self.width = original.shape[:2]
        # Regions are read by the recovery and by a read-ahead thread.
        self._lock = threading.Lock()

    @property
    def result_shape(self):
        """tuple of int: the shape of R (the filtered file's)."""
        return self.filtered.shape

    @property
    def result_dtype(self):
        """numpy.dtype: the dtype of R (the filtered file's)."""
        return self.filtered.dtype

    @property
    def result_layout(self):
        """Layout: R's (the filtered file's), for :func:`aarecovery.pipeline.recover_tiles`."""
        return layout_of(_shape_only(self.filtered.shape, self.filtered.dtype), "filtered")

    def read(self, outer):
        """Both images on `outer` (rows, columns), checked like ``aarecovery.recover`` checks them."""
        with self._lock:
            original, filtered = self.original.read(*outer), self.filtered.read(*outer)
        check_values(original, layout_of(original, "original"), "original")
        check_values(filtered, layout_of(filtered, "filtered"), "filtered")
        return original, filtered

    def close(self):
        self.original.close()
        self.filtered.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def resolve_tile(capabilities, tile_size=None):
    """The tile side a pair streams at: `tile_size` when given, else the backend's default up
    to :data:`STREAM_TILE`; never more than the backend holds."""
    return min(capabilities.max_tile, tile_size or min(capabilities.default_tile, STREAM_TILE))


def stream_tile(tile, iterations, reach=0):
    """The inner side of a streamed tile: the largest multiple of 16 (TIFF's tile rule) that
    fits in `tile` with its halo (``halo_for(iterations, reach)``), and at least 16."""
    return max(16, (tile - 2 * halo_for(iterations, reach)) // 16 * 16)


def open_pair(original_path, filtered_path, tile, iterations, max_bytes=None):
    """Open a pair for streaming, or return None when it should be read whole.

    A pair streams when both files can be read in pieces (``aarecovery.io.tiled``) and it
    does not fit in one tile of side `tile` (from :func:`resolve_tile`); otherwise reading
    it whole costs no more.

    Streaming bounds the memory, not what a file may claim: a 15 MB BigTIFF declaring
    10^6 x 10^6 pixels streamed for hours. Each image's declared size is held to the same
    limit as an image read whole (`max_bytes`, ``--max-image-memory``), which a genuine
    gigapixel pair raises.

    Raises
    ------
    InputError
        When both can be read in pieces but are not a pair (different sizes), or either
        declares more than `max_bytes` decoded.
    """
    original = tiff_regions(original_path)
    if original is None:
        return None
    filtered = tiff_regions(filtered_path)
    side = stream_tile(tile, iterations) + 2 * halo_for(iterations)
    if filtered is None or max(original.shape[:2]) <= side:
        original.close()
        if filtered is not None:
            filtered.close()
        return None
    try:
        for regions in (original, filtered):
            check_decoded_size(regions.path, regions.shape, regions.dtype, max_bytes)
        return StreamedPair(original, filtered)
    except BaseException:
        original.close()
        filtered.close()
        raise


def check_room(pair, output):
    """Refuse a streamed result that will not fit on its disk, before hours of work.

    The result has FILTERED's size, depth and kind of content, so its file takes about as
    much as FILTERED's (the best estimate before it is compressed); a result written whole
    (not TIFF) is assembled in memory, bounded by :func:`open_pair`'s limit.
    """
    folder = os.path.dirname(os.path.abspath(os.fspath(output)))
    needed = os.path.getsize(pair.filtered.path)
    try:
        free = shutil.disk_usage(folder).free
    except OSError:
        return
    if needed > free:
        raise InputError(f"the result {output} will take about {format_bytes(needed)} (as much as the filtered "
                         f"file {pair.filtered.path}) and the disk holding {folder} has {format_bytes(free)} free; "
                         "free some space or write elsewhere (nothing was written)")


def plan_pair(pair, parameters, *, mode, linear=False, blend_space=None, planner=make_plan):
    """The pair's Plan, made once before tiling from the window ``aarecovery.sample`` picks.

    `planner` is ``aarecovery.plan.make_plan`` or a stand-in that runs it elsewhere (the
    batch runs it in worker processes).
    """
    sample = analysis_sample(pair.original.read, pair.filtered.read, pair.height, pair.width)
    return planner(*sample, parameters, mode=mode, linear=linear, blend_space=blend_space)


def _read_ahead(items, read):
    """Yield ``(item, read(item))`` while a thread reads the next item: decoding overlaps recovery."""
    items = iter(items)
    box = {}

    def fetch(item):
        try:
            box["value"] = read(item)
        except BaseException as error:  # handed to the consumer, which raises it
            box["error"] = error

    current = next(items, None)
    if current is None:
        return
    fetch(current)
    while current is not None:
        value, error = box.pop("value", None), box.pop("error", None)
        if error is not None:
            raise error
        following = next(items, None)
        worker = None
        if following is not None:
            worker = threading.Thread(target=fetch, args=(following,), daemon=True)
            worker.start()
        try:
            yield current, value
        finally:
            if worker is not None:
                worker.join()
        current = following


class _WriteBehind:
    """Feed a :class:`TiledTiffWriter` from a thread of its own: compression overlaps recovery.

    An exception in the producer aborts the write (the writer then removes its temporary
    file); an exception in the writer reaches the producer at its next :meth:`put`.
    """

    _DONE, _ABORT = object(), object()

    def __init__(self, writer):
        self._writer = writer
        # Two tiles waiting at most: memory stays a few tiles.
        self._queue = queue.Queue(maxsize=2)
        self._error = None
        self._thread = threading.Thread(target=self._write, daemon=True)

    def _tiles(self):
        while True:
            item = self._queue.get()
            if item is self._DONE:
                return
            if item is self._ABORT:
                raise _Aborted
            yield item

    def _write(self):
        try:
            self._writer.write(self._tiles())
        except BaseException as error:  # handed to the producer
            self._error = error
            while True:  # unblock a producer waiting on a full queue
                try:
                    self._queue.get_nowait()
                except queue.Empty:
                    break

    def put(self, piece):
        while True:
            if self._error is not None:
                raise self._error
            try:
                self._queue.put(piece, timeout=0.1)
                return
            except queue.Full:
                continue

    def __enter__(self):
        self._thread.start()
        return self

    def __exit__(self, kind, error, trace):
        if kind is None:
            self.put(self._DONE)
        else:
            while self._thread.is_alive():
                try:
                    self._queue.put(self._ABORT, timeout=0.1)
                    break
                except queue.Full:
                    continue
        self._thread.join()
        if kind is None and self._error is not None:
            raise self._error


class _Aborted(Exception):
    pass


def recover_pair(pair, output, plan, *, engine, tile=None, linear=False):
    """Recover a streamed pair into `output`, tile by tile.

    Parameters
    ----------
    pair : StreamedPair
    output : str or os.PathLike
        A .tif/.tiff output is written as a tiled TIFF (BigTIFF when needed), one tile at a
        time; any other format is assembled in memory (the result only) and written whole.
        Either way the write is atomic.
    plan : Plan
        From :func:`plan_pair`.
    engine : Engine
    tile : int, optional
        Largest tile side (:func:`resolve_tile`).
    linear : bool
    """
    side = stream_tile(resolve_tile(engine.capabilities, tile), plan.iterations, plan.reach)
    halo = halo_for(plan.iterations, plan.reach)
    grid = list(aligned_tiles(pair.height, pair.width, side, halo))
    if plan.keeps_filtered:
        pieces = ((inner, pair.filtered.read(*inner)) for inner, _ in grid)
    else:
        ahead = _read_ahead(grid, lambda piece: pair.read(piece[1]))
        pieces = ((inner, result) for inner, result, _ in
                  recover_tiles(engine, _Prefetched(ahead), plan, grid, pair.result_layout, linear=linear))
    if WRITE_FORMATS.get(os.path.splitext(os.fspath(output))[1].lower()) == "TIFF":
        with _WriteBehind(TiledTiffWriter(output, pair.result_shape, pair.result_dtype, side)) as sink:
            for _, piece in pieces:
                sink.put(piece)
        return
    result = np.empty(pair.result_shape, pair.result_dtype)
    for inner, piece in pieces:
        result[inner] = piece
    write_image(output, result)


class _Prefetched:
    """A ``read(outer)`` for :func:`aarecovery.pipeline.recover_tiles` that takes each tile
    from the read-ahead, which reads the same tiles in the same order."""

    def __init__(self, ahead):
        self._ahead = ahead

    def __call__(self, outer):
        (_, expected), value = next(self._ahead)
        assert expected == outer, "tiles were read out of order"
        return value
