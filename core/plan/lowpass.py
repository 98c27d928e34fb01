"""Is F a blur of O? A small shift-invariant kernel fitted from O to F by least squares.

If it explains F and is low-pass, F's soft edges are the filter's intent (the paper's
failure case: recovery would re-sharpen them), and F is kept.
"""

import numpy as np

__all__ = ["fit_lowpass"]

# Low-pass fit: kernel radius, the largest relative residual that counts as "F is this
# kernel applied to O", and the shape of a low-pass kernel. Measured with a 5 x 5 kernel:
# Gaussian blur (sigma 1.5) fits to 0.02-0.10 (the Siemens star is the worst, its spokes
# alias) with no negative weights and a centre weight near 0.08; unsharp masking has
# negative lobes of 0.3-1.2; the bilateral filter leaves residuals of 0.1-0.19 with a centre
# of 0.27-1.04 and negative lobes of 0.05-0.38.
_KERNEL_RADIUS = 2
_LOWPASS_RESIDUAL = 0.15
_LOWPASS_NEGATIVE = 0.03
_LOWPASS_CENTRE = 0.5


def fit_lowpass(original, filtered):
    """Fit ``F ~ K * O`` with a small kernel shared by the colour channels.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 3)
        Encoded colour.

    Returns
    -------
    lowpass : bool
        The kernel explains F (relative residual below the measured bound) and is a
        low-pass kernel: weights sum to about 1, negative lobes are negligible and the
        centre does not dominate (which would be the identity).
    residual : float
        ``|F - K * O| / |F - mean(F)|`` on the sampled pixels.
    kernel : ndarray of float64, shape (2r + 1, 2r + 1)
    """
    r = _KERNEL_RADIUS
    height, width = original.shape[:2]
    if height <= 2 * r + 2 or width <= 2 * r + 2:
        return False, 1.0, None
    padded = np.pad(original, ((r, r), (r, r), (0, 0)), mode="edge")
    step = max(1, int(np.sqrt(height * width / 20000)))
    rows = np.arange(0, height, step)
    cols = np.arange(0, width, step)
    columns = [padded[r + dy + rows[:, None], r + dx + cols[None, :]].reshape(-1)
               for dy in range(-r, r + 1) for dx in range(-r, r + 1)]
    design = np.stack(columns, axis=1).astype(np.float64)
    target = filtered[rows[:, None], cols[None, :]].reshape(-1).astype(np.float64)
    spread = np.linalg.norm(target - target.mean())
    if spread < 1e-6:
        return False, 1.0, None
    # Normal equations: a 25 x 25 solve, ten times faster than lstsq's SVD here; the tiny
    # ridge only matters for flat images, whose columns are all alike (and all zero for a
    # black O, hence the absolute term: a gradient map of black O was a singular matrix).
    gram = design.T @ design
    gram[np.diag_indices_from(gram)] += 1e-9 * np.trace(gram) + 1e-12
    weights = np.linalg.solve(gram, design.T @ target)
    residual = float(np.linalg.norm(design @ weights - target) / spread)
    kernel = weights.reshape(2 * r + 1, 2 * r + 1)
    total = kernel.sum()
    negative = -kernel[kernel < 0].sum()
    lowpass = (residual < _LOWPASS_RESIDUAL and abs(total - 1) < 0.05 and negative < _LOWPASS_NEGATIVE * total
               and kernel[r, r] < _LOWPASS_CENTRE * total)
    return bool(lowpass), residual, kernel
