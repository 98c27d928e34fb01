"""The filter's table averaged across each pixel where O is a ramp: the ramp lookup.

A point-wise filter ``F = f(O)`` applied to an antialiased image is not the antialiased image
of the filtered scene: a pixel's value is the box filter of the scene, and the box filter of
``f`` over a pixel whose scene is a ramp is the table averaged over the values the ramp takes
there, ``mean f(O + gx u + gy v)`` for ``u, v`` across the pixel. Where the table steps
(posterize, threshold, a steep curve) F shows a hard contour through O's smooth gradients,
where the reference shows one pixel of blend.

The two-colour model repairs edges, where a pixel holds two colours; the ramp lookup
repairs the rest, and each pixel takes it as far as the model does not act:
``R += (1 - beta) (mean f - f(O))``, with ``beta`` the model's confidence after the plan's
strength. Each channel's slope is limited as in MUSCL schemes, the minmod of its one-sided
differences (0 at a local extreme, so that a step beside the pixel is not read as a ramp
across it), and the table is sampled at :data:`RAMP_SAMPLES` squared points across the pixel,
averaged in encoded values (as F's own values are).

Only where F differs from a neighbour of the pixel and the table bends between the
pixel's samples (:data:`RAMP_BEND`): elsewhere the lookup adds next to nothing, and the
passes skip it (``ramp_lookup``). The backends run it for sRGB-encoded inputs only (its
difference is in encoded values); a shift key's clipping of its sum is no bend of its table.

Measured on the tuning half of the real-tools suite (the whole run, 920 cases, with the
plan's rules of ``aarecovery.plan.ramp``: 239 up by over 0.005, none down; photos under
point-wise filters 0.295 -> 0.339, docs/quality.md),
and before the two skips above on its photos under the point-wise tools with the calibrated
strength (96 px, edge-band error removed): PNG 0.309 -> 0.358 (58 cases,
52 up, 3 down, worst -0.07), JPEG 0.245 -> 0.276 (59 cases, 49 up, 3 down); the drawings,
scans and mixed scenes calibrated or read as compressed drawings or grained pages (286
cases) every family up, none down by more than 0.03 but the screenshot (-0.085 once).
Added where the model acts too (``R += mean f - f(O)`` everywhere), the photos gained less
(0.342) and the mixed scenes' text lost (0.589 -> 0.578): both models then count the same
blend. 2 x 2 samples gained less (0.345), 4 x 4 as much (0.354) but lost more on the grey
camera photo's dark coat, a step of 6 levels that the curve (G'MIC's ``-pow 3``) makes
steep (-0.14 against -0.07 with 3 x 3). Central differences instead of the minmod took a
pixel beside an edge for a ramp across it (camera -2.2); averaging in linear light moved the
affine maps' clipped pixels (autocontrast -0.26 to -1.5).
"""

from dataclasses import dataclass

import numpy as np

from .pure_colours import _KEY_CODES, EXTENSION_KEYS, SCALE_KEYS, SHIFT_KEYS, key_values, transfer_encoded

__all__ = ["RampTable", "RAMP_SAMPLES", "RAMP_BEND", "table_bends", "ramp_slopes", "ramp_delta", "ramp_lookup"]

#: Samples across the pixel per axis, at offsets ``(i + 0.5) / n - 0.5``: 3 x 3 (above).
RAMP_SAMPLES = 3
#: A pixel whose samples' keys span table bins whose bends (the table's second differences,
#: summed, encoded) are at most this takes no lookup: a table that is straight there
#: averages to f(O) across a symmetric ramp. Most of a threshold's or posterize's pixels
#: lie between its steps, and a smooth curve bends less than this over a few bins, so the
#: passes skip the nine samples there (see ``table_bends``).
RAMP_BEND = 1.0 / 255


