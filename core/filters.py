"""The nonlinear filters the paper names, as pure functions on the core's image contract.

Every filter takes and returns float32 ``(H, W, 3)`` RGB or ``(H, W, 4)`` straight RGBA
with sRGB-encoded colour in [0, 1] (the core contract, see :mod:`aarecovery`); alpha passes
through unchanged and only colour is filtered. Use :func:`apply` to run a filter by name
on any layout the core accepts (grey, uint8, uint16...): it converts in and back out.

The filters exist to damage antialiased edges in the ways users do, so that recovery can
be measured against supersampled ground truth; they are ordinary, documented versions of
the operations in Yang et al. (2011), section 4, not replicas of one editor's.

Point-wise filters (each output pixel a function of the same input pixel): `threshold`,
`levels` (gamma/levels), `tone_map`, `posterize`, `equalize_histogram`, `gradient_map`,
`replace_colour`, `colour_to_grey`. Neighbourhood filters: `unsharp_mask`, `bilateral`
(iterated), and `gaussian_blur`, the paper's own failure case (section 6), kept on purpose.

Neighbourhood filters take their radii in pixels; :func:`apply` multiplies every spatial
parameter by `scale`, which is how the ground truth runs "the same" filter on a scene
rendered at ``scale`` times the resolution.
"""

from dataclasses import dataclass, field

import numpy as np

from ._colour import linear_to_srgb, srgb_to_linear
from ._contract import from_rgba_float, layout_of, to_rgba_float
from ._errors import InputError

__all__ = [
    "threshold", "levels", "tone_map", "posterize", "equalization_transfer", "equalize_histogram",
    "gradient_map", "replace_colour", "colour_to_grey", "unsharp_mask", "bilateral", "gaussian_blur",
    "Filter", "Parameter", "FILTERS", "get_filter", "apply",
]

# Rec. 709 / sRGB luminance weights: the luma every point-wise filter keys on.
_LUMA = np.array([0.2126, 0.7152, 0.0722], np.float32)


def _check(image, name="image"):
    if not isinstance(image, np.ndarray) or image.ndim != 3 or image.shape[2] not in (3, 4):
        shape = getattr(image, "shape", type(image).__name__)
        raise InputError(f"{name} has shape {shape}; filters take the core contract, float32 (H, W, 3) "
                         "or (H, W, 4) in [0, 1]: use aarecovery.filters.apply(name, image) for other layouts")
    if image.dtype != np.float32:
        raise InputError(f"{name} has dtype {image.dtype}; filters take float32 in [0, 1]: use "
                         "aarecovery.filters.apply(name, image), which converts uint8/uint16/grey images")
    return image[..., :3]


def _with_colour(image, colour):
    colour = np.clip(colour, 0, 1).astype(np.float32, copy=False)
    if image.shape[2] == 4:
        return np.concatenate([colour, image[..., 3:4]], axis=-1)
    return np.ascontiguousarray(colour)


def _luma(colour):
    return colour @ _LUMA


def _positive(name, value):
    if not np.isfinite(value) or value <= 0:
        raise InputError(f"{name} must be a number above 0, got {value!r}")


