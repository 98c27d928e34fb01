"""The point-wise filters: each output pixel is a function of the same input pixel alone.

All take and return the core contract (float32 ``(H, W, 3)`` or ``(H, W, 4)``, sRGB-encoded,
straight alpha); alpha passes through.
"""

import numpy as np

from ..colour import LUMA, linear_to_srgb, luma, srgb_to_linear
from ..errors import InputError
from .base import check_contract, check_positive, with_colour

__all__ = ["threshold", "levels", "tone_map", "posterize", "equalization_transfer", "equalize_histogram",
           "DEFAULT_RAMP", "gradient_map", "replace_colour", "colour_to_grey"]


def threshold(image, level=0.5, dark=(0.0, 0.0, 0.0), light=(1.0, 1.0, 1.0)):
    """Intensity threshold: pixels whose luma is at or above `level` become `light`, others `dark`.

    Parameters
    ----------
    image : ndarray of float32, shape (H, W, 3) or (H, W, 4)
        sRGB-encoded, straight alpha.
    level : float
        Luma threshold in [0, 1] (luma of the encoded values, Rec. 709 weights).
    dark, light : sequence of 3 floats
        sRGB-encoded output colours.

    Returns
    -------
    ndarray of float32, same shape as `image`
    """
    colour = check_contract(image)
    above = (luma(colour) >= level)[..., None]
    return with_colour(image, np.where(above, np.float32(light), np.float32(dark)))


def levels(image, black=0.0, white=1.0, gamma=2.0):
    """Levels and gamma: stretch ``[black, white]`` to [0, 1], then raise to ``1 / gamma``.

    ``gamma > 1`` brightens mid-tones as in an editor's Levels dialog.

    Parameters
    ----------
    image : ndarray of float32, shape (H, W, 3) or (H, W, 4)
    black, white : float
        Input values that map to 0 and 1; ``0 <= black < white <= 1``.
    gamma : float
        Mid-tone exponent, > 0.

    Returns
    -------
    ndarray of float32, same shape as `image`
    """
    colour = check_contract(image)
    if not 0 <= black < white <= 1:
        raise InputError(f"levels needs 0 <= black < white <= 1, got black={black!r}, white={white!r}")
    check_positive("gamma", gamma)
    stretched = np.clip((colour - np.float32(black)) / np.float32(white - black), 0, 1)
    return with_colour(image, np.power(stretched, np.float32(1 / gamma)))


def tone_map(image, exposure=4.0, white=2.0):
    """Global tone mapping (extended Reinhard) of the luminance, in linear light.

    The colour is decoded to linear light, multiplied by `exposure`, and its luminance L is
    compressed to ``L (1 + L / white^2) / (1 + L)``; colour is scaled with its luminance.

    Parameters
    ----------
    image : ndarray of float32, shape (H, W, 3) or (H, W, 4)
    exposure : float
        Linear gain before compression, > 0.
    white : float
        Smallest exposed luminance that maps to white, > 0.

    Returns
    -------
    ndarray of float32, same shape as `image`
    """
    colour = check_contract(image)
    check_positive("exposure", exposure)
    check_positive("white", white)
    linear = srgb_to_linear(colour) * np.float32(exposure)
    lum = luma(linear)
    mapped = lum * (1 + lum / np.float32(white * white)) / (1 + lum)
    ratio = np.where(lum > 1e-8, mapped / np.maximum(lum, 1e-8), 0)[..., None]
    return with_colour(image, linear_to_srgb(np.clip(linear * ratio, 0, 1)))


def posterize(image, steps=4):
    """Posterize: round every channel to one of `steps` equally spaced levels.

    Parameters
    ----------
    image : ndarray of float32, shape (H, W, 3) or (H, W, 4)
    steps : int
        Levels per channel, 2 to 256.

    Returns
    -------
    ndarray of float32, same shape as `image`
    """
    colour = check_contract(image)
    if int(steps) != steps or not 2 <= steps <= 256:
        raise InputError(f"posterize steps must be a whole number from 2 to 256, got {steps!r}")
    top = np.float32(steps - 1)
    return with_colour(image, np.floor(colour * top + np.float32(0.5)) / top)


