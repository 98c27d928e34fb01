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

from .catalogue import FILTERS, Filter, Parameter, apply, get_filter
from .pointwise import (colour_to_grey, equalization_transfer, equalize_histogram, gradient_map, levels, posterize,
                        replace_colour, threshold, tone_map)
from .spatial import bilateral, gaussian_blur, unsharp_mask

__all__ = [
    "threshold", "levels", "tone_map", "posterize", "equalization_transfer", "equalize_histogram",
    "gradient_map", "replace_colour", "colour_to_grey", "unsharp_mask", "bilateral", "gaussian_blur",
    "Filter", "Parameter", "FILTERS", "get_filter", "apply",
]
