"""Supersampled ground truth, as in the paper (section 4, figure 1d).

A scene is rendered at ``k`` times the target resolution; then

* ``O = box_downsample(scene)``: the properly antialiased original,
* ``F = filter(O)``: what the user has,
* ``reference = box_downsample(filter(scene))``: the filter applied before antialiasing,
  which is what recovery should produce.

The box filter runs in one of two spaces, the two ways real images are antialiased:
``"linear"`` averages linear light (cameras, physically based renderers), ``"srgb"``
averages the encoded values (most text and vector renderers, and many editors).
"""

from dataclasses import dataclass

import numpy as np

from .. import filters as _filters
from ..params import BLEND_SPACES
from ..plan.resample import box_downsample

__all__ = ["AA_SPACES", "Case", "box_downsample", "make_case"]

#: The two spaces in which images are antialiased (and in which a model can be fitted).
AA_SPACES = BLEND_SPACES


@dataclass
class Case:
    """One ground-truth case.

    Attributes
    ----------
    original, filtered, reference : ndarray of float32, shape (H, W, 3)
        O, F and the supersampled reference, sRGB-encoded.
    filter_name : str
    space : str
        The space of the box filter.
    k : int
    """

    original: np.ndarray
    filtered: np.ndarray
    reference: np.ndarray
    filter_name: str
    space: str
    k: int


def make_case(scene, filter_name, k, space="linear", **params):
    """Build O, F and the reference from a high-resolution scene.

    Parameters
    ----------
    scene : ndarray of float32, shape (H * k, W * k, 3)
        sRGB-encoded scene at `k` times the target resolution.
    filter_name : str
        A key of :data:`aarecovery.filters.FILTERS`.
    k : int
        Supersampling factor.
    space : {"linear", "srgb"}
        Space of the box filter.
    **params
        Filter parameters. Spatial ones (radii) are given at the target resolution and
        multiplied by `k` on the scene; per-image state (the equalization curve) is fitted on
        O once and reused on the scene, as a user's filter would be.

    Returns
    -------
    Case
    """
    spec = _filters.get_filter(filter_name)
    original = box_downsample(scene, k, space)
    merged = dict(spec.defaults(), **params)
    if spec.prepare is not None:
        merged = spec.prepare(original, merged)
    filtered = _filters.apply(filter_name, original, **merged)
    reference = box_downsample(_filters.apply(filter_name, scene, scale=k, **merged), k, space)
    return Case(original, filtered, reference, filter_name, space, k)
