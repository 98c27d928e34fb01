"""The one Sobel operator of the project: the passes' edge strength, the safe plan's edge
pixels and the evaluation's edge band all read it.

The kernel is divided by 8, so that a unit ramp gives 1; the magnitude is the Euclidean
norm over the channels of (gx, gy). At that scale the paper's ``sigma_e = 0.01`` separates
real edges (black/white gives ``e_p`` about 0.75) from noise; the raw kernel (64 times
larger ``e_p``) kept the gate open everywhere and smeared smooth gradients that a filter
had broken into bands (measured).
"""

import numpy as np

from .neighbourhood import OPPOSITE_PAIRS, dot, neighbours, planes

__all__ = ["sobel_gradients", "sobel_magnitude", "ridge_magnitude", "image_gradients", "gradient_magnitude"]


def sobel_gradients(around):
    """Sobel derivatives divided by 8 from a neighbourhood.

    Differences are taken first: a flat neighbourhood then gives exactly 0 in any summation
    order, which the edge test ``e_p == 0`` relies on (in both backends).

    Parameters
    ----------
    around : list of 9 ndarray, shape (C, ...)
        The neighbourhood in ``NEIGHBOUR_OFFSETS`` order: 1 N, 2 W, 3 E, 4 S, 5 NW, 6 NE,
        7 SW, 8 SE.

    Returns
    -------
    gx, gy : ndarray, shape (C, ...)
    """
    v = around
    eighth = np.float32(0.125)
    gx = ((v[6] - v[5]) + 2 * (v[3] - v[2]) + (v[8] - v[7])) * eighth
    gy = ((v[7] - v[5]) + 2 * (v[4] - v[1]) + (v[8] - v[6])) * eighth
    return gx, gy


def sobel_magnitude(around):
    """Sobel magnitude of a 4-channel (working space) neighbourhood, summed as GLSL does.

    Parameters
    ----------
    around : list of 9 ndarray, shape (4, ...)

    Returns
    -------
    ndarray, shape (...)
    """
    gx, gy = sobel_gradients(around)
    return np.sqrt(dot(gx, gx) + dot(gy, gy))


def ridge_magnitude(around):
    """How far the centre of a 4-channel neighbourhood stands out from its opposite neighbours.

    A 1 px line or dot centred on the pixel (a screentone's grid of dots, a stroke on the
    pixel grid) has no Sobel gradient there: its neighbours are symmetric about it. This is
    the largest, over the four opposite pairs (N/S, W/E, NW/SE, NE/SW), of the distance from
    the centre to the pair's mean, Euclidean over the channels: a line of unit contrast in
    one channel gives 1, a unit step 1/2 beside it, a ramp 0.

    Parameters
    ----------
    around : list of 9 ndarray, shape (4, ...)
        In ``NEIGHBOUR_OFFSETS`` order.

    Returns
    -------
    ndarray, shape (...)
    """
    v = around
    half = np.float32(0.5)
    largest = None
    for i, j in OPPOSITE_PAIRS:
        # Differences first, as for the gradient: a flat neighbourhood gives exactly 0.
        offset = ((v[0] - v[i]) + (v[0] - v[j])) * half
        squared = dot(offset, offset)
        largest = squared if largest is None else np.maximum(largest, squared)
    return np.sqrt(largest)


def image_gradients(image):
    """Sobel derivatives of an image, borders replicated.

    Parameters
    ----------
    image : ndarray of float, shape (H, W, C)

    Returns
    -------
    gx, gy : ndarray, shape (H, W, C)
    """
    gx, gy = sobel_gradients(neighbours(planes(image)))
    return np.moveaxis(gx, 0, -1), np.moveaxis(gy, 0, -1)


def gradient_magnitude(image):
    """Sobel magnitude of an image over all its channels.

    Parameters
    ----------
    image : ndarray of float, shape (H, W, C)

    Returns
    -------
    ndarray, shape (H, W)
    """
    gx, gy = image_gradients(image)
    return np.sqrt(np.sum(gx * gx + gy * gy, axis=-1))