# ----------------------------------------------------------------------------- point-wise


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
    colour = _check(image)
    above = (_luma(colour) >= level)[..., None]
    return _with_colour(image, np.where(above, np.float32(light), np.float32(dark)))


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
    colour = _check(image)
    if not 0 <= black < white <= 1:
        raise InputError(f"levels needs 0 <= black < white <= 1, got black={black!r}, white={white!r}")
    _positive("gamma", gamma)
    stretched = np.clip((colour - np.float32(black)) / np.float32(white - black), 0, 1)
    return _with_colour(image, np.power(stretched, np.float32(1 / gamma)))


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
    colour = _check(image)
    _positive("exposure", exposure)
    _positive("white", white)
    linear = srgb_to_linear(colour) * np.float32(exposure)
    lum = _luma(linear)
    mapped = lum * (1 + lum / np.float32(white * white)) / (1 + lum)
    ratio = np.where(lum > 1e-8, mapped / np.maximum(lum, 1e-8), 0)[..., None]
    return _with_colour(image, linear_to_srgb(np.clip(linear * ratio, 0, 1)))


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
    colour = _check(image)
    if int(steps) != steps or not 2 <= steps <= 256:
        raise InputError(f"posterize steps must be a whole number from 2 to 256, got {steps!r}")
    top = np.float32(steps - 1)
    return _with_colour(image, np.floor(colour * top + np.float32(0.5)) / top)


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
    colour = _check(image)
    if int(bins) != bins or bins < 2:
        raise InputError(f"bins must be a whole number >= 2, got {bins!r}")
    luma = _luma(colour)
    weight = image[..., 3] if image.shape[2] == 4 else None
    counts, _ = np.histogram(luma, bins=int(bins), range=(0, 1), weights=weight)
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
    colour = _check(image)
    if transfer is None:
        transfer = equalization_transfer(image)
    transfer = np.asarray(transfer, np.float32)
    if transfer.ndim != 1 or transfer.size < 3:
        raise InputError(f"transfer must be a 1-D curve of at least 3 values, got shape {transfer.shape}")
    luma = _luma(colour)
    mapped = np.interp(luma, np.linspace(0, 1, transfer.size), transfer).astype(np.float32)
    ratio = np.where(luma > 1e-6, mapped / np.maximum(luma, 1e-6), 0)[..., None]
    # Black has no hue to keep; it goes to the curve's grey.
    out = np.where(luma[..., None] > 1e-6, colour * ratio, mapped[..., None])
    return _with_colour(image, out)


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
    colour = _check(image)
    ramp = np.asarray(colours, np.float32)
    if ramp.ndim != 2 or ramp.shape[1] != 3 or len(ramp) < 2:
        raise InputError(f"colours must be two or more RGB triples, got shape {ramp.shape}")
    stops = np.linspace(0, 1, len(ramp))
    luma = _luma(colour)
    out = np.stack([np.interp(luma, stops, ramp[:, c]) for c in range(3)], axis=-1)
    return _with_colour(image, out)


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
    colour = _check(image)
    if not 0 < width <= 360:
        raise InputError(f"width must be in (0, 360] degrees, got {width!r}")
    h, s, v = _rgb_to_hsv(colour)
    distance = np.abs((h - hue + 180) % 360 - 180)
    selected = (distance <= width / 2) & (s >= min_saturation)
    swapped = _hsv_to_rgb(np.full_like(h, new_hue % 360), s, v)
    return _with_colour(image, np.where(selected[..., None], swapped, colour))


_D65 = np.array([0.95047, 1.0, 1.08883], np.float32)
_RGB_TO_XYZ = np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]],
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
    colour = _check(image)
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
    return _with_colour(image, np.repeat(grey[..., None], 3, axis=-1))


# ----------------------------------------------------------------------------- neighbourhood


def _gaussian_kernel(sigma, truncate=3.0):
    radius = max(1, int(np.ceil(truncate * sigma)))
    x = np.arange(-radius, radius + 1, dtype=np.float64)
    kernel = np.exp(-0.5 * (x / sigma) ** 2)
    return (kernel / kernel.sum()).astype(np.float32)


def _convolve_axis(values, kernel, axis, mode="edge"):
    radius = len(kernel) // 2
    pad = [(0, 0)] * values.ndim
    pad[axis] = (radius, radius)
    padded = np.pad(values, pad, mode=mode)
    size = values.shape[axis]
    out = np.zeros_like(values)
    for i, weight in enumerate(kernel):
        out += weight * np.take(padded, np.arange(i, i + size), axis=axis)
    return out


def _blur(values, sigma):
    kernel = _gaussian_kernel(sigma)
    return _convolve_axis(_convolve_axis(values, kernel, 0), kernel, 1)


def gaussian_blur(image, sigma=1.5):
    """Gaussian blur of the encoded colour (borders replicate edge pixels).

    Parameters
    ----------
    image : ndarray of float32, shape (H, W, 3) or (H, W, 4)
    sigma : float
        Standard deviation in pixels, > 0; the kernel reaches ``ceil(3 sigma)`` pixels.

    Returns
    -------
    ndarray of float32, same shape as `image`
    """
    colour = _check(image)
    _positive("sigma", sigma)
    return _with_colour(image, _blur(colour, sigma))


def unsharp_mask(image, radius=1.5, amount=1.5, threshold=0.0):
    """Unsharp mask: add back ``amount`` times the difference from a Gaussian blur.

    ``F = O + amount (O - blur(O))`` where the difference exceeds `threshold` in magnitude,
    clipped to [0, 1]; the clipping at strong edges and the threshold make it nonlinear.

    Parameters
    ----------
    image : ndarray of float32, shape (H, W, 3) or (H, W, 4)
    radius : float
        Blur standard deviation in pixels, > 0.
    amount : float
        Strength, >= 0.
    threshold : float
        Least difference that is sharpened, in [0, 1].

    Returns
    -------
    ndarray of float32, same shape as `image`
    """
    colour = _check(image)
    _positive("radius", radius)
    detail = colour - _blur(colour, radius)
    detail = np.where(np.abs(detail) >= threshold, detail, 0)
    return _with_colour(image, colour + np.float32(amount) * detail)


