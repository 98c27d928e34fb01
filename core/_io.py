"""Reading and writing image files in their own bit depth.

PNG goes through imagecodecs (Pillow cannot hold 16-bit RGB), TIFF through tifffile,
``.npy`` through NumPy and every other format through Pillow, as 8-bit. The codec packages
are imported inside the functions, so ``import aarecovery`` needs only NumPy and moderngl.
"""

import importlib
import os
import tempfile
import threading

import numpy as np

from ._contract import check_values, layout_of
from ._errors import InputError

__all__ = ["read_image", "write_image", "WRITE_FORMATS", "check_output_path"]

#: Output extensions and the format each one writes.
WRITE_FORMATS = {
    ".png": "PNG", ".tif": "TIFF", ".tiff": "TIFF", ".npy": "NPY",
    ".jpg": "JPEG", ".jpeg": "JPEG", ".webp": "WEBP", ".bmp": "BMP",
}

_READ_FORMATS = ("PNG (8/16-bit), TIFF (8/16-bit, 32-bit float), NumPy .npy (uint8, uint16, float32, "
                 "float64), and as 8-bit JPEG, WebP, BMP, GIF and the other formats Pillow reads")
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_TIFF_SIGNATURES = (b"II*\x00", b"MM\x00*", b"II+\x00", b"MM\x00+")
_NPY_SIGNATURE = b"\x93NUMPY"
_NPY_DTYPES = (np.uint8, np.uint16, np.float32, np.float64)

# Pillow refuses images above about 179 megapixels as possible decompression bombs; a 20000 x
# 20000 scan is legitimate here. The limit below still stops a few-byte file that claims
# 65535 x 65535 from allocating tens of gigabytes.
MAX_PIXELS = 1 << 31
# Pillow's limit is a module global; the lock keeps our own concurrent reads from restoring
# each other's value out of order.
_PILLOW_LIMIT_LOCK = threading.Lock()

_JPEG_QUALITY = 95


_LAYOUT_NAMES = {1: "grey", 2: "grey+alpha", 3: "RGB", 4: "RGBA"}


def _layout_name(shape):
    return _LAYOUT_NAMES[1 if len(shape) == 2 else shape[2]]


def read_image(path):
    """Read an image file's pixels in the file's own bit depth and layout.

    The format is found from the file's first bytes, not its name.

    Parameters
    ----------
    path : str or os.PathLike
        A PNG (8 or 16-bit), TIFF (8 or 16-bit integer, or 32-bit float; the first image of
        a multi-page file), NumPy ``.npy`` file, or anything else Pillow reads (JPEG, WebP,
        BMP, GIF, ...; the first frame), which is read as 8-bit.

    Returns
    -------
    ndarray, shape (H, W), (H, W, 2), (H, W, 3) or (H, W, 4)
        Grey, grey+alpha, RGB or RGBA with straight alpha, row 0 at the top. dtype uint8 or
        uint16 as stored, float32 for float TIFF, and for ``.npy`` the stored uint8, uint16,
        float32 or float64. Palette images become RGB (RGBA where the palette has
        transparency), 1-bit images grey uint8 with values 0 and 255, CMYK RGB, 16-bit grey
        Pillow modes (``I;16``) grey uint16. JPEG EXIF orientation is applied, so row 0 is
        the top as viewers show it.

    Raises
    ------
    InputError
        When the file is missing, a folder, unreadable, truncated or corrupt, empty, or in a
        format, mode or sample type this function does not read; the message says which
        ones it does.
    """
    path = os.fspath(path)
    if not os.path.exists(path):
        raise InputError(f"{path} does not exist; check the file name")
    if os.path.isdir(path):
        raise InputError(f"{path} is a folder, not an image file; give the path of an image inside it")
    try:
        with open(path, "rb") as file:
            head = file.read(16)
    except OSError as error:
        raise InputError(f"cannot read {path}: {error.strerror or error}; check its permissions") from None
    if not head:
        raise InputError(f"{path} is empty (0 bytes); is the file complete?")
    if head.startswith(_PNG_SIGNATURE):
        image = _read_png(path)
    elif head.startswith(_TIFF_SIGNATURES):
        image = _read_tiff(path)
    elif head.startswith(_NPY_SIGNATURE):
        image = _read_npy(path)
    else:
        image = _read_with_pillow(path)
    if image.ndim == 3 and image.shape[2] == 1:
        image = image[..., 0]
    if 0 in image.shape:
        raise InputError(f"{path} holds an empty image of shape {image.shape}; an image needs at least "
                         "one row and one column")
    return np.ascontiguousarray(image)