@dataclass(frozen=True)
class RampTable:
    """The filter's table the ramp lookup averages.

    Attributes
    ----------
    key : str
        One of :data:`~aarecovery.spec.pure_colours.EXTENSION_KEYS`: how the table is
        indexed.
    table : ndarray of float32, shape (256, 3)
        Encoded output colour per bin of the key, read with linear interpolation between
        bin centres, as the pure colours read it (the same table when the plan has both).
    """

    key: str
    table: np.ndarray

    def __post_init__(self):
        if self.key not in EXTENSION_KEYS:
            raise ValueError(f"ramp table key {self.key!r} is not one of {EXTENSION_KEYS}")
        if np.shape(self.table) != (256, 3):
            raise ValueError(f"ramp table has shape {np.shape(self.table)}, expected (256, 3)")

    @property
    def key_code(self):
        """int: the GL define ``TABLE_KEY`` (``PureColourPrior.key_code``)."""
        return _KEY_CODES[self.key]


def table_bends(table, beyond=0.0):
    """The table's bends, summed from its first bin:
    ``S[i] = sum(max(|t[j+1] - 2 t[j] + t[j-1]| - beyond, 0), 0 < j <= i)``.

    The bends of a piecewise-linear table lie at its bin centres; those between keys whose
    positions (``key * 256 - 0.5``) are ``a <= b`` sum to at most
    ``S[ceil(b)] - S[max(floor(a) - 1, 0)]``.

    Parameters
    ----------
    table : ndarray of float32, shape (256, 3)
    beyond : float
        Bends up to this are not counted (the passes count every bend: 0).

    Returns
    -------
    ndarray of float32, shape (256, 3)
    """
    table = np.asarray(table, np.float64)
    bends = np.zeros_like(table)
    bends[1:-1] = np.maximum(np.abs(table[2:] - 2 * table[1:-1] + table[:-2]) - beyond, 0)
    return np.cumsum(bends, axis=0).astype(np.float32)


def _positions(keys):
    return np.clip(keys * np.float32(256) - np.float32(0.5), 0, 255).astype(np.float32)


def _bend_between(low_keys, high_keys, key, bends):
    """The bends between each pixel's lowest and highest sample keys ``(3, N)``: shape (N,)."""
    low = np.maximum(np.floor(_positions(low_keys)).astype(np.intp) - 1, 0)
    high = np.ceil(_positions(high_keys)).astype(np.intp)
    if key == "channel":
        spans = [bends[high[c], c] - bends[low[c], c] for c in range(3)]
    elif key in SCALE_KEYS or key in SHIFT_KEYS:
        spans = [bends[high[0], 0] - bends[low[0], 0]]
    else:
        spans = [bends[high[0], c] - bends[low[0], c] for c in range(3)]
    return np.max(np.stack(spans), axis=0)


def _minmod(a, b):
    return np.where(a * b > 0, np.sign(a) * np.minimum(np.abs(a), np.abs(b)), np.float32(0)).astype(np.float32)


def ramp_slopes(encoded):
    """Each channel's limited slope along columns and rows: the minmod of the one-sided
    differences (the image's edge pixels repeated beyond it).

    Parameters
    ----------
    encoded : ndarray of float32, shape (H, W, 3)

    Returns
    -------
    along_x, along_y : ndarray of float32, shape (H, W, 3)
    """
    padded = np.pad(encoded, ((1, 1), (1, 1), (0, 0)), mode="edge")
    centre = padded[1:-1, 1:-1]
    along_x = _minmod(padded[1:-1, 2:] - centre, centre - padded[1:-1, :-2])
    along_y = _minmod(padded[2:, 1:-1] - centre, centre - padded[:-2, 1:-1])
    return along_x, along_y


def _opaque_cross(alpha):
    """Where a pixel and its four neighbours are opaque (the slopes read all five)."""
    padded = np.pad(alpha >= 1, 1, mode="edge")
    return (padded[1:-1, 1:-1] & padded[:-2, 1:-1] & padded[2:, 1:-1] & padded[1:-1, :-2]
            & padded[1:-1, 2:])


