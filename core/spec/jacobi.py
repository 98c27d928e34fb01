"""Equation 6 solved by Jacobi iterations, reading only the previous iterate (ping-pong)."""

import numpy as np

from .neighbourhood import NEIGHBOUR_OFFSETS

__all__ = ["jacobi_step"]


def _gather_indices(index, height, width):
    offsets = np.asarray(NEIGHBOUR_OFFSETS, dtype=np.int64)
    rows = np.clip(np.arange(height)[:, None] + offsets[index, 0], 0, height - 1)
    cols = np.clip(np.arange(width)[None, :] + offsets[index, 1], 0, width - 1)
    return rows * width + cols


def jacobi_step(recovered, filtered, model):
    """One Jacobi iteration of equation 6.

    ``R'[p] = beta (alpha R[p_a] + (1 - alpha) R[p_b]) + (1 - beta) F[p]``, reading only the
    previous iterate, as a GL pass does. With a pure-colour prior, a fixed filtered colour
    stands in for R at an extreme that was a thin feature's partial colour.

    Parameters
    ----------
    recovered : ndarray of float32, shape (H, W, 4)
        The previous iterate (F for the first step).
    filtered : ndarray of float32, shape (H, W, 4)
        F in the working space.
    model : BlendModel

    Returns
    -------
    ndarray of float32, shape (H, W, 4)
    """
    height, width = recovered.shape[:2]
    # Whole pixels as 16-byte items: a 1-D take is far cheaper than gathering rows of 4.
    pixels = np.ascontiguousarray(recovered, dtype=np.float32).reshape(-1).view(np.complex128)

    def gather(index):
        return np.take(pixels, _gather_indices(index, height, width)).view(np.float32).reshape(height, width, 4)

    at_a = gather(model.index_a)
    at_b = gather(model.index_b)
    if model.pure_a is not None:
        at_a = np.where(model.pure_a[..., None], model.fixed_a, at_a)
        at_b = np.where(model.pure_b[..., None], model.fixed_b, at_b)
    alpha = model.alpha[..., None]
    beta = model.beta[..., None]
    if model.toward is not None:
        # A smoothing filter's drawn edges move towards O (blend_model.toward_original).
        toward = model.toward[..., None]
        # g (O - F) rather than g O - g F: exactly F where F left O's pixel as it was.
        return (beta * (alpha * at_a + (1 - alpha) * at_b) + (1 - beta) * filtered
                + toward * (model.original - filtered)).astype(np.float32)
    return (beta * (alpha * at_a + (1 - alpha) * at_b) + (1 - beta) * filtered).astype(np.float32)

