"""Writing image files atomically, in the bit depth their format can hold."""

import contextlib
import errno
import os
import re
import shutil

import numpy as np

from ..contract import check_values, layout_of
from ..errors import InputError, NotEnoughMemory
from .formats import NPY_DTYPES, WRITE_FORMATS, import_codec, layout_name
from .limits import format_bytes
from .parts import create_part
from .png import write_png

__all__ = ["write_image", "write_images", "check_output_path", "check_writable_folder", "DiskError",
           "disk_error", "os_error_line", "tiff_options"]

_JPEG_QUALITY = 95


def _format_of(path):
    extension = os.path.splitext(path)[1].lower()
    if extension not in WRITE_FORMATS:
        shown = f"its extension {extension!r}" if extension else "its name, which has no extension"
        raise InputError(f"cannot tell which format to write {path} in from {shown}; end the name in "
                         f"one of {', '.join(WRITE_FORMATS)}")
    return WRITE_FORMATS[extension]


def check_output_path(path, shape=None):
    """Check that an image can be written at `path` without writing anything.

    Parameters
    ----------
    path : str or os.PathLike
    shape : tuple of int, optional
        The image's shape, to check that the format can hold its channels.

    Returns
    -------
    str
        The format name the extension selects (``"PNG"``, ``"TIFF"``, ``"NPY"``, ``"JPEG"``,
        ``"WEBP"`` or ``"BMP"``).

    Raises
    ------
    InputError
        On an unknown extension, a missing folder, a path that is a folder, or (given
        `shape`) alpha for a format without alpha.
    """
    path = os.fspath(path)
    if os.path.isdir(path):
        raise InputError(f"{path} is a folder; give a file name inside it, such as "
                         f"{os.path.join(path, 'result.png')}")
    format_name = _format_of(path)
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise InputError(f"folder {folder} does not exist; create it first (nothing was written)")
    channels = None if shape is None else 1 if len(shape) == 2 else shape[2]
    if format_name in ("JPEG", "BMP") and channels in (2, 4):
        # BMP's alpha is ignored by most readers, Pillow's included.
        raise InputError(f"{format_name} cannot store the alpha channel of this {layout_name(shape)} image; "
                         f"write {os.path.splitext(path)[0]}.png (or .tif) instead, or drop the alpha first")
    return format_name


class DiskError(OSError):
    """The disk refused a write: one sentence that names the folder and says what to do."""

    def __str__(self):
        return self.strerror


# ndarray.tofile (tifffile writes arrays with it) reports a short write without an errno.
_SHORT_WRITE = re.compile(r"\d+ requested and \d+ written")


def disk_error(error, folder, path=None, nothing_written=True):
    """A :class:`DiskError` for an OSError met while writing `path` in `folder`.

    The message names the folder, not the hidden temporary file, and says why: full,
    read-only, no permission, or the system's own words.
    """
    code = error.errno
    if code is None and _SHORT_WRITE.search(str(error)):
        code = errno.ENOSPC
    what = f"cannot write {path}" if path else f"cannot write into {folder}"
    if code in (errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC)):
        try:
            free = f" ({shutil.disk_usage(folder).free / 1e6:.1f} MB free)"
        except OSError:
            free = ""
        message = (f"{what}: the disk (or quota) holding {folder} is full{free}; free some space or "
                   "write elsewhere")
    elif code == errno.EROFS:
        message = f"{what}: {folder} is on a read-only file system; choose a folder you can write to"
    elif code in (errno.EACCES, errno.EPERM):
        message = f"{what}: no permission to create files in {folder}; choose another folder or change its permissions"
    else:
        message = f"{what}: {error.strerror or error} (in {folder})"
    return DiskError(code, message + " (nothing was written)" if path and nothing_written else message)


def os_error_line(error):
    """One line for an OSError met outside :func:`write_image` (a folder made, a report
    written): a write the disk refused as :func:`disk_error` says it, anything else as
    ``PATH: reason`` instead of Python's ``[Errno N] reason: 'PATH'``."""
    if isinstance(error, DiskError) or error.errno is None or error.filename is None:
        return str(error)
    path = os.fsdecode(error.filename)
    if error.errno in (errno.ENOSPC, getattr(errno, "EDQUOT", errno.ENOSPC), errno.EROFS):
        return str(disk_error(error, os.path.dirname(os.path.abspath(path)), path, nothing_written=False))
    return f"{path}: {error.strerror or error}"


