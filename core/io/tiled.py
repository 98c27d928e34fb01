"""TIFF files read and written in pieces, so that memory is bounded by a tile, not the image.

A TIFF stores its pixels in independently compressed segments (tiles, or strips of rows),
listed by offset in the file. :class:`TiffRegions` decodes only the segments a region
overlaps (tifffile's own per-segment decoder, so every compression tifffile reads works),
and :class:`TiledTiffWriter` writes a tiled TIFF, BigTIFF when it may pass 4 GB, tile by
tile, atomically. PNG, JPEG and the other formats have no such segments (a PNG is one
compressed stream) and are read whole by :func:`aarecovery.read_image`.

Decoding the segments here, not through ``tifffile.imread(selection=...)``: that needs the
``zarr`` package and reopens the file and builds a Zarr array per call. Measured on a
20000 x 20000 RGB file in 512 x 512 zstd tiles, 1032 x 1032 regions (a streamed tile with
its halo) at nine places, no segment cached: 0.033 s each here, 0.068 s through Zarr, the
same pixels.
"""

import contextlib
import os
from collections import OrderedDict

import numpy as np

from ..errors import InputError
from .formats import import_codec
from .read import _decode_error, _unpremultiply
from .parts import create_part
from .write import DiskError, _default_permissions, _encoded_pixels, disk_error, tiff_options

__all__ = ["TiffRegions", "tiff_regions", "TiledTiffWriter", "LARGEST_SEGMENT"]

#: A segment (tile or strip) larger than this, decoded, makes a file unsuitable for reading in
#: pieces: one strip of a whole image (the layout of most non-tiled TIFFs) is the image.
LARGEST_SEGMENT = 64 << 20
# Decoded segments kept for the next region: the blocks of a streamed recovery overlap their
# neighbours by a few pixels, and a row of 256 x 256 RGB tiles across a 20000-pixel image
# is 15 MB, so 64 MB keeps the left neighbour's column of segments.
_SEGMENT_CACHE_BYTES = 64 << 20
_TIFF_SIGNATURES = (b"II*\x00", b"MM\x00*", b"II+\x00", b"MM\x00+")


def tiff_regions(path):
    """Open `path` for reading in pieces, or return None when it cannot be read that way.

    None is not an error: the file may be another format, a TIFF in one strip, or a TIFF
    kind that only :func:`aarecovery.read_image` converts (palette, CMYK, YCbCr, 1-bit,
    bit depths other than 8, 16 and float); read it whole then.
    """
    path = os.fspath(path)
    try:
        with open(path, "rb") as file:
            if file.read(4) not in _TIFF_SIGNATURES:
                return None
    except OSError:
        return None
    tifffile = import_codec("tifffile", "TIFF")
    try:
        tif = tifffile.TiffFile(path)
    except Exception:
        return None
    try:
        regions = TiffRegions(path, tif)
    except _NotInPieces:
        tif.close()
        return None
    return regions


class _NotInPieces(Exception):
    pass


