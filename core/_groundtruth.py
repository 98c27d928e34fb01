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

from . import filters as _filters
from ._colour import linear_to_srgb, srgb_to_linear
from ._errors import InputError

__all__ = ["AA_SPACES", "Case", "box_downsample", "make_case"]

AA_SPACES = ("linear", "srgb")


def box_downsample(image, k, space="linear"):
    """Average ``k x k`` blocks, in linear light or in encoded values.

    Parameters
    ----------
    image : ndarray of float32, shape (H * k, W * k, C)
        sRGB-encoded colour (a fourth channel, alpha, is averaged as is).
    k : int
        Block size, >= 1; H * k and W * k must be multiples of k.
    space : {"linear", "srgb"}
        Where the average is taken.

    Returns
    -------
    ndarray of float32, shape (H, W, C)
        sRGB-encoded.
    """
    if space not in AA_SPACES:
        raise InputError(f"space must be one of {', '.join(AA_SPACES)}, got {space!r}")
    height, width = image.shape[0] // k, image.shape[1] // k
    if height * k != image.shape[0] or width * k != image.shape[1]:
        raise InputError(f"image of {image.shape[1]}x{image.shape[0]} is not a multiple of k={k}")
    values = image.astype(np.float32)
    if space == "linear":
        values = values.copy()
        values[..., :3] = srgb_to_linear(values[..., :3])
    mean = values.reshape(height, k, width, k, -1).mean(axis=(1, 3), dtype=np.float64).astype(np.float32)
    if space == "linear":
        mean[..., :3] = linear_to_srgb(mean[..., :3])
    return mean


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