def ramp_delta(original_rgba, table):
    """The ramp lookup's change to f(O): the table averaged across each pixel, less f(O).

    Parameters
    ----------
    original_rgba : ndarray of float32, shape (H, W, 4)
        O as straight sRGB-encoded RGBA (the contract's colour).
    table : RampTable

    Returns
    -------
    ndarray of float32, shape (H, W, 3)
        Encoded; 0 where O is flat, at a local extreme in every channel, or not opaque
        around the pixel.
    """
    encoded = np.ascontiguousarray(original_rgba[..., :3], dtype=np.float32)
    shape = encoded.shape
    along_x, along_y = ramp_slopes(encoded)

    def transfer(colour):
        planes = np.ascontiguousarray(colour.reshape(-1, 3).T)
        return np.clip(transfer_encoded(planes, table.key, table.table), 0, 1).T.reshape(shape)

    offsets = ((np.arange(RAMP_SAMPLES, dtype=np.float32) + np.float32(0.5)) / np.float32(RAMP_SAMPLES)
               - np.float32(0.5))
    total = np.zeros(shape, np.float32)
    # The sum in the order the GL twin takes it: v (rows) outer, u (columns) inner.
    for v in offsets:
        for u in offsets:
            total += transfer(np.clip(encoded + along_x * u + along_y * v, 0, 1).astype(np.float32))
    delta = total * np.float32(1.0 / RAMP_SAMPLES ** 2) - transfer(encoded)
    # Every sample lies within `reach` of O per channel, and every key rises with each
    # channel: the samples' keys lie between those of the two corners.
    reach = (np.abs(along_x) + np.abs(along_y)) * np.float32(abs(offsets[0]))
    corners = [np.ascontiguousarray(np.clip(encoded + sign * reach, 0, 1).astype(np.float32).reshape(-1, 3).T)
               for sign in (-1, 1)]
    bend = _bend_between(key_values(corners[0], table.key), key_values(corners[1], table.key), table.key,
                         table_bends(table.table)).reshape(shape[:2])
    ramp = ((np.any(along_x != 0, axis=-1) | np.any(along_y != 0, axis=-1)) & (bend > np.float32(RAMP_BEND))
            & _opaque_cross(original_rgba[..., 3]))
    return np.where(ramp[..., None], delta, np.float32(0)).astype(np.float32)


def _varies(filtered_rgba):
    """Where a pixel of F differs from one of its four neighbours (the image's edge pixels
    repeated beyond it)."""
    padded = np.pad(filtered_rgba, ((1, 1), (1, 1), (0, 0)), mode="edge")
    centre = padded[1:-1, 1:-1]
    return np.any((padded[:-2, 1:-1] != centre) | (padded[2:, 1:-1] != centre) | (padded[1:-1, :-2] != centre)
                  | (padded[1:-1, 2:] != centre), axis=-1)


def ramp_lookup(result, original_rgba, filtered_rgba, beta, table):
    """Add the ramp lookup to a straight result, as far as the model did not act.

    Only where F differs from a neighbour of the pixel: a monotone table that bends across a
    pixel's samples steps between its neighbours too, so F is flat only where the lookup
    has little to add, and the passes need not visit F's flat blocks (measured: the tuning
    half's gain kept whole, below).

    Parameters
    ----------
    result : ndarray of float32, shape (H, W, 4)
        Straight sRGB-encoded RGBA (``from_working_space`` of an sRGB-encoded input).
    original_rgba, filtered_rgba : ndarray of float32, shape (H, W, 4)
        O and F, straight sRGB-encoded RGBA (the contract's colour).
    beta : ndarray of float32, shape (H, W)
        The model's confidence (after the plan's strength), 0 where it did not act.
    table : RampTable

    Returns
    -------
    ndarray of float32, shape (H, W, 4)
        `result` with ``(1 - beta) * ramp_delta`` added to its colour, clipped to [0, 1];
        untouched where the delta is 0 or F is flat around the pixel.
    """
    delta = ramp_delta(original_rgba, table)
    out = result.copy()
    moved = np.any(delta != 0, axis=-1) & _varies(filtered_rgba)
    weight = (np.float32(1) - beta.astype(np.float32))[..., None]
    out[..., :3] = np.where(moved[..., None], np.clip(result[..., :3] + weight * delta, 0, 1), result[..., :3])
    return out