def equalization_transfer(image, bins=256):
    """The histogram-equalization curve of an image's luma, to apply to this or another image.

    Parameters
    ----------
    image : ndarray of float32, shape (H, W, 3) or (H, W, 4)
        The image whose histogram is flattened (transparent pixels are not counted).
    bins : int
        Histogram bins, >= 2.

    Returns
    -------
    ndarray of float32, shape (bins + 1,)
        The curve's values at luma ``0, 1/bins, ..., 1`` (a cumulative histogram scaled to
        [0, 1]); :func:`equalize_histogram` interpolates it linearly.
    """
    colour = check_contract(image)
    if int(bins) != bins or bins < 2:
        raise InputError(f"bins must be a whole number >= 2, got {bins!r}")
    key = luma(colour)
    weight = image[..., 3] if image.shape[2] == 4 else None
    counts, _ = np.histogram(key, bins=int(bins), range=(0, 1), weights=weight)
    cumulative = np.concatenate([[0], np.cumsum(counts)]).astype(np.float64)
    if cumulative[-1] <= 0:
        return np.linspace(0, 1, int(bins) + 1, dtype=np.float32)
    return (cumulative / cumulative[-1]).astype(np.float32)


def equalize_histogram(image, transfer=None):
    """Histogram equalization of luma, colour scaled with it.

    Parameters
    ----------
    image : ndarray of float32, shape (H, W, 3) or (H, W, 4)
    transfer : ndarray of float32, shape (N + 1,), optional
        A curve from :func:`equalization_transfer`; by default `image`'s own. Passing the
        curve of another image applies *that* mapping, as ground truth does when it filters
        the high-resolution scene with the mapping computed on the original.

    Returns
    -------
    ndarray of float32, same shape as `image`
        Each pixel's colour is multiplied by ``curve(luma) / luma``, which maps luma through
        the curve and keeps hue; grey pixels get ``curve(luma)`` exactly.
    """
    colour = check_contract(image)
    if transfer is None:
        transfer = equalization_transfer(image)
    transfer = np.asarray(transfer, np.float32)
    if transfer.ndim != 1 or transfer.size < 3:
        raise InputError(f"transfer must be a 1-D curve of at least 3 values, got shape {transfer.shape}")
    key = luma(colour)
    mapped = np.interp(key, np.linspace(0, 1, transfer.size), transfer).astype(np.float32)
    ratio = np.where(key > 1e-6, mapped / np.maximum(key, 1e-6), 0)[..., None]
    # Black has no hue to keep; it goes to the curve's grey.
    out = np.where(key[..., None] > 1e-6, colour * ratio, mapped[..., None])
    return with_colour(image, out)


#: Default colour ramp of :func:`gradient_map`: deep blue, magenta-red, warm yellow.
DEFAULT_RAMP = ((0.05, 0.05, 0.35), (0.85, 0.15, 0.35), (1.0, 0.95, 0.55))


def gradient_map(image, colours=DEFAULT_RAMP):
    """Gradient map: luma selects a colour on a ramp (piecewise linear in sRGB values).

    Parameters
    ----------
    image : ndarray of float32, shape (H, W, 3) or (H, W, 4)
    colours : sequence of N >= 2 RGB triples
        sRGB-encoded colours at luma ``0, 1/(N-1), ..., 1``.

    Returns
    -------
    ndarray of float32, same shape as `image`
    """
    colour = check_contract(image)
    ramp = np.asarray(colours, np.float32)
    if ramp.ndim != 2 or ramp.shape[1] != 3 or len(ramp) < 2:
        raise InputError(f"colours must be two or more RGB triples, got shape {ramp.shape}")
    stops = np.linspace(0, 1, len(ramp))
    key = luma(colour)
    out = np.stack([np.interp(key, stops, ramp[:, c]) for c in range(3)], axis=-1)
    return with_colour(image, out)


def _rgb_to_hsv(colour):
    maximum = colour.max(axis=-1)
    minimum = colour.min(axis=-1)
    chroma = maximum - minimum
    safe = np.where(chroma > 0, chroma, 1)
    r, g, b = colour[..., 0], colour[..., 1], colour[..., 2]
    hue = np.where(maximum == r, ((g - b) / safe) % 6,
                   np.where(maximum == g, (b - r) / safe + 2, (r - g) / safe + 4)) * 60
    hue = np.where(chroma > 0, hue, 0)
    saturation = np.where(maximum > 0, chroma / np.where(maximum > 0, maximum, 1), 0)
    return hue, saturation, maximum