def _decode_error(path, format_name, error):
    detail = str(error).strip() or type(error).__name__
    return InputError(f"could not decode {path} as {format_name}: {detail}; is the file complete?")


def _import_codec(module, format_name):
    try:
        return importlib.import_module(module)
    except ImportError:
        raise InputError(f"{format_name} files need the {module} package, which is not installed here; "
                         f"install it with 'pip install {module}', or use another format") from None


def _read_png(path):
    imagecodecs = _import_codec("imagecodecs", "PNG")
    with open(path, "rb") as file:
        data = file.read()
    try:
        # libpng expands palette, tRNS and sub-byte grey to 8 bits, so every PNG arrives as
        # one of the four layouts in 8 or 16 bits.
        return imagecodecs.png_decode(data)
    except Exception as error:
        raise _decode_error(path, "PNG", error) from None


def _read_npy(path):
    try:
        array = np.load(path, allow_pickle=False)
    except Exception as error:
        raise _decode_error(path, "a NumPy .npy array", error) from None
    if array.dtype.byteorder not in ("=", "|") and array.dtype.newbyteorder("=") in _NPY_DTYPES:
        array = array.astype(array.dtype.newbyteorder("="))
    if array.dtype not in _NPY_DTYPES:
        raise InputError(f"{path} holds a {array.dtype} array; .npy images must be uint8, uint16, "
                         "float32 or float64 (floats in [0, 1])")
    if array.ndim not in (2, 3) or (array.ndim == 3 and not 1 <= array.shape[2] <= 4):
        raise InputError(f"{path} holds an array of shape {array.shape}; .npy images must be (H, W) grey, "
                         "(H, W, 2) grey+alpha, (H, W, 3) RGB or (H, W, 4) RGBA")
    return array


def _scale_to_dtype_depth(data, bits):
    """Stretch integer samples of `bits` bits (1-bit, 4-bit, 12-bit...) to their dtype's full range."""
    full = np.iinfo(data.dtype).max
    top = (1 << bits) - 1
    if bits >= np.iinfo(data.dtype).bits or top == 0:
        return data
    return np.rint(data.astype(np.float64) * (full / top)).astype(data.dtype)


def _unpremultiply(data):
    colour, alpha = data[..., :-1], data[..., -1:]
    if data.dtype.kind == "f":
        safe = np.where(alpha > 0, alpha, 1)
        return np.concatenate([np.where(alpha > 0, colour / safe, 0), alpha], axis=-1).astype(data.dtype)
    full = float(np.iinfo(data.dtype).max)
    safe = np.where(alpha > 0, alpha, 1).astype(np.float64)
    straight = np.clip(np.rint(colour * (full / safe)), 0, full)
    return np.concatenate([np.where(alpha > 0, straight, 0).astype(data.dtype), alpha], axis=-1)


