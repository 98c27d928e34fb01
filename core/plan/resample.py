"""The one box filter of the project: averaging k x k blocks, in linear light or in encoded values.

The safe plan's self-calibration uses it to see O as a scene at twice the resolution; the
lab's supersampled ground truth uses it to antialias scenes.
"""

import numpy as np

from ..colour import linear_to_srgb, srgb_to_linear
from ..errors import InputError
from ..params import BLEND_SPACES

__all__ = ["box_downsample"]


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
    if space not in BLEND_SPACES:
        raise InputError(f"space must be one of {', '.join(BLEND_SPACES)}, got {space!r}")
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
