"""Reading image files in their own bit depth and layout.

PNG goes through imagecodecs (Pillow cannot hold 16-bit RGB), TIFF through tifffile,
``.npy`` through NumPy and every other format through Pillow, as 8-bit. The codec packages
are imported inside the functions, so ``import aarecovery`` needs only NumPy and moderngl.
"""

import os
import threading
import warnings

import numpy as np

from ..errors import InputError, NotEnoughMemory, OrientationWarning
from .formats import NPY_DTYPES, READ_FORMATS, import_codec
from .limits import DECLARED_ONLY, Declared, check_decoded_size
from .orientation import ORIENTATION_NAMES, apply_orientation, png_header, tiff_orientation

__all__ = ["read_image", "declared_image", "orientation_tag", "describe_orientations", "warn_if_orientations_differ"]

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_TIFF_SIGNATURES = (b"II*\x00", b"MM\x00*", b"II+\x00", b"MM\x00+")
_NPY_SIGNATURE = b"\x93NUMPY"

# Pillow refuses images above about 179 megapixels as possible decompression bombs; a 20000 x
# 20000 scan is legitimate here. Its check is switched off and ours (check_decoded_size, by
# the bytes decoded) runs instead, with the same message as for every other format. Pillow's
# limit is a module global; the lock keeps our own concurrent reads from restoring each
# other's value out of order.
_PILLOW_LIMIT_LOCK = threading.Lock()


def read_image(path, *, max_bytes=None):
    """Read an image file's pixels in the file's own bit depth and layout.

    The format is found from the file's first bytes, not its name.

    Parameters
    ----------
    path : str or os.PathLike
        A PNG (8 or 16-bit), TIFF (8 or 16-bit integer, or 32-bit float; the first image of
        a multi-page file), NumPy ``.npy`` file, or anything else Pillow reads (JPEG, WebP,
        BMP, GIF, ...; the first frame), which is read as 8-bit.
    max_bytes : int or float, optional
        The most memory the decoded image may take, checked against the size the file
        declares before anything is decoded. By default 4 GB, or the environment variable
        ``AARECOVERY_MAX_IMAGE_MEMORY`` in GB (see ``aarecovery.io.limits`` for why).

    Returns
    -------
    ndarray, shape (H, W), (H, W, 2), (H, W, 3) or (H, W, 4)
        Grey, grey+alpha, RGB or RGBA with straight alpha, row 0 at the top. dtype uint8 or
        uint16 as stored, float32 for float TIFF, and for ``.npy`` the stored uint8, uint16,
        float32 or float64. Palette images become RGB (RGBA where the palette has
        transparency), 1-bit images grey uint8 with values 0 and 255, CMYK RGB, 16-bit grey
        Pillow modes (``I;16``) grey uint16. The orientation a file declares (EXIF in JPEG,
        WebP and PNG's ``eXIf`` chunk, the TIFF Orientation tag) is applied, so row 0 is the
        top as viewers show it, in every format alike.

    Raises
    ------
    InputError
        When the file is missing, a folder, unreadable, truncated or corrupt, empty, in a
        format, mode or sample type this function does not read (the message says which
        ones it does), or larger once decoded than `max_bytes`.
    """
    path, head = _opened(path)
    if head.startswith(_PNG_SIGNATURE):
        image = _read_png(path, max_bytes)
    elif head.startswith(_TIFF_SIGNATURES):
        image = _read_tiff(path, max_bytes)
    elif head.startswith(_NPY_SIGNATURE):
        image = _read_npy(path, max_bytes)
    else:
        image = _read_with_pillow(path, max_bytes)
    if image.ndim == 3 and image.shape[2] == 1:
        image = image[..., 0]
    if 0 in image.shape:
        raise InputError(f"{path} holds an empty image of shape {image.shape}; an image needs at least "
                         "one row and one column")
    return np.ascontiguousarray(image)


def orientation_tag(path):
    """The orientation `path` declares (EXIF / TIFF, 1 to 8; 1 when none), from its header only.

    For messages: :func:`read_image` has already applied it.
    """
    path, head = _opened(path)
    try:
        if head.startswith(_PNG_SIGNATURE):
            return png_header(path).orientation
        if head.startswith(_TIFF_SIGNATURES):
            tifffile = import_codec("tifffile", "TIFF")
            with tifffile.TiffFile(path) as tif:
                return tiff_orientation(tif.pages.first)
        if head.startswith(_NPY_SIGNATURE):
            return 1
        from PIL import Image
        with Image.open(path) as image:
            return int(image.getexif().get(0x0112, 1))
    except (InputError, OSError, ValueError, TypeError):
        return 1


