"""The filters by name: their parameters for the command line, and :func:`apply` for any layout."""

import inspect
from dataclasses import dataclass, field

import numpy as np

from ..contract import from_rgba_float, layout_of, to_rgba_float
from ..errors import InputError
from .pointwise import (colour_to_grey, equalization_transfer, equalize_histogram, gradient_map, levels,
                        posterize, replace_colour, threshold, tone_map)
from .spatial import bilateral, gaussian_blur, unsharp_mask

__all__ = ["Filter", "Parameter", "FILTERS", "get_filter", "apply"]


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


def _described(function, spatial=(), **helps):
    """The parameters of `function` named in `helps`, with the defaults of its signature."""
    signature = inspect.signature(function).parameters
    return tuple(Parameter(name, signature[name].default, text, name in spatial) for name, text in helps.items())


FILTERS = {f.name: f for f in (
    Filter("threshold", threshold, "intensity threshold to black and white",
           _described(threshold, level="luma threshold in [0, 1]")),
    Filter("gamma", levels, "levels and gamma",
           _described(levels, gamma="mid-tone exponent (> 1 brightens)", black="input value that maps to 0",
                      white="input value that maps to 1")),
    Filter("tonemap", tone_map, "global tone mapping (extended Reinhard)",
           _described(tone_map, exposure="linear gain before compression",
                      white="exposed luminance that maps to white")),
    Filter("posterize", posterize, "round each channel to a few levels",
           _described(posterize, steps="levels per channel, 2 to 256")),
    Filter("equalize", equalize_histogram, "histogram equalization of luma",
           _described(equalize_histogram, transfer="curve from equalization_transfer; default: the image's own"),
           prepare=_prepare_equalization),
    Filter("gradientmap", gradient_map, "luma to a colour ramp",
           _described(gradient_map, colours="ramp colours, sRGB triples from dark to light")),
    Filter("replacecolour", replace_colour, "hue range swapped for another hue",
           _described(replace_colour, hue="centre of the selected hue range, degrees",
                      width="width of the hue range, degrees", new_hue="hue given to selected pixels, degrees",
                      min_saturation="least saturation of a selected pixel")),
    Filter("colourtogrey", colour_to_grey, "nonlinear colour to grey (lightness plus chroma)",
           _described(colour_to_grey, chroma_weight="share of chroma added to lightness",
                      bright_hue="CIELAB hue lightened most, degrees")),
    Filter("unsharp", unsharp_mask, "unsharp mask (sharpening)",
           _described(unsharp_mask, spatial=("radius",), radius="blur radius in pixels", amount="strength",
                      threshold="least difference sharpened"), pointwise=False),
    Filter("bilateral", bilateral, "iterated bilateral filter (bilateral grid)",
           _described(bilateral, spatial=("sigma_spatial",), sigma_spatial="spatial scale in pixels",
                      sigma_range="luma scale", iterations="passes"), pointwise=False),
    Filter("blur", gaussian_blur, "Gaussian blur (the paper's failure case)",
           _described(gaussian_blur, spatial=("sigma",), sigma="standard deviation in pixels"), pointwise=False),
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
