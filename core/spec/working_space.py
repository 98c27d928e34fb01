"""The working space of every pass: premultiplied RGBA whose colour is in the blend space.

Colour is premultiplied by alpha before the fit, so a transparent pixel is the colour
(0, 0, 0, 0) and blending towards it lowers coverage without bleeding its hidden colour.
The blend space is where the image was antialiased: linear light (cameras, the paper's
choice) or sRGB-encoded values (most text and vector renderers); see ``aarecovery.plan``.
"""

import numpy as np

from ..colour import linear_to_srgb, srgb_to_linear

__all__ = ["to_working_space", "from_working_space", "VISIBLE_COVERAGE"]

#: A result's coverage at or below this is none: the pixel comes back transparent with F's
#: colour. Half a 16-bit level, so no integer output can show it. Below it the colour is the
#: ratio of two rounding errors: where the model's alpha is 1 exactly in NumPy and 1 - 4e-6
#: on an NVIDIA H100 (fused multiply-adds), a transparent pixel took 4e-6 of an opaque
#: neighbour and came back in that neighbour's colour at coverage 1e-6 (255 levels apart
#: in 8-bit colour, measured; both backends now return F's colour there).
VISIBLE_COVERAGE = 0.5 / 65535


def to_working_space(rgba, *, linear_input=False, blend_space="linear"):
    """Move straight RGBA from its encoding into the premultiplied blend space.

    Parameters
    ----------
    rgba : ndarray of float32, shape (H, W, 4)
        Straight alpha, colour sRGB-encoded (or linear if `linear_input`).
    linear_input : bool
        True when `rgba`'s colour is already linear light.
    blend_space : {"linear", "srgb"}
        Where the model is fitted and the blend happens.

    Returns
    -------
    ndarray of float32, shape (H, W, 4)
        Premultiplied colour in the blend space, then alpha.
    """
    colour = rgba[..., :3]
    if blend_space == "linear" and not linear_input:
        colour = srgb_to_linear(colour)
    elif blend_space == "srgb" and linear_input:
        colour = linear_to_srgb(colour)
    alpha = rgba[..., 3:4]
    return np.concatenate([colour * alpha, alpha], axis=-1).astype(np.float32, copy=False)


def from_working_space(work, filtered_rgba, *, linear_input=False, blend_space="linear", filtered_work=None):
    """Undo :func:`to_working_space`: un-premultiply and re-encode.

    Parameters
    ----------
    work : ndarray of float32, shape (H, W, 4)
        Premultiplied RGBA in the blend space.
    filtered_rgba : ndarray of float32, shape (H, W, 4)
        F in its own encoding; its colour is kept where the result is transparent (coverage
        at most :data:`VISIBLE_COVERAGE`), where colour cannot be recovered from a
        premultiplied value.
    linear_input, blend_space
        As given to :func:`to_working_space`.
    filtered_work : ndarray of float32, shape (H, W, 4), optional
        F in the working space. Pixels the recovery left exactly at F take `filtered_rgba`
        as it was: decoding and re-encoding is not exact to the last bit, and a pixel
        recovery did not touch must come back bit for bit (16-bit and float images).

    Returns
    -------
    ndarray of float32, shape (H, W, 4)
        Straight RGBA in the input's encoding, clipped to [0, 1].
    """
    alpha = np.clip(work[..., 3:4], 0, 1)
    visible = alpha > np.float32(VISIBLE_COVERAGE)
    alpha = np.where(visible, alpha, np.float32(0))
    colour = np.where(visible, work[..., :3] / np.where(visible, alpha, 1), 0)
    colour = np.clip(colour, 0, 1)
    if blend_space == "linear" and not linear_input:
        colour = linear_to_srgb(colour)
    elif blend_space == "srgb" and linear_input:
        colour = srgb_to_linear(colour)
    colour = np.where(visible, colour, filtered_rgba[..., :3])
    result = np.concatenate([colour, alpha], axis=-1).astype(np.float32, copy=False)
    if filtered_work is not None:
        untouched = np.all(work == filtered_work, axis=-1)
        result[untouched] = filtered_rgba[untouched]
    return result
