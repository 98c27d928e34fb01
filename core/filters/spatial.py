"""The neighbourhood filters: sharpening, edge-preserving smoothing and blur.

Radii are in pixels; ``catalogue.apply`` scales them with the image (``scale``).
"""

import numpy as np

from ..colour import luma
from ..errors import InputError
from .base import check_contract, check_positive, with_colour

__all__ = ["gaussian_blur", "unsharp_mask", "bilateral", "gaussian_filter"]


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


def gaussian_filter(values, sigma, mode="edge", truncate=3.0):
    """Separable Gaussian filter over the first two axes of `values`.

    Parameters
    ----------
    values : ndarray, shape (H, W, ...)
    sigma : float
        Standard deviation in pixels.
    mode : {"edge", "reflect"}
        How the border is padded (``numpy.pad`` modes).
    truncate : float
        The kernel's half-width in standard deviations.
    """
    kernel = _gaussian_kernel(sigma, truncate)
    return _convolve_axis(_convolve_axis(values, kernel, 0, mode), kernel, 1, mode)


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
    colour = check_contract(image)
    check_positive("sigma", sigma)
    return with_colour(image, gaussian_filter(colour, sigma))


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
    colour = check_contract(image)
    check_positive("radius", radius)
    detail = colour - gaussian_filter(colour, radius)
    detail = np.where(np.abs(detail) >= threshold, detail, 0)
    return with_colour(image, colour + np.float32(amount) * detail)


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
    colour = check_contract(image)
    check_positive("sigma_spatial", sigma_spatial)
    check_positive("sigma_range", sigma_range)
    if int(iterations) != iterations or not 1 <= iterations <= 10:
        raise InputError(f"iterations must be a whole number from 1 to 10, got {iterations!r}")
    out = colour.astype(np.float32)
    for _ in range(int(iterations)):
        out = _bilateral_grid_pass(out, float(sigma_spatial), float(sigma_range))
    return with_colour(image, out)


def _bilateral_grid_pass(colour, sigma_spatial, sigma_range):
    height, width = colour.shape[:2]
    key = luma(colour)
    # Grid coordinates: +1 keeps the [1, 2, 1] blur and trilinear reads inside the grid.
    gy = np.arange(height, dtype=np.float32)[:, None] / sigma_spatial + 1 + np.zeros((1, width), np.float32)
    gx = np.arange(width, dtype=np.float32)[None, :] / sigma_spatial + 1 + np.zeros((height, 1), np.float32)
    gz = key / sigma_range + 1
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