def check_writable_folder(folder):
    """Raise :class:`DiskError` unless a file can be created in `folder`.

    Tried for real, with an empty part file that is removed at once: permissions alone do
    not say it (root ignores them; a read-only mount or a full inode table does not show).
    """
    folder = os.fspath(folder)
    try:
        descriptor, probe = create_part(folder, "aarecovery-probe", ".tmp")
    except OSError as error:
        raise disk_error(error, folder) from None
    os.close(descriptor)
    os.unlink(probe)


def _encoded_pixels(image, format_name):
    """Convert `image` to what `format_name` stores, per the table in :func:`write_image`."""
    layout = layout_of(image, "image")
    if layout.channels == 1 and image.ndim == 3 and format_name != "NPY":
        image = image[..., 0]
    if format_name == "NPY":
        # read_image reads back float32 and float64; float16 and longdouble become float32.
        return image if image.dtype in NPY_DTYPES else image.astype(np.float32)
    if format_name == "TIFF" and image.dtype.kind == "f":
        return image.astype(np.float32, copy=False)
    if format_name in ("PNG", "TIFF") and image.dtype != np.uint8:
        depth, dtype = 65535, np.uint16
    else:
        depth, dtype = 255, np.uint8
    if image.dtype == dtype:
        return image
    if image.dtype.kind == "f":
        # NaN has no integer value, and values beyond [0, 1] would be clipped silently.
        check_values(image, layout, "image")
        return np.rint(np.clip(image, 0, 1) * depth).astype(dtype)
    return np.rint(image / np.float32(257)).astype(np.uint8)


def tiff_options(channels):
    """How a TIFF of `channels` samples is stored (tifffile's ``write`` keywords), whole or in tiles."""
    return dict(photometric="rgb" if channels >= 3 else "minisblack",
                extrasamples=("unassalpha",) if channels in (2, 4) else None,
                compression="zlib", predictor=True, metadata=None)


def _encode(file, pixels, format_name):
    if format_name == "NPY":
        # Header and data by file.write, not ndarray.tofile (what np.save does), whose short
        # write on a full disk reports no errno.
        np.lib.format.write_array_header_1_0(file, np.lib.format.header_data_from_array_1_0(pixels))
        file.write(memoryview(np.ascontiguousarray(pixels)).cast("B"))
    elif format_name == "PNG":
        write_png(file, pixels)
    elif format_name == "TIFF":
        tifffile = import_codec("tifffile", "TIFF")
        tifffile.imwrite(file, pixels, **tiff_options(1 if pixels.ndim == 2 else pixels.shape[2]))
    else:
        _encode_with_pillow(file, pixels, format_name)


def _encode_with_pillow(file, pixels, format_name):
    from PIL import Image

    image = Image.fromarray(pixels)
    if pixels.ndim == 3 and pixels.shape[2] == 2:
        # WebP has no grey+alpha; RGBA keeps every value.
        image = image.convert("RGBA")
    options = {"JPEG": {"quality": _JPEG_QUALITY, "subsampling": 0},
               "WEBP": {"lossless": True}}.get(format_name, {})
    image.save(file, format=format_name, **options)


def _current_umask():
    try:
        # Linux publishes the umask; reading it there avoids changing process-wide state.
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    # Elsewhere the umask can only be read by setting it; set it straight back.
    umask = os.umask(0o022)
    os.umask(umask)
    return umask


def _default_permissions(destination):
    try:
        return os.stat(destination).st_mode & 0o777
    except OSError:
        return 0o666 & ~_current_umask()


