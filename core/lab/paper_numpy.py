"""The paper's method as a straightforward vectorised NumPy program: the yardstick of ``aarecovery bench --process``.

Yang, Sander, Lawrence and Hoppe, "Antialiasing Recovery" (2011), written the way a reader
of the paper would write it with NumPy, independently of the project's specification
(``aarecovery.spec``) and of its speed work: colours in linear light; at each pixel the
principal direction of its 3 x 3 neighbourhood by Roweis EM (power iteration); the two
extremes along the line through the centre among the neighbours within 3 sigma_d of it;
coverage alpha, residual d_p, edge strength ``e_p = |Sobel O| |Sobel F|``,
``beta = G(d_p, sigma_d) (1 - G(e_p, sigma_e))``; Jacobi iterations of equation 6 from
``R = F``. The neighbourhoods are processed in bands of rows so that a 4096 x 4096 pair
needs about 1 GB, not the 9 x 3 floats per pixel of a whole-image stack.

Run as a process: ``python -m aarecovery.lab.paper_numpy ORIGINAL FILTERED -o OUTPUT``
(8-bit RGB files, read and written with :mod:`aarecovery.io`, as ``aarecovery recover``
reads and writes them, so that a comparison of the two measures the method's work).
"""

import argparse
import sys

import numpy as np

from ..params import ITERATIONS, SIGMA_D, SIGMA_E

__all__ = ["recover_paper", "main"]

# The centre first, then the 4-neighbours, then the diagonals: ties go to the nearest.
_OFFSETS = ((0, 0), (-1, 0), (0, -1), (0, 1), (1, 0), (-1, -1), (-1, 1), (1, -1), (1, 1))
_BAND_ROWS = 256


def _to_linear(encoded):
    return np.where(encoded <= 0.04045, encoded / 12.92, ((encoded + 0.055) / 1.055) ** 2.4).astype(np.float32)


def _to_encoded(linear):
    linear = np.clip(linear, 0, 1)
    return np.where(linear <= 0.0031308, linear * 12.92, 1.055 * linear ** (1 / 2.4) - 0.055)


def _sobel_magnitude(padded, rows, width):
    """|Sobel| / 8 of the band `rows` of an edge-padded image, the norm over the channels."""
    def at(dy, dx):
        return padded[rows.start + 1 + dy:rows.stop + 1 + dy, 1 + dx:1 + dx + width]
    gx = (at(-1, 1) + 2 * at(0, 1) + at(1, 1) - at(-1, -1) - 2 * at(0, -1) - at(1, -1)) / 8
    gy = (at(1, -1) + 2 * at(1, 0) + at(1, 1) - at(-1, -1) - 2 * at(-1, 0) - at(-1, 1)) / 8
    return np.sqrt((gx * gx + gy * gy).sum(axis=-1))


def _fit_band(o_padded, f_padded, rows, width, sigma_d, sigma_e):
    """alpha, beta and the extremes' neighbour indices for the rows `rows`."""
    c = np.stack([o_padded[rows.start + 1 + dy:rows.stop + 1 + dy, 1 + dx:1 + dx + width] for dy, dx in _OFFSETS])
    y = c - c.mean(axis=0)
    scatter = np.einsum("nhwi,nhwj->hwij", y, y)
    # Roweis EM for one component, started at the neighbour farthest from the mean. In 8-bit
    # neighbourhoods two neighbours are often equally far; three EM steps do not converge, so
    # the tie decides the extremes. A later neighbour wins only when further by more than
    # 0.1% (or 1e-6), the rule the project's passes use, so that the two agree on such ties.
    spread = (y * y).sum(axis=-1)
    farthest = np.zeros(spread.shape[1:], np.intp)
    largest = spread[0].copy()
    for n in range(1, len(spread)):
        further = spread[n] > largest + np.maximum(largest * 1e-3, 1e-6)
        farthest[further] = n
        largest[further] = spread[n][further]
    x = np.take_along_axis(y, farthest[None, ..., None], axis=0)[0]
    for _ in range(3):
        x = np.einsum("hwij,hwj->hwi", scatter, x)
        x /= np.sqrt((x * x).sum(axis=-1, keepdims=True)) + 1e-15
    offset = c - c[0]
    t = np.einsum("nhwi,hwi->nhw", offset, x)
    candidate = (offset * offset).sum(axis=-1) - t * t < (3 * sigma_d) ** 2
    a = np.argmax(np.where(candidate, t, -np.inf), axis=0)
    b = np.argmin(np.where(candidate, t, np.inf), axis=0)
    c_a = np.take_along_axis(c, a[None, ..., None], axis=0)[0]
    c_b = np.take_along_axis(c, b[None, ..., None], axis=0)[0]
    span = c_a - c_b
    span_sq = (span * span).sum(axis=-1)
    alpha = np.where(span_sq > 1e-12, np.clip(((c[0] - c_b) * span).sum(axis=-1) / np.maximum(span_sq, 1e-12), 0, 1),
                     0.5)
    miss = alpha[..., None] * c_a + (1 - alpha[..., None]) * c_b - c[0]
    residual_sq = (miss * miss).sum(axis=-1)
    edge = _sobel_magnitude(o_padded, rows, width) * _sobel_magnitude(f_padded, rows, width)
    beta = np.exp(-residual_sq / sigma_d ** 2) * (1 - np.exp(-(edge / sigma_e) ** 2))
    return alpha.astype(np.float32), beta.astype(np.float32), a, b


