"""The one Sobel operator of the project: the passes' edge strength, the safe plan's edge
pixels and the evaluation's edge band all read it.

The kernel is divided by 8, so that a unit ramp gives 1; the magnitude is the Euclidean
norm over the channels of (gx, gy). At that scale the paper's ``sigma_e = 0.01`` separates
real edges (black/white gives ``e_p`` about 0.75) from noise; the raw kernel (64 times
larger ``e_p``) kept the gate open everywhere and smeared smooth gradients that a filter
had broken into bands (measured).
"""

import numpy as np

from .neighbourhood import dot, neighbours, planes

__all__ = ["sobel_gradients", "sobel_magnitude", "image_gradients", "gradient_magnitude"]


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