class TiffRegions:
    """The first image of a TIFF file, read region by region.

    Regions come in :func:`aarecovery.read_image`'s conventions: samples last, grey as
    ``(H, W)``, straight alpha, uint8, uint16 or float32. Use :func:`tiff_regions` to open
    one; close it (or use it as a context manager) when done.

    Attributes
    ----------
    path : str
    shape : tuple of int
        ``(H, W)`` or ``(H, W, C)``, what ``read_image`` would give.
    dtype : numpy.dtype
    segment_shape : tuple of int
        ``(rows, columns)`` of one tile or strip.
    """

    def __init__(self, path, tif):
        import tifffile

        self.path = path
        self._tif = tif
        page = tif.pages.first
        names = tifffile.PHOTOMETRIC
        separate, depth, height, width, contig = page.shaped
        samples = separate * contig
        if depth != 1 or not 1 <= samples <= 4:
            raise _NotInPieces
        if page.photometric not in (names.MINISBLACK, names.RGB) or (page.photometric == names.MINISBLACK
                                                                     and samples > 2):
            raise _NotInPieces
        if page.dtype is None or page.dtype.kind not in "uf" or (page.dtype.kind == "u" and page.bitspersample
                                                               not in (8, 16)) or page.is_subsampled:
            raise _NotInPieces
        rows, cols = (page.tilelength, page.tilewidth) if page.is_tiled else (page.rowsperstrip, width)
        rows = min(rows, height)
        if rows * cols * contig * page.dtype.itemsize > LARGEST_SEGMENT or len(page.dataoffsets) < 2:
            raise _NotInPieces
        self._page = page
        self._separate = separate > 1
        self._grid = (-(-height // rows), -(-width // cols))
        self._associated = samples in (2, 4) and tuple(page.extrasamples or ())[:1] == (
            tifffile.EXTRASAMPLE.ASSOCALPHA,)
        self.segment_shape = (rows, cols)
        self.shape = (height, width) if samples == 1 else (height, width, samples)
        self.dtype = np.dtype(np.float32) if page.dtype.kind == "f" else page.dtype
        self._cache = OrderedDict()
        self._cached_bytes = 0

    def read(self, rows, cols):
        """Pixels in `rows` and `cols` (slices with a step of 1, within the image).

        Returns
        -------
        ndarray, shape (rows, cols) or (rows, cols, C)

        Raises
        ------
        InputError
            When a segment is missing or cannot be decoded (a truncated or corrupt file).
        """
        top, bottom = rows.indices(self.shape[0])[:2]
        left, right = cols.indices(self.shape[1])[:2]
        samples = 1 if len(self.shape) == 2 else self.shape[2]
        out = np.empty((bottom - top, right - left, samples), self._page.dtype)
        seg_rows, seg_cols = self.segment_shape
        planes = samples if self._separate else 1
        across = self._grid[1]
        for plane in range(planes):
            for row in range(top // seg_rows, (bottom - 1) // seg_rows + 1):
                for col in range(left // seg_cols, (right - 1) // seg_cols + 1):
                    index = (plane * self._grid[0] + row) * across + col
                    self._place(out, self._segment(index), row * seg_rows, col * seg_cols, top, left, plane)
        if self._associated:
            out = _unpremultiply(out)
        out = out.astype(self.dtype, copy=False)
        return out[..., 0] if samples == 1 else out

    def _place(self, out, segment, y, x, top, left, plane):
        height, width = out.shape[:2]
        y0, x0 = max(y, top), max(x, left)
        y1, x1 = min(y + segment.shape[0], top + height), min(x + segment.shape[1], left + width)
        if y1 <= y0 or x1 <= x0:
            return
        target = out[y0 - top:y1 - top, x0 - left:x1 - left]
        piece = segment[y0 - y:y1 - y, x0 - x:x1 - x]
        if self._separate:
            target[..., plane] = piece[..., 0]
        else:
            target[...] = piece

    def _segment(self, index):
        cached = self._cache.get(index)
        if cached is not None:
            self._cache.move_to_end(index)
            return cached
        page = self._page
        try:
            offset, count = page.dataoffsets[index], page.databytecounts[index]
            data = None
            if count:
                handle = self._tif.filehandle
                handle.seek(offset)
                data = handle.read(count)
                if len(data) != count:
                    raise ValueError(f"segment {index} is cut short ({len(data)} of {count} bytes)")
            segment, _, shape = page.decode(data, index, jpegtables=page.jpegtables)
        except InputError:
            raise
        except Exception as error:
            raise _decode_error(self.path, "TIFF", error) from None
        if segment is None:
            segment = np.zeros(shape, page.dtype)
        segment = segment[0]
        self._cache[index] = segment
        self._cached_bytes += segment.nbytes
        while self._cached_bytes > _SEGMENT_CACHE_BYTES and len(self._cache) > 1:
            _, dropped = self._cache.popitem(last=False)
            self._cached_bytes -= dropped.nbytes
        return segment

    def close(self):
        """Close the file."""
        self._cache.clear()
        self._tif.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class TiledTiffWriter:
    """Write one image as a tiled TIFF, tile by tile, atomically.

    Tiles go to a temporary file in the destination's folder (named like
    :func:`aarecovery.write_image`'s, ``.NAME.XXXX.part.tif``), which replaces the
    destination only when every tile is written: an interrupted or failed write leaves the
    destination as it was and removes the temporary file. The file is BigTIFF when the
    pixels could pass 4 GB; the pixels are stored as :func:`aarecovery.write_image` stores
    them in a TIFF (8/16-bit or 32-bit float, zlib with a predictor, unassociated alpha).

    Parameters
    ----------
    path : str or os.PathLike
        Ends in .tif or .tiff; its folder must exist.
    shape : tuple of int
        The whole image, ``(H, W)`` or ``(H, W, C)``.
    dtype : numpy.dtype
        uint8, uint16 or float (stored as float32).
    tile : int
        The tile side, a multiple of 16 (TIFF's rule).
    """

    def __init__(self, path, shape, dtype, tile):
        if tile % 16:
            raise ValueError(f"TIFF tiles are multiples of 16 pixels, got {tile}")
        self.path = os.fspath(path)
        self.shape = tuple(shape)
        self.tile = tile
        self._dtype = np.dtype(dtype)

    def write(self, pieces):
        """Write the image from `pieces`, the tiles in row-major order.

        Parameters
        ----------
        pieces : iterable of ndarray
            Each tile of the grid of :attr:`tile`-sided tiles, left to right then top to
            bottom; those at the right and bottom edges may be cut to the image.
        """
        tifffile = import_codec("tifffile", "TIFF")
        channels = 1 if len(self.shape) == 2 else self.shape[2]
        stored = np.float32 if self._dtype.kind == "f" else self._dtype
        bigtiff = int(np.prod(self.shape)) * np.dtype(stored).itemsize > 2**32 - 2**25
        encoded = (_encoded_pixels(np.asarray(piece), "TIFF") for piece in pieces)
        folder = os.path.dirname(os.path.abspath(self.path))
        name, extension = os.path.splitext(os.path.basename(self.path))
        # A locked part, as write_image's: a streamed write can take hours, and a run beside
        # it that tidies stale parts in the folder must see that this one's writer lives.
        try:
            descriptor, temporary = create_part(folder, name, extension)
        except OSError as error:
            raise disk_error(error, folder, self.path) from None
        try:
            with open(temporary, "wb") as file:
                with tifffile.TiffWriter(file, bigtiff=bigtiff) as tif:
                    tif.write(encoded, shape=self.shape, dtype=stored, tile=(self.tile, self.tile),
                              **tiff_options(channels))
                file.flush()
                os.fsync(file.fileno())
            os.chmod(temporary, _default_permissions(self.path))
            os.replace(temporary, self.path)
        except BaseException as error:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(temporary)
            if isinstance(error, OSError) and not isinstance(error, DiskError):
                raise disk_error(error, folder, self.path) from None
            raise
        finally:
            os.close(descriptor)