def _hsv_to_rgb(hue, saturation, value):
    sector = (hue / 60) % 6
    channel = lambda n: value - value * saturation * np.clip(np.minimum((n + sector) % 6, 4 - (n + sector) % 6), 0, 1)
    return np.stack([channel(5), channel(3), channel(1)], axis=-1)


def replace_colour(image, hue=0.0, width=40.0, new_hue=220.0, min_saturation=0.25):
    """Colour replacement: pixels whose hue lies in a range get a new hue.

    A pixel is selected when its HSV hue (of the encoded values) is within ``width / 2``
    degrees of `hue` and its saturation is at least `min_saturation`; selected pixels keep
    saturation and value and take `new_hue`. The selection is hard, as with an editor's
    "select by colour" followed by a hue change, which is what leaves mixed edge pixels behind.

    Parameters
    ----------
    image : ndarray of float32, shape (H, W, 3) or (H, W, 4)
    hue : float
        Centre of the hue range, degrees.
    width : float
        Width of the hue range, degrees, in (0, 360].
    new_hue : float
        Hue the selected pixels take, degrees.
    min_saturation : float
        Least saturation a selected pixel has, in [0, 1].

    Returns
    -------
    ndarray of float32, same shape as `image`
    """
    colour = check_contract(image)
    if not 0 < width <= 360:
        raise InputError(f"width must be in (0, 360] degrees, got {width!r}")
    h, s, v = _rgb_to_hsv(colour)
    distance = np.abs((h - hue + 180) % 360 - 180)
    selected = (distance <= width / 2) & (s >= min_saturation)
    swapped = _hsv_to_rgb(np.full_like(h, new_hue % 360), s, v)
    return with_colour(image, np.where(selected[..., None], swapped, colour))


_D65 = np.array([0.95047, 1.0, 1.08883], np.float32)
_RGB_TO_XYZ = np.array([[0.4124, 0.3576, 0.1805], LUMA, [0.0193, 0.1192, 0.9505]],
                       np.float32)


def _lab_f(t):
    return np.where(t > (6 / 29) ** 3, np.cbrt(t), t / (3 * (6 / 29) ** 2) + 4 / 29)


def colour_to_grey(image, chroma_weight=0.6, bright_hue=30.0):
    """Nonlinear colour to grey: CIELAB lightness raised by a hue-weighted share of chroma.

    ``L' = L* + chroma_weight * C* * (1 + cos(h - bright_hue)) / 2``, clipped to [0, 100] and
    turned back into an sRGB grey. Saturated colours of the `bright_hue` family come out
    lighter than their luminance, so iso-luminant colour edges stay visible (the aim of
    colour-to-grey methods such as Kim et al. 2009), at the cost of a nonlinear response at
    edges between colours.

    Parameters
    ----------
    image : ndarray of float32, shape (H, W, 3) or (H, W, 4)
    chroma_weight : float
        Share of CIELAB chroma added to lightness, >= 0.
    bright_hue : float
        CIELAB hue angle (degrees) that is lightened most.

    Returns
    -------
    ndarray of float32, same shape as `image`, with three equal colour channels.
    """
    colour = check_contract(image)
    if not np.isfinite(chroma_weight) or chroma_weight < 0:
        raise InputError(f"chroma_weight must be a number >= 0, got {chroma_weight!r}")
    xyz = srgb_to_linear(colour) @ _RGB_TO_XYZ.T
    fx, fy, fz = (_lab_f(xyz[..., c] / _D65[c]) for c in range(3))
    lightness = 116 * fy - 16
    a, b = 500 * (fx - fy), 200 * (fy - fz)
    chroma = np.hypot(a, b)
    hue = np.arctan2(b, a)
    boost = chroma_weight * chroma * (1 + np.cos(hue - np.deg2rad(bright_hue))) / 2
    grey_l = np.clip(lightness + boost, 0, 100)
    fy = (grey_l + 16) / 116
    y = np.where(fy > 6 / 29, fy ** 3, 3 * (6 / 29) ** 2 * (fy - 4 / 29))
    grey = linear_to_srgb(y.astype(np.float32))
    return with_colour(image, np.repeat(grey[..., None], 3, axis=-1))