def _read_tiff(path):
    tifffile = _import_codec("tifffile", "TIFF")
    try:
        with tifffile.TiffFile(path) as tif:
            page = tif.pages.first
            data = page.asarray()
            axes, photometric = page.axes, page.photometric
            extrasamples, colormap = tuple(page.extrasamples or ()), page.colormap
            bits, compression = page.bitspersample, page.compression
    except Exception as error:
        raise _decode_error(path, "TIFF", error) from None

    # Bring the samples last (planar "separate" files store them first) and drop axes of
    # length 1; anything else is a stack or a volume, not one image.
    others = [length for length, axis in zip(data.shape, axes) if axis not in "YXS"]
    if any(length > 1 for length in others):
        raise InputError(f"{path} is a TIFF whose first page has axes {axes!r} and shape {data.shape} "
                         "(a stack or volume); only 2-D images with up to 4 samples per pixel are read: "
                         "save one plane as its own file")
    kept = [axis for axis in axes if axis in "YXS"]
    data = data.reshape([length for length, axis in zip(data.shape, axes) if axis in "YXS"])
    data = np.transpose(data, [kept.index(axis) for axis in "YXS" if axis in kept])
    if data.dtype == bool:
        data = data.astype(np.uint8) * np.uint8(255)
        bits = 8
    names = tifffile.PHOTOMETRIC
    if photometric == names.PALETTE:
        if colormap is None:
            raise _decode_error(path, "TIFF", ValueError("palette image without a colour map"))
        colours = colormap.T[data]
        # TIFF colour maps are 16-bit; 8-bit palettes are stored times 257 or times 256.
        if np.all(colormap % 257 == 0) or np.all(colormap % 256 == 0):
            return (colours >> 8).astype(np.uint8)
        return colours.astype(np.uint16)
    if data.dtype.kind == "f":
        data = data.astype(np.float32, copy=False)
    elif data.dtype in (np.uint8, np.uint16):
        data = _scale_to_dtype_depth(data, bits)
    else:
        raise InputError(f"{path} is a TIFF with {data.dtype} samples; TIFF images must hold 1 to 16-bit "
                         "unsigned integers or 16/32/64-bit floats: convert it, for example to 16-bit")
    if photometric == names.MINISWHITE:
        data = (np.float32(1) - data) if data.dtype.kind == "f" else np.iinfo(data.dtype).max - data
    elif photometric == names.SEPARATED:
        data = _cmyk_to_rgb(data, path)
    elif photometric == names.YCBCR and compression != tifffile.COMPRESSION.JPEG:
        raise InputError(f"{path} is an uncompressed YCbCr TIFF, which is not read; save it as RGB")
    elif photometric not in (names.MINISBLACK, names.RGB, names.YCBCR):
        raise InputError(f"{path} is a TIFF with photometric interpretation {photometric.name}; "
                         "TIFF images must be grey, RGB, palette, CMYK or black-and-white")
    channels = 1 if data.ndim == 2 else data.shape[2]
    if channels > 2 and photometric in (names.MINISBLACK, names.MINISWHITE):
        raise InputError(f"{path} is a grey TIFF with {channels} samples per pixel; grey TIFFs are read with "
                         "1 sample, or 2 with alpha: save the channels as separate files or as RGB")
    if channels > 4:
        raise InputError(f"{path} is a TIFF with {channels} samples per pixel; at most 4 (RGBA) are read: "
                         "drop the extra channels first")
    if channels in (2, 4) and extrasamples and extrasamples[0] == tifffile.EXTRASAMPLE.ASSOCALPHA:
        data = _unpremultiply(data)
    return data


def _cmyk_to_rgb(data, path):
    if data.ndim != 3 or data.shape[2] < 4:
        raise InputError(f"{path} is a CMYK TIFF with shape {data.shape}; 4 ink channels were expected")
    full = np.float32(1) if data.dtype.kind == "f" else np.float32(np.iinfo(data.dtype).max)
    inks = data[..., :4].astype(np.float32) / full
    rgb = (1 - inks[..., :3]) * (1 - inks[..., 3:4]) * full
    return rgb.astype(np.float32) if data.dtype.kind == "f" else np.rint(rgb).astype(data.dtype)


# Pillow modes and what they become: 8-bit layouts as they are, the rest converted.
_PILLOW_CONVERSIONS = {
    "L": None, "LA": None, "RGB": None, "RGBA": None,
    "1": "L", "La": "LA", "RGBa": "RGBA", "RGBX": "RGB", "CMYK": "RGB", "YCbCr": "RGB", "PA": "RGBA",
}


def _read_with_pillow(path):
    from PIL import Image, ImageOps, UnidentifiedImageError

    with _PILLOW_LIMIT_LOCK:
        saved_limit = Image.MAX_IMAGE_PIXELS
        # Checked below against MAX_PIXELS instead, with our own message.
        Image.MAX_IMAGE_PIXELS = None
        try:
            try:
                image = Image.open(path)
            except UnidentifiedImageError:
                raise InputError(f"{path} is not an image format aarecovery reads; supported: "
                                 f"{_READ_FORMATS}") from None
            except Exception as error:
                raise _decode_error(path, "an image", error) from None
            with image:
                return _pillow_pixels(image, path, ImageOps)
        finally:
            Image.MAX_IMAGE_PIXELS = saved_limit