def bilateral(image, sigma_spatial=2.0, sigma_range=0.1, iterations=3):
    """Iterated bilateral filter on a bilateral grid (Chen, Paris and Durand 2007).

    Each iteration splats the colour into a grid over (row, column, luma) with cells of
    `sigma_spatial` pixels and `sigma_range` luma, blurs the grid with a [1, 2, 1] kernel
    along each axis and reads it back by trilinear interpolation; luma keys the range
    weight, so colours on either side of a luma edge do not mix. Iterating it pulls edge
    colours towards the nearer side, the staircase the paper repairs (section 4).

    Parameters
    ----------
    image : ndarray of float32, shape (H, W, 3) or (H, W, 4)
    sigma_spatial : float
        Spatial scale in pixels, > 0.
    sigma_range : float
        Luma scale in [0, 1] units, > 0.
    iterations : int
        Passes, 1 to 10.

    Returns
    -------
    ndarray of float32, same shape as `image`
    """
    colour = _check(image)
    _positive("sigma_spatial", sigma_spatial)
    _positive("sigma_range", sigma_range)
    if int(iterations) != iterations or not 1 <= iterations <= 10:
        raise InputError(f"iterations must be a whole number from 1 to 10, got {iterations!r}")
    out = colour.astype(np.float32)
    for _ in range(int(iterations)):
        out = _bilateral_grid_pass(out, float(sigma_spatial), float(sigma_range))
    return _with_colour(image, out)


def _bilateral_grid_pass(colour, sigma_spatial, sigma_range):
    height, width = colour.shape[:2]
    luma = _luma(colour)
    # Grid coordinates: +1 keeps the [1, 2, 1] blur and trilinear reads inside the grid.
    gy = np.arange(height, dtype=np.float32)[:, None] / sigma_spatial + 1 + np.zeros((1, width), np.float32)
    gx = np.arange(width, dtype=np.float32)[None, :] / sigma_spatial + 1 + np.zeros((height, 1), np.float32)
    gz = luma / sigma_range + 1
    shape = (int(np.ceil((height - 1) / sigma_spatial)) + 3, int(np.ceil((width - 1) / sigma_spatial)) + 3,
             int(np.ceil(1 / sigma_range)) + 3)
    index = (np.rint(gy).astype(np.int64) * shape[1] + np.rint(gx).astype(np.int64)) * shape[2] \
        + np.rint(gz).astype(np.int64)
    values = np.concatenate([colour, np.ones((height, width, 1), np.float32)], axis=-1)
    grid = np.stack([np.bincount(index.ravel(), values[..., c].ravel(), minlength=np.prod(shape))
                     for c in range(4)], axis=-1).reshape(*shape, 4)
    for axis in range(3):
        grid = _convolve_axis(grid, np.array([0.25, 0.5, 0.25], np.float64), axis)
    # Trilinear read-back.
    y0, x0, z0 = (np.clip(np.floor(g).astype(np.int64), 0, s - 2) for g, s in zip((gy, gx, gz), shape))
    fy, fx, fz = ((g - c)[..., None] for g, c in zip((gy, gx, gz), (y0, x0, z0)))
    result = np.zeros((height, width, 4), np.float64)
    for dy in (0, 1):
        for dx in (0, 1):
            for dz in (0, 1):
                weight = (fy if dy else 1 - fy) * (fx if dx else 1 - fx) * (fz if dz else 1 - fz)
                result += weight * grid[y0 + dy, x0 + dx, z0 + dz]
    filtered = result[..., :3] / np.maximum(result[..., 3:4], 1e-12)
    return filtered.astype(np.float32)


# ----------------------------------------------------------------------------- registry


@dataclass(frozen=True)
class Parameter:
    """One parameter of a filter, as the command line and :func:`apply` see it.

    Attributes
    ----------
    name : str
    default : float, int or tuple
    help : str
    spatial : bool
        A length in pixels, multiplied by :func:`apply`'s `scale`.
    """

    name: str
    default: object
    help: str
    spatial: bool = False


@dataclass(frozen=True)
class Filter:
    """A named filter with its parameters.

    Attributes
    ----------
    name : str
        Command-line name (``gamma``, ``unsharp``...).
    function : callable
        ``function(image, **params) -> image`` on the core contract.
    summary : str
        One line for ``aarecovery filters``.
    parameters : tuple of Parameter
    pointwise : bool
        Each output pixel depends on the same input pixel only.
    prepare : callable, optional
        ``prepare(original, params) -> params``: per-image state fitted once on the
        original (the histogram-equalization curve) and reused on other images.
    """

    name: str
    function: object
    summary: str
    parameters: tuple = field(default_factory=tuple)
    pointwise: bool = True
    prepare: object = None

    def defaults(self):
        """dict: every parameter's default."""
        return {p.name: p.default for p in self.parameters}


