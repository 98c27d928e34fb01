"""Exact piecewise sRGB transfer functions (IEC 61966-2-1), the NumPy backend's only colour maths.

The GL backend has the same two functions once, in ``shaders/colour.glsl``.
"""

import numpy as np

__all__ = ["srgb_to_linear", "linear_to_srgb"]


def srgb_to_linear(encoded):
    """Decode sRGB-encoded values to linear light.

    Parameters
    ----------
    encoded : ndarray of float32, any shape
        Values in [0, 1].

    Returns
    -------
    ndarray of float32, same shape
    """
    encoded = np.asarray(encoded, dtype=np.float32)
    low = encoded * np.float32(1 / 12.92)
    high = np.power((encoded + np.float32(0.055)) * np.float32(1 / 1.055), np.float32(2.4))
    return np.where(encoded <= np.float32(0.04045), low, high).astype(np.float32, copy=False)


def linear_to_srgb(linear):
    """Encode linear-light values with the sRGB transfer function.

    Parameters
    ----------
    linear : ndarray of float32, any shape
        Values in [0, 1]; values outside are clipped first.

    Returns
    -------
    ndarray of float32, same shape
    """
    linear = np.clip(np.asarray(linear, dtype=np.float32), 0.0, 1.0)
    low = linear * np.float32(12.92)
    high = np.float32(1.055) * np.power(linear, np.float32(1 / 2.4)) - np.float32(0.055)
    return np.where(linear <= np.float32(0.0031308), low, high).astype(np.float32, copy=False)
