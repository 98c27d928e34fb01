"""The core's one image contract, and the conversions at its edges.

Inside the core every image is float32 ``(H, W, 4)``: straight (not premultiplied) alpha,
row 0 at the top, values in [0, 1], colour sRGB-encoded unless the caller declared it linear.
Grey and grey+alpha images are expanded to RGB(A) on the way in and folded back on the way out;
integer images are converted by their declared bit depth (the dtype), and only here.
"""

from dataclasses import dataclass

import numpy as np

from .errors import InputError

__all__ = ["Layout", "native_byte_order", "layout_of", "check_values", "to_rgba_float", "from_rgba_float", "check_same_size"]

_SHAPES = "(H, W) grey, (H, W, 1) grey, (H, W, 2) grey+alpha, (H, W, 3) RGB or (H, W, 4) RGBA"
_DTYPES = "uint8, uint16 or a float dtype with values in [0, 1]"
# Float inputs a hair outside [0, 1] (resampling overshoot, 16F rounding) are clipped;
# anything further out is display-unreferred data the caller must map first.
_FLOAT_SLACK = 1e-3


@dataclass(frozen=True)
class Layout:
    """How a caller's array is laid out, so the result can be given back the same way.

    Attributes
    ----------
    shape : tuple of int
        The array's shape.
    dtype : numpy.dtype
        The array's dtype.
    grey : bool
        True for one colour channel.
    alpha : bool
        True when the last channel is alpha.
    """

    shape: tuple
    dtype: np.dtype
    grey: bool
    alpha: bool

    @property
    def height(self):
        return self.shape[0]

    @property
    def width(self):
        return self.shape[1]

    @property
    def channels(self):
        return 1 if len(self.shape) == 2 else self.shape[2]


def native_byte_order(image):
    """`image` with its samples in this machine's byte order (a big-endian ``>u2`` array, as
    FITS and some TIFF readers give, copied to ``uint16``); anything else unchanged."""
    if isinstance(image, np.ndarray) and not image.dtype.isnative:
        return image.astype(image.dtype.newbyteorder("="))
    return image


def layout_of(image, name):
    """Check an image array's shape and dtype and describe its layout.

    Parameters
    ----------
    image : ndarray
        ``(H, W)`` or ``(H, W, C)`` with C in 1..4; uint8, uint16 or float.
    name : str
        What to call the image in error messages (``"original"``, ``"filtered"``).

    Returns
    -------
    Layout

    Raises
    ------
    InputError
        On a shape, dtype or size the core cannot use, saying which ones it can.
    """
    if not isinstance(image, np.ndarray):
        raise InputError(f"{name} is a {type(image).__name__}, not a NumPy array; "
                         f"pass numpy.asarray(image) with shape {_SHAPES}")
    if image.ndim not in (2, 3) or (image.ndim == 3 and not 1 <= image.shape[2] <= 4):
        raise InputError(f"{name} has shape {image.shape}; an image must be {_SHAPES}")
    if image.shape[0] == 0 or image.shape[1] == 0:
        raise InputError(f"{name} has shape {image.shape}: the image is empty (zero size)")
    if image.dtype not in (np.uint8, np.uint16) and image.dtype.kind != "f":
        raise InputError(f"{name} has dtype {image.dtype}; use {_DTYPES}")
    channels = 1 if image.ndim == 2 else image.shape[2]
    return Layout(tuple(image.shape), image.dtype, grey=channels <= 2, alpha=channels in (2, 4))


def check_same_size(original, filtered):
    """Raise unless two layouts have the same width and height."""
    if original.shape[:2] != filtered.shape[:2]:
        raise InputError(
            f"original is {original.width}x{original.height} but filtered is "
            f"{filtered.width}x{filtered.height} (width x height); recovery needs the two images "
            "pixel for pixel, so crop or resize one of them to the other's size first")


def check_values(image, layout, name):
    """Raise on NaN, infinite or out-of-range values of a float image (integers always fit)."""
    if layout.dtype.kind == "f":
        _check_finite_and_range(image, name)