def _prepare_equalization(original, params):
    if params.get("transfer") is None:
        params = dict(params, transfer=equalization_transfer(original))
    return params


FILTERS = {f.name: f for f in (
    Filter("threshold", threshold, "intensity threshold to black and white",
           (Parameter("level", 0.5, "luma threshold in [0, 1]"),)),
    Filter("gamma", levels, "levels and gamma",
           (Parameter("gamma", 2.0, "mid-tone exponent (> 1 brightens)"),
            Parameter("black", 0.0, "input value that maps to 0"),
            Parameter("white", 1.0, "input value that maps to 1"))),
    Filter("tonemap", tone_map, "global tone mapping (extended Reinhard)",
           (Parameter("exposure", 4.0, "linear gain before compression"),
            Parameter("white", 2.0, "exposed luminance that maps to white"))),
    Filter("posterize", posterize, "round each channel to a few levels",
           (Parameter("steps", 4, "levels per channel, 2 to 256"),)),
    Filter("equalize", equalize_histogram, "histogram equalization of luma",
           (Parameter("transfer", None, "curve from equalization_transfer; default: the image's own"),),
           prepare=_prepare_equalization),
    Filter("gradientmap", gradient_map, "luma to a colour ramp",
           (Parameter("colours", DEFAULT_RAMP, "ramp colours, sRGB triples from dark to light"),)),
    Filter("replacecolour", replace_colour, "hue range swapped for another hue",
           (Parameter("hue", 0.0, "centre of the selected hue range, degrees"),
            Parameter("width", 40.0, "width of the hue range, degrees"),
            Parameter("new_hue", 220.0, "hue given to selected pixels, degrees"),
            Parameter("min_saturation", 0.25, "least saturation of a selected pixel"))),
    Filter("colourtogrey", colour_to_grey, "nonlinear colour to grey (lightness plus chroma)",
           (Parameter("chroma_weight", 0.6, "share of chroma added to lightness"),
            Parameter("bright_hue", 30.0, "CIELAB hue lightened most, degrees"))),
    Filter("unsharp", unsharp_mask, "unsharp mask (sharpening)",
           (Parameter("radius", 1.5, "blur radius in pixels", spatial=True),
            Parameter("amount", 1.5, "strength"),
            Parameter("threshold", 0.0, "least difference sharpened")), pointwise=False),
    Filter("bilateral", bilateral, "iterated bilateral filter (bilateral grid)",
           (Parameter("sigma_spatial", 2.0, "spatial scale in pixels", spatial=True),
            Parameter("sigma_range", 0.1, "luma scale"),
            Parameter("iterations", 3, "passes")), pointwise=False),
    Filter("blur", gaussian_blur, "Gaussian blur (the paper's failure case)",
           (Parameter("sigma", 1.5, "standard deviation in pixels", spatial=True),), pointwise=False),
)}


def get_filter(name):
    """Look a filter up by its command-line name.

    Raises
    ------
    InputError
        For an unknown name, listing the known ones.
    """
    try:
        return FILTERS[name]
    except KeyError:
        raise InputError(f"unknown filter {name!r}; the filters are: {', '.join(FILTERS)}") from None


def apply(name, image, *, scale=1, **params):
    """Run a filter by name on an image of any layout the core accepts.

    Parameters
    ----------
    name : str
        A key of :data:`FILTERS`.
    image : ndarray, shape (H, W) or (H, W, C), C in 1..4
        uint8, uint16 or float in [0, 1], sRGB-encoded, straight alpha.
    scale : float
        Multiplies every spatial parameter (radii in pixels): the filter as it would act on
        an image `scale` times larger.
    **params
        Filter parameters; missing ones take their defaults.

    Returns
    -------
    ndarray
        Same shape and dtype as `image` (a colour-to-grey result of an RGB image stays RGB).
    """
    spec = get_filter(name)
    known = spec.defaults()
    unknown = set(params) - set(known)
    if unknown:
        raise InputError(f"filter {name!r} has no parameter {sorted(unknown)[0]!r}; "
                         f"its parameters are: {', '.join(known) or 'none'}")
    merged = dict(known, **params)
    for p in spec.parameters:
        if p.spatial:
            merged[p.name] = merged[p.name] * scale
    layout = layout_of(image, "image")
    native = image.dtype == np.float32 and image.ndim == 3 and image.shape[2] in (3, 4)
    rgba = image if native else to_rgba_float(image, layout, "image")
    if spec.prepare is not None:
        merged = spec.prepare(rgba, merged)
    result = spec.function(rgba, **merged)
    return result if native else from_rgba_float(result, layout)