def _pillow_pixels(image, path, ImageOps):
    format_name = image.format or "an image"
    width, height = image.size
    if width * height > MAX_PIXELS:
        raise InputError(f"{path} claims {width}x{height} pixels, more than the {MAX_PIXELS} this reader "
                         "accepts; split the image into parts first")
    try:
        image.load()
        # In place: a copy would double the memory of a large JPEG.
        ImageOps.exif_transpose(image, in_place=True)
        mode = image.mode
        if mode == "P":
            image = image.convert("RGBA" if "transparency" in image.info else "RGB")
        elif mode.startswith("I;16"):
            pixels = np.asarray(image)
            return pixels.astype(pixels.dtype.newbyteorder("="))
        elif mode == "I":
            pixels = np.asarray(image)
            if pixels.min() < 0 or pixels.max() > 65535:
                raise InputError(f"{path} is a 32-bit integer {format_name} with values from {pixels.min()} "
                                 f"to {pixels.max()}; only values 0 to 65535 (16-bit) are read")
            return pixels.astype(np.uint16)
        elif mode == "F":
            return np.array(image, dtype=np.float32)
        elif mode not in _PILLOW_CONVERSIONS:
            raise InputError(f"{path} is a {format_name} in Pillow mode {mode!r}, which is not read; supported "
                             f"modes: {', '.join(_PILLOW_CONVERSIONS)}, I;16, I and F: convert it to RGB first")
        elif _PILLOW_CONVERSIONS[mode] is not None:
            image = image.convert(_PILLOW_CONVERSIONS[mode])
    except InputError:
        raise
    except Exception as error:
        raise _decode_error(path, format_name, error) from None
    return np.array(image)


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
        raise InputError(f"{format_name} cannot store the alpha channel of this {_layout_name(shape)} image; "
                         f"write {os.path.splitext(path)[0]}.png (or .tif) instead, or drop the alpha first")
    return format_name


def _encoded_pixels(image, format_name):
    """Convert `image` to what `format_name` stores, per the table in :func:`write_image`."""
    layout = layout_of(image, "image")
    if layout.channels == 1 and image.ndim == 3 and format_name != "NPY":
        image = image[..., 0]
    if format_name == "NPY":
        # read_image reads back float32 and float64; float16 and longdouble become float32.
        return image if image.dtype in _NPY_DTYPES else image.astype(np.float32)
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


def _encode(file, pixels, format_name):
    if format_name == "NPY":
        np.save(file, pixels, allow_pickle=False)
    elif format_name == "PNG":
        imagecodecs = _import_codec("imagecodecs", "PNG")
        file.write(imagecodecs.png_encode(pixels))
    elif format_name == "TIFF":
        tifffile = _import_codec("tifffile", "TIFF")
        channels = 1 if pixels.ndim == 2 else pixels.shape[2]
        tifffile.imwrite(
            file, pixels, photometric="rgb" if channels >= 3 else "minisblack",
            extrasamples=("unassalpha",) if channels in (2, 4) else None,
            compression="zlib", predictor=True, metadata=None)
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
        When the disk refuses the write (full, read-only, no permission).
    """
    path = os.fspath(path)
    format_name = check_output_path(path, layout_of(image, "image").shape)
    if not overwrite and os.path.lexists(path):
        raise InputError(f"{path} already exists; choose another name or allow overwriting")
    pixels = _encoded_pixels(image, format_name)
    folder = os.path.dirname(os.path.abspath(path))
    name, extension = os.path.splitext(os.path.basename(path))
    descriptor, temporary = tempfile.mkstemp(dir=folder, prefix=f".{name}.", suffix=".part" + extension)
    try:
        os.close(descriptor)
        # Opened by name: tifffile needs a file object whose name is a path.
        with open(temporary, "wb") as file:
            try:
                _encode(file, pixels, format_name)
            except (InputError, OSError):
                raise
            except Exception as error:
                raise InputError(f"could not encode the {pixels.dtype} {pixels.shape} image as "
                                 f"{format_name}: {error}") from error
            file.flush()
            os.fsync(file.fileno())
        os.chmod(temporary, _default_permissions(path))
        if overwrite:
            os.replace(temporary, path)
        else:
            _link_without_replacing(temporary, path)
    except BaseException:
        try:
            os.unlink(temporary)
        except FileNotFoundError:
            pass
        raise


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