def _check_finite_and_range(values, name):
    finite = np.isfinite(values)
    if not finite.all():
        bad = np.argwhere(~finite)
        row, col = int(bad[0][0]), int(bad[0][1])
        raise InputError(
            f"{name} holds {len(bad)} NaN or infinite values (the first at row {row}, column {col}); "
            "replace them, for example with numpy.nan_to_num, before recovery")
    low, high = float(values.min()), float(values.max())
    if low < -_FLOAT_SLACK or high > 1 + _FLOAT_SLACK:
        raise InputError(
            f"{name} has float values from {low:g} to {high:g}, outside [0, 1]; float images must "
            "be display-referred: scale, clip or tone-map them into [0, 1] first")


def to_rgba_float(image, layout, name, out=None):
    """Convert a checked image to the core contract: float32 ``(H, W, 4)`` straight RGBA.

    Parameters
    ----------
    image : ndarray
        An array described by `layout`.
    layout : Layout
        From :func:`layout_of`.
    name : str
        What to call the image in error messages.
    out : ndarray of float32, shape (H, W, 4), optional
        Where to write the result (avoids an allocation for large images).

    Returns
    -------
    ndarray of float32, shape (H, W, 4)
        Integer images divided by 255 or 65535; floats checked for NaN, infinities and range.
    """
    height, width = layout.height, layout.width
    if out is None:
        out = np.empty((height, width, 4), np.float32)
    pixels = image.reshape(height, width, layout.channels)
    if layout.dtype == np.uint8:
        scale = np.float32(1 / 255)
    elif layout.dtype == np.uint16:
        scale = np.float32(1 / 65535)
    else:
        scale = None
        _check_finite_and_range(pixels, name)
    colour = pixels[..., :1] if layout.grey else pixels[..., :3]
    alpha = pixels[..., -1] if layout.alpha else None
    out[..., :3] = colour
    if alpha is None:
        out[..., 3] = 1
    else:
        out[..., 3] = alpha
    if scale is not None:
        out *= scale
        if alpha is None:
            out[..., 3] = 1
    else:
        np.clip(out, 0, 1, out=out)
    return out


def from_rgba_float(rgba, layout, out=None):
    """Give a core image back in a caller's layout and dtype.

    Parameters
    ----------
    rgba : ndarray, shape (H, W, 4) or (H, W, C)
        Straight RGBA: float32 in [0, 1], or already in ``layout.dtype`` (a GL readback of a
        normalised texture), in which case only the channels are folded; or already in the
        layout's C channels and dtype (a GL readback of a texture in F's own format).
    layout : Layout
        The layout to return (normally the filtered image's).
    out : ndarray, optional
        Where to write the result instead (a tile's part of the whole result): the shape
        ``layout`` describes for `rgba`'s height and width, ``layout.dtype``.

    Returns
    -------
    ndarray
        Shape ``layout.shape`` and dtype ``layout.dtype`` (or `out`). Grey results take the
        first colour channel: recovery blends grey inputs into equal channels, so nothing is
        lost.
    """
    if rgba.shape[-1] == layout.channels:
        picked = rgba
    elif layout.grey:
        picked = rgba[..., [0, 3]] if layout.alpha else rgba[..., 0]
    else:
        picked = rgba[..., :3]
    result = picked.reshape(layout.shape if out is None else out.shape)
    if result.dtype != layout.dtype:
        if layout.dtype == np.uint8:
            result = np.rint(np.clip(result, 0, 1) * 255).astype(np.uint8)
        elif layout.dtype == np.uint16:
            result = np.rint(np.clip(result, 0, 1) * 65535).astype(np.uint16)
        else:
            result = np.clip(result, 0, 1).astype(layout.dtype)
    elif out is None:
        # Always a copy: a backend may hand over its reusable readback buffer.
        return np.array(result, order="C", copy=True)
    if out is None:
        return result
    out[...] = result
    return out
