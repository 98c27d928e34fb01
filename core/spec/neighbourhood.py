"""The 3x3 neighbourhood every pass reads, as shifted channel planes.

The passes work on channel planes, shape ``(C, H, W)``: NumPy is slow at reducing a last
axis of length 4 and fast at elementwise work on whole planes. Sums run in the GLSL
passes' order (left to right, neighbours in :data:`NEIGHBOUR_OFFSETS` order), so that
float rounding, and with it every argmax and threshold decision, is the same in both
backends. Borders replicate edge pixels.
"""

import numpy as np

__all__ = ["NEIGHBOUR_OFFSETS", "OPPOSITE_PAIRS", "planes", "neighbours", "dot"]

#: (row, column) offsets of the 3x3 neighbourhood in tie-breaking order: centre, N, W, E, S,
#: then the diagonals NW, NE, SW, SE. On a flat pixel beside an edge every neighbour ties;
#: preferring the centre, then the nearest neighbours, keeps R from copying a neighbour into
#: flat pixels (measured: unsharp mask and blur cases improved markedly over row-major order).
NEIGHBOUR_OFFSETS = ((0, 0), (-1, 0), (0, -1), (0, 1), (1, 0), (-1, -1), (-1, 1), (1, -1), (1, 1))
#: Indices into :data:`NEIGHBOUR_OFFSETS` of the neighbours opposite each other across the
#: centre: N/S, W/E, NW/SE, NE/SW.
OPPOSITE_PAIRS = ((1, 4), (2, 3), (5, 8), (6, 7))


def planes(image):
    """An image ``(H, W, C)`` as contiguous channel planes ``(C, H, W)``."""
    return np.ascontiguousarray(np.moveaxis(image, -1, 0))


def neighbours(image_planes):
    """The 9 neighbourhood images of channel planes, each ``(C, H, W)``, borders replicated.

    Parameters
    ----------
    image_planes : ndarray, shape (C, H, W)

    Returns
    -------
    list of 9 ndarray, shape (C, H, W)
        In :data:`NEIGHBOUR_OFFSETS` order (views into one padded copy).
    """
    height, width = image_planes.shape[1:]
    padded = np.pad(image_planes, ((0, 0), (1, 1), (1, 1)), mode="edge")
    return [padded[:, 1 + dy:1 + dy + height, 1 + dx:1 + dx + width] for dy, dx in NEIGHBOUR_OFFSETS]


def dot(a, b):
    """Per-pixel dot product of two 4-channel plane stacks, summed in GLSL's order."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