def write_image(path, image, *, overwrite=True):
    """Write an image array to a file, atomically, in the format its extension names.

    The pixels go to a temporary file in the destination's folder, which then replaces the
    destination in one step: an interrupted or failed write leaves the destination as it
    was and no temporary file behind. A replaced file keeps its permission bits; a new one
    gets ``0666`` less the umask, as ``open()`` would give it.

    How each dtype is stored, by its declared bit depth:

    ============  ==========  ================  ==========  ===========================
    image dtype   .png        .tif / .tiff      .npy        .jpg .jpeg .webp .bmp
    ============  ==========  ================  ==========  ===========================
    uint8         8-bit       8-bit             unchanged   8-bit
    uint16        16-bit      16-bit            unchanged   8-bit, ``rint(v / 257)``
    float         16-bit (1)  32-bit float (2)  unchanged   8-bit, ``rint(v * 255)`` (1)
    ============  ==========  ================  ==========  ===========================

    (1) floats must be finite and within [0, 1] (clipped within a hair of it); 16-bit is
    ``rint(v * 65535)``. (2) float64 and float16 are stored as float32, as is float16 in
    ``.npy`` (float32 and float64 stay unchanged there).

    JPEG is written at quality 95 without chroma subsampling; WebP losslessly. JPEG and BMP
    cannot hold alpha (BMP's is ignored by most readers), so grey+alpha and RGBA images are
    refused there. WebP has no grey: grey is stored as RGB and grey+alpha as RGBA.

    Parameters
    ----------
    path : str or os.PathLike
        Ends in .png, .tif, .tiff, .npy, .jpg, .jpeg, .webp or .bmp. Its folder must exist.
    image : ndarray, shape (H, W) or (H, W, C), C in 1..4
        Grey, grey+alpha, RGB or RGBA; uint8, uint16 or float.
    overwrite : bool, optional
        If False, refuse to replace an existing file.

    Raises
    ------
    InputError
        On an unknown extension, a missing folder, an existing file with
        ``overwrite=False``, or an image the format cannot hold.
    OSError
        When the disk refuses the write; the message names the folder and why (full,
        read-only, no permission), not the temporary file.
    """
    write_images({path: image}, overwrite=overwrite)


def write_images(images, *, overwrite=True):
    """Write several images as :func:`write_image` does, all or none of them.

    Every image is first written completely to its temporary file; only then are they
    renamed into place, so that a failure while writing any of them (a full disk, an
    interruption) leaves every destination as it was.

    Parameters
    ----------
    images : dict
        ``{path: image}``.
    overwrite : bool, optional
        If False, refuse to replace existing files.
    """
    checked = []
    for path, image in images.items():
        path = os.fspath(path)
        format_name = check_output_path(path, layout_of(image, "image").shape)
        if not overwrite and os.path.lexists(path):
            raise InputError(f"{path} already exists; choose another name or allow overwriting")
        checked.append((path, image, format_name))
    parts = []
    try:
        for path, image, format_name in checked:
            parts.append(_write_part(path, image, format_name))
        for _, temporary, path in parts:
            _commit(temporary, path, overwrite)
    except BaseException:
        for _, temporary, _ in parts:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(temporary)
        raise
    finally:
        for descriptor, _, _ in parts:
            os.close(descriptor)


def _write_part(path, image, format_name):
    """Encode `image` into a new locked part beside `path`; return ``(descriptor, part, path)``."""
    pixels = _encoded_pixels(image, format_name)
    folder = os.path.dirname(os.path.abspath(path))
    name, extension = os.path.splitext(os.path.basename(path))
    try:
        descriptor, temporary = create_part(folder, name, extension)
    except OSError as error:
        raise disk_error(error, folder, path) from None
    try:
        # Opened by name: tifffile needs a file object whose name is a path.
        with open(temporary, "wb") as file:
            try:
                _encode(file, pixels, format_name)
            except (InputError, OSError):
                raise
            except MemoryError as error:
                reason = str(error) or "out of memory"
                raise NotEnoughMemory(f"not enough memory to encode {path} as {format_name} ({reason}; the "
                                      f"{pixels.dtype} {pixels.shape} image takes {format_bytes(pixels.nbytes)}); "
                                      "close other programs, or write .tif or .npy, which encode with less") from None
            except Exception as error:
                raise InputError(f"could not encode the {pixels.dtype} {pixels.shape} image as "
                                 f"{format_name}: {error}") from error
            file.flush()
            os.fsync(file.fileno())
        os.chmod(temporary, _default_permissions(path))
    except BaseException as error:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temporary)
        os.close(descriptor)
        if isinstance(error, OSError) and not isinstance(error, DiskError):
            raise disk_error(error, folder, path) from None
        raise
    return descriptor, temporary, path


def _commit(temporary, path, overwrite):
    try:
        if overwrite:
            os.replace(temporary, path)
        else:
            _link_without_replacing(temporary, path)
    except OSError as error:
        raise disk_error(error, os.path.dirname(os.path.abspath(path)), path) from None


def _link_without_replacing(temporary, path):
    try:
        # A hard link fails if the name exists, so no concurrent writer's file is replaced.
        os.link(temporary, path)
    except FileExistsError:
        raise InputError(f"{path} already exists; choose another name or allow overwriting") from None
    except OSError:
        # Some filesystems have no hard links; a check then a rename is the best they allow.
        if os.path.lexists(path):
            raise InputError(f"{path} already exists; choose another name or allow overwriting") from None
        os.replace(temporary, path)
        return
    os.unlink(temporary)