def recover_paper(original, filtered, sigma_d=SIGMA_D.default, sigma_e=SIGMA_E.default, iterations=ITERATIONS.default):
    """Recover `filtered` (8-bit RGB) from `original` by the paper's method; returns 8-bit RGB."""
    height, width = filtered.shape[:2]
    o = _to_linear(original[..., :3] / np.float32(255))
    f = _to_linear(filtered[..., :3] / np.float32(255))
    o_padded = np.pad(o, ((1, 1), (1, 1), (0, 0)), mode="edge")
    f_padded = np.pad(f, ((1, 1), (1, 1), (0, 0)), mode="edge")
    alpha = np.empty((height, width), np.float32)
    beta = np.empty((height, width), np.float32)
    index_a = np.empty((height, width), np.intp)
    index_b = np.empty((height, width), np.intp)
    for top in range(0, height, _BAND_ROWS):
        rows = slice(top, min(height, top + _BAND_ROWS))
        alpha[rows], beta[rows], a, b = _fit_band(o_padded, f_padded, rows, width, sigma_d, sigma_e)
        # Flat indices of the extremes, clamped at the border (replicated edges).
        offsets = np.asarray(_OFFSETS)
        row_index = np.arange(rows.start, rows.stop)[:, None]
        column_index = np.arange(width)[None, :]
        index_a[rows] = (np.clip(row_index + offsets[a, 0], 0, height - 1) * width
                         + np.clip(column_index + offsets[a, 1], 0, width - 1))
        index_b[rows] = (np.clip(row_index + offsets[b, 0], 0, height - 1) * width
                         + np.clip(column_index + offsets[b, 1], 0, width - 1))
    del o_padded, f_padded, o
    # Equation 6 by Jacobi iterations from R = F, reading the previous iterate.
    alpha, beta = alpha[..., None], beta[..., None]
    recovered = f
    for _ in range(iterations):
        flat = recovered.reshape(-1, 3)
        recovered = beta * (alpha * flat[index_a] + (1 - alpha) * flat[index_b]) + (1 - beta) * f
    return np.rint(_to_encoded(recovered) * 255).astype(np.uint8)


def main(argv=None):
    """``python -m aarecovery.lab.paper_numpy ORIGINAL FILTERED -o OUTPUT``; returns the exit status."""
    from ..io import read_image, write_image
    parser = argparse.ArgumentParser(prog="python -m aarecovery.lab.paper_numpy",
                                     description="The paper's method, straightforward NumPy, file to file.")
    parser.add_argument("original")
    parser.add_argument("filtered")
    parser.add_argument("-o", "--output", required=True)
    args = parser.parse_args(argv)
    original, filtered = (np.asarray(read_image(path)) for path in (args.original, args.filtered))
    if original.ndim != 3 or filtered.ndim != 3 or original.dtype != np.uint8 or filtered.dtype != np.uint8:
        parser.error("this yardstick reads 8-bit RGB files only")
    write_image(args.output, recover_paper(original, filtered))
    return 0


if __name__ == "__main__":
    sys.exit(main())