def declared_image(path):
    """The shape and dtype :func:`read_image` would decode `path` to, from its header alone.

    Returns
    -------
    shape : tuple of int
    dtype : numpy.dtype

    Raises
    ------
    InputError
        As :func:`read_image` does for a file it cannot read.
    """
    try:
        # Each reader reports its header's figures to check_decoded_size before decoding.
        image = read_image(path, max_bytes=DECLARED_ONLY)
    except Declared as declared:
        return declared.shape, declared.dtype
    return image.shape, image.dtype  # a reader that checks no size (an .npy of another rank)


def describe_orientations(paths):
    """How the files `paths` (ORIGINAL, FILTERED) declare different orientations, or None when
    they declare the same (for messages: a reader has applied each)."""
    tags = [orientation_tag(path) for path in paths]
    if tags[0] == tags[1]:
        return None
    return " but ".join(f"{role} is tagged orientation {tag} ({ORIENTATION_NAMES.get(tag, 'unknown')} for display)"
                        for role, tag in zip(("ORIGINAL", "FILTERED"), tags))


def warn_if_orientations_differ(original, filtered, name=None):
    """Warn (:class:`OrientationWarning`, one line) when two files declare different orientations.

    Called once the pair's sizes match: a square pair then reads the same size however it is
    turned, and a program that dropped the tag without turning the pixels leaves F misaligned.
    """
    described = describe_orientations((original, filtered))
    if described is not None:
        warnings.warn(f"{name + ': ' if name else ''}the files' orientation tags differ: {described}; each is "
                      "turned upright as tagged, so if a program dropped or changed a tag without turning the "
                      "pixels the pair is misaligned and the repair is wrong: check that both look the same "
                      "way up", OrientationWarning, stacklevel=2)


def _opened(path):
    """``(path, its first 16 bytes)``, or an InputError saying why the file cannot be read."""
    if not isinstance(path, (str, bytes, os.PathLike)):
        raise InputError(f"an image path must be a str or os.PathLike, got {type(path).__name__}; "
                         "pass the file's name")
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
    return path, head


def _decode_error(path, format_name, error):
    if isinstance(error, MemoryError):
        # Not the file's fault: its declared size passed the limit, but this process has less.
        return NotEnoughMemory(f"not enough memory to decode {path} as {format_name} ({str(error) or 'out of memory'}); "
                               "close other programs, or use a machine with more memory")
    if isinstance(error, ImportError):
        # imagecodecs loads each codec on first use and reports any failure to load it, most
        # often a process out of memory (mapping the library failed), as a missing name.
        return NotEnoughMemory(f"could not load the {format_name} decoder to read {path} ({error}): this process "
                               "is most likely out of memory; close other programs or raise its memory limit, "
                               "and if memory is plentiful reinstall imagecodecs (pip install --force-reinstall "
                               "imagecodecs)")
    detail = str(error).strip() or type(error).__name__
    return InputError(f"could not decode {path} as {format_name}: {detail}; is the file complete?")


def _read_png(path, max_bytes):
    header = png_header(path)
    check_decoded_size(path, header.shape, header.dtype, max_bytes)
    imagecodecs = import_codec("imagecodecs", "PNG")
    try:
        with open(path, "rb") as file:
            data = file.read()
        # libpng expands palette, tRNS and sub-byte grey to 8 bits, so every PNG arrives as
        # one of the four layouts in 8 or 16 bits.
        image = imagecodecs.png_decode(data)
    except Exception as error:
        raise _decode_error(path, "PNG", error) from None
    return apply_orientation(image, header.orientation)


#: The longest ``.npy`` header read: NumPy's own limit. An image's header is about 128 bytes;
#: a longer one is not an image (and NumPy's refusal is a paragraph).
_NPY_HEADER_LIMIT = 10000


def _npy_header(path):
    """``(shape, dtype)`` from a ``.npy`` header, or an InputError saying why it is not an image."""
    try:
        with open(path, "rb") as file:
            version = np.lib.format.read_magic(file)
            length_bytes = 2 if version == (1, 0) else 4
            length = int.from_bytes(file.read(length_bytes), "little")
            if length > _NPY_HEADER_LIMIT:
                raise InputError(f"{path} has a .npy header of {length} bytes, where an image's takes about 128; "
                                 "it is not an image array: save one with numpy.save(path, image)")
            file.seek(0)
            np.lib.format.read_magic(file)
            shape, _, dtype = (np.lib.format.read_array_header_1_0 if version == (1, 0)
                               else np.lib.format.read_array_header_2_0)(file)
    except InputError:
        raise
    except Exception as error:
        raise _decode_error(path, "a NumPy .npy array", error) from None
    return shape, dtype


