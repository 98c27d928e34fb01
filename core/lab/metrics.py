"""Image-quality measures for the evaluation: PSNR, SSIM and the edge band.

Images are float32 ``(H, W, 3)`` sRGB-encoded in [0, 1]; every measure is taken on the
encoded values (what a viewer sees), all channels together.
"""

import numpy as np

from ..colour import LUMA_WEIGHTS
from ..filters.spatial import gaussian_filter
from ..spec.local_plan import FLAT_SPAN, neighbourhood_extremes
from ..spec.sobel import image_gradients

__all__ = ["mse", "psnr", "ssim", "ssim_map", "edge_band", "error_reduction", "outside_local_range", "haze_pixels",
           "flat_areas", "HAZE_TOLERANCE"]

# An edge-band pixel is one where the reference and F differ by more than this (they
# disagree there, so that is where a repair is needed or can harm) ...
_BAND_DIFFERENCE = 1.0 / 255
# ... or where O has a gradient of at least this (Sobel / 8 on encoded values, the largest
# channel): an edge the repair will act on.
_BAND_GRADIENT = 0.02
_PSNR_CAP = 100.0
#: How much darker than F a background pixel may come out before it counts as haze: two
#: 8-bit steps of luma, above the rounding of any repair but far below a visible blotch.
HAZE_TOLERANCE = 2.0 / 255
_LUMA = LUMA_WEIGHTS  # Rec. 709, on encoded values


def mse(a, b, mask=None):
    """Mean squared error over all channels, optionally inside a boolean ``(H, W)`` mask."""
    squared = np.square(a.astype(np.float64) - b.astype(np.float64)).mean(axis=-1)
    if mask is not None:
        if not mask.any():
            return 0.0
        squared = squared[mask]
    return float(squared.mean())


def psnr(a, b, mask=None):
    """Peak signal-to-noise ratio in dB for a peak of 1, capped at 100 dB for equal images."""
    error = mse(a, b, mask)
    return _PSNR_CAP if error <= 10 ** (-_PSNR_CAP / 10) else float(10 * np.log10(1 / error))


def _gaussian_filter(values, sigma=1.5):
    # The usual SSIM window: truncated at 3.5 sigma, reflected at the borders.
    return gaussian_filter(values, sigma, "reflect", truncate=3.5)


def ssim(a, b, mask=None):
    """Structural similarity (Wang et al. 2004) with a Gaussian window of sigma 1.5.

    The usual constants ``K1 = 0.01, K2 = 0.03`` for a data range of 1; the SSIM map is
    averaged over channels, then over the image or over `mask`.
    """
    value = ssim_map(a, b)
    if mask is not None:
        return float(value[mask].mean()) if mask.any() else 1.0
    return float(value.mean())


def ssim_map(a, b):
    """Per-pixel SSIM, averaged over channels: ndarray of float64, shape (H, W)."""
    a = a.astype(np.float64)
    b = b.astype(np.float64)
    c1, c2 = 0.01 ** 2, 0.03 ** 2
    mu_a, mu_b = _gaussian_filter(a), _gaussian_filter(b)
    var_a = _gaussian_filter(a * a) - mu_a ** 2
    var_b = _gaussian_filter(b * b) - mu_b ** 2
    cov = _gaussian_filter(a * b) - mu_a * mu_b
    value = ((2 * mu_a * mu_b + c1) * (2 * cov + c2)) / ((mu_a ** 2 + mu_b ** 2 + c1) * (var_a + var_b + c2))
    return value.mean(axis=-1)


def _sobel_max(image):
    gx, gy = image_gradients(image)
    return np.sqrt(gx * gx + gy * gy).max(axis=-1)


def edge_band(original, filtered, reference):
    """The pixels where antialiasing recovery matters.

    Parameters
    ----------
    original, filtered, reference : ndarray of float32, shape (H, W, 3)

    Returns
    -------
    ndarray of bool, shape (H, W)
        Where the reference and F differ by more than 1/255 in some channel, or O has a
        gradient (Sobel / 8, largest channel) of at least 0.02, grown by one pixel.
    """
    differs = np.abs(reference - filtered).max(axis=-1) > _BAND_DIFFERENCE
    band = differs | (_sobel_max(original) >= _BAND_GRADIENT)
    padded = np.pad(band, 1, mode="edge")
    h, w = band.shape
    grown = np.zeros_like(band)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            grown |= padded[1 + dy:1 + dy + h, 1 + dx:1 + dx + w]
    return grown


def error_reduction(result, filtered, reference, mask):
    """``1 - MSE(result) / MSE(F)`` inside `mask`: 1 is perfect, 0 no change, negative harm."""
    base = mse(filtered, reference, mask)
    if base <= 0:
        return 0.0
    return 1.0 - mse(result, reference, mask) / base


def outside_local_range(image, filtered, slack=1.0 / 255):
    """Where `image` leaves the colour range of F's 3 x 3 neighbourhood: invented colour.

    Parameters
    ----------
    image, filtered : ndarray of float32, shape (H, W, 3)
    slack : float
        Allowed excess beyond F's local minimum and maximum, per channel.

    Returns
    -------
    ndarray of bool, shape (H, W)
        True where some channel lies below the 3 x 3 minimum of F minus `slack` or above
        its maximum plus `slack` (borders replicated).
    """
    padded = np.pad(filtered, ((1, 1), (1, 1), (0, 0)), mode="edge")
    h, w = filtered.shape[:2]
    windows = [padded[1 + dy:1 + dy + h, 1 + dx:1 + dx + w] for dy in (-1, 0, 1) for dx in (-1, 0, 1)]
    low, high = np.minimum.reduce(windows), np.maximum.reduce(windows)
    return ((image < low - slack) | (image > high + slack)).any(axis=-1)


def flat_areas(image):
    """bool ``(H, W)``: where `image`'s 3 x 3 neighbourhood (borders replicated) spans at most
    half an 8-bit level in every channel (``spec.local_plan.FLAT_SPAN``, black included): one
    8-bit colour, a thresholded page's white or a posterized level's fill, where haze would show.

    Parameters
    ----------
    image : ndarray of float32, shape (H, W, 3)
    """
    brightest, darkest = neighbourhood_extremes(np.asarray(image, np.float32))
    return (brightest - darkest).max(axis=-1) <= np.float32(FLAT_SPAN)


def haze_pixels(image, filtered, background, tolerance=HAZE_TOLERANCE):
    """Background pixels that `image` makes darker than F: the haze a repair paints on paper.

    Parameters
    ----------
    image, filtered : ndarray of float32, shape (H, W, 3)
    background : ndarray of bool, shape (H, W)
        Where the scene is paper (no ink in or next to the pixel).
    tolerance : float
        Luma (Rec. 709, encoded values) by which `image` must be darker than F to count.

    Returns
    -------
    int
        0 for F itself.
    """
    darker = (filtered - image) @ _LUMA > tolerance
    return int((darker & background).sum())