def _read_npy(path, max_bytes):
    shape, dtype = _npy_header(path)
    # Refused from the header, before anything is allocated or unpickled.
    if dtype.hasobject:
        raise InputError(f"{path} holds Python objects (a pickled array), which are not read for safety; "
                         ".npy images must hold uint8, uint16, float32 or float64 numbers")
    if dtype.newbyteorder("=") not in NPY_DTYPES:
        raise InputError(f"{path} holds a {dtype} array; .npy images must be uint8, uint16, "
                         "float32 or float64 (floats in [0, 1])")
    if len(shape) not in (2, 3) or (len(shape) == 3 and not 1 <= shape[2] <= 4):
        raise InputError(f"{path} holds an array of shape {shape}; .npy images must be (H, W) grey, "
                         "(H, W, 2) grey+alpha, (H, W, 3) RGB or (H, W, 4) RGBA")
    check_decoded_size(path, shape, dtype, max_bytes)
    try:
        array = np.load(path, allow_pickle=False)
    except Exception as error:
        raise _decode_error(path, "a NumPy .npy array", error) from None
    # Big-endian arrays (saved on another machine) are read in this machine's order.
    return array.astype(array.dtype.newbyteorder("="), copy=False)


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


def _read_tiff(path, max_bytes):
    tifffile = import_codec("tifffile", "TIFF")
    try:
        with tifffile.TiffFile(path) as tif:
            page = tif.pages.first
            # Palette indices become RGB colours (of the colour map's depth, at most 16-bit).
            shape = page.shape + ((3,) if page.photometric == tifffile.PHOTOMETRIC.PALETTE else ())
            check_decoded_size(path, shape, np.uint16 if page.colormap is not None else page.dtype, max_bytes)
            orientation = tiff_orientation(page)
            data = page.asarray()
            layout = dict(axes=page.axes, photometric=page.photometric, extrasamples=tuple(page.extrasamples or ()),
                          colormap=page.colormap, bits=page.bitspersample, compression=page.compression)
    except InputError:
        raise
    except Exception as error:
        raise _decode_error(path, "TIFF", error) from None
    return apply_orientation(_tiff_pixels(path, data, tifffile, **layout), orientation)


def _tiff_pixels(path, data, tifffile, axes, photometric, extrasamples, colormap, bits, compression):
    """A TIFF page's samples as one of the four layouts, in 8/16-bit or float32."""
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


def _read_with_pillow(path, max_bytes):
    from PIL import Image, ImageOps, UnidentifiedImageError

    with _PILLOW_LIMIT_LOCK:
        saved_limit = Image.MAX_IMAGE_PIXELS
        # Checked in _pillow_pixels by check_decoded_size instead.
        Image.MAX_IMAGE_PIXELS = None
        try:
            try:
                image = Image.open(path)
            except UnidentifiedImageError:
                raise InputError(f"{path} is not an image format aarecovery reads; supported: "
                                 f"{READ_FORMATS}") from None
            except Exception as error:
                raise _decode_error(path, "an image", error) from None
            with image:
                return _pillow_pixels(image, path, ImageOps, max_bytes)
        finally:
            Image.MAX_IMAGE_PIXELS = saved_limit


def _pillow_decoded(image):
    """The shape and dtype :func:`_pillow_pixels` returns for `image`, from its header."""
    from PIL import ImageMode

    width, height = image.size
    mode = image.mode
    if mode.startswith("I;16") or mode == "I":
        return (height, width), np.uint16
    if mode == "F":
        return (height, width), np.float32
    if mode == "P":
        converted = "RGBA" if "transparency" in image.info else "RGB"
    else:
        converted = _PILLOW_CONVERSIONS.get(mode) or mode
    return (height, width, len(ImageMode.getmode(converted).bands)), np.uint8


def _pillow_pixels(image, path, ImageOps, max_bytes):
    format_name = image.format or "an image"
    try:
        shape, dtype = _pillow_decoded(image)
    except (KeyError, ValueError):  # a mode Pillow itself does not describe: refused below
        shape, dtype = (image.size[1], image.size[0], 4), np.uint8
    check_decoded_size(path, shape, dtype, max_bytes)
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
