"""The two-colour blend model of O at each pixel and its confidence (section 3.1, equation 5).

Decisions where the paper is ambiguous, each measured against supersampled ground truth
(``docs/quality.md``):

* The centre is itself a candidate extreme (t = 0, d = 0), so ``(a, b) = argmax(t_i - t_j)``
  is simply ``a = argmax t, b = argmin t`` over candidates within ``3 sigma_d`` of the
  line, the first of equal candidates in ``NEIGHBOUR_OFFSETS`` order winning; then a is the
  extreme earlier in that order (the direction's sign is arbitrary).
* Roweis EM starts from the deviation of the neighbour farthest from the mean: a fixed start
  such as (1, 1, 1) is orthogonal to a red/green edge and never leaves it.
* ``e_p = |grad O| |grad F|`` with the Sobel of ``aarecovery.spec.sobel``.
* The paper's extra rule "if e_p > 3 sigma_e set beta_p = 0" is not applied: read literally it
  switches recovery off on every real edge (pooled error reduction 0.79 -> 0.02), and the
  other readings cost up to 1 dB. Equation 5 alone is used.
* If ``c_a`` and ``c_b`` coincide, alpha is undefined and set to 0.5 (beta is 0 there anyway).
* The safe default only (``best_pair``): where the principal line misses the centre, the
  pair of neighbours that explains it best replaces the line's extremes (:func:`best_pair`).
  Three colours meet in a map's contour lines over its tints and at a drawing's corners, and
  the line through the nine colours passes between them. Measured on the real-tools suite's
  tuning half (``docs/quality.md``); the paper's method keeps its extremes.
* Where the edge strength is exactly 0 (O or F flat around the pixel), beta is exactly 0
  and the model is never used; it is not fitted there (alpha 0.5, extremes at the centre,
  residual 0). The GL pass skips those pixels, which most of a filtered image is.
"""

from dataclasses import dataclass

import numpy as np

from .neighbourhood import dot, neighbours, planes
from .sobel import sobel_magnitude

__all__ = ["BlendModel", "edge_strength", "fit_paper_model", "principal_direction", "fit_extremes", "best_pair", "coverage",
           "confidence", "untouched_factor", "toward_original", "toward_weight", "UNTOUCHED_EXTREMES", "KEPT_EXTREMES"]

_EM_ITERATIONS = 3
_TINY = np.float32(1e-12)
_FAINT = np.float32(1e-30)
#: How much further from the mean a neighbour must be to replace the EM's start: quantised
#: images hold exact ties (two neighbours 819 / (81 * 255^2) from the mean), and float
#: rounding, which differs between NumPy and a GPU (fused multiply-adds, a reciprocal for a
#: division), broke them differently: the unconverged direction, and with it the extremes,
#: differed on 158 of 27 M samples of a 3000 x 3000 photo-like pair, by up to 37/255. Spreads
#: equal within this share of the larger (or within SPREAD_TIE_FLOOR) keep the first.
SPREAD_TIE = np.float32(1e-3)
#: The same tie for spreads too small for a relative margin: rounding of the mean is absolute.
SPREAD_TIE_FLOOR = np.float32(1e-6)
#: :func:`untouched_factor` applies only where F moved both extremes of the pixel's model by
#: at most this (largest working-space channel): a smoothing filter moves them by a few levels,
#: a colour replacement (the built-in suite's, read as smoothing on drawings) swaps a hue
#: there and leaves the blended pixel between them as O had it, which is its damage. Tuning
#: half, PNG drawings under the three smoothing filters (30 cases, with UNTOUCHED_SPAN): 0.586
#: without the factor, 0.585 at 0, 0.591 at 0.05, 0.600 at 0.1, 0.604 at 0.2 and above;
#: built-in quick suite, its colour replacement on the five drawings read as smoothing: 0.770
#: without the factor, 0.769 at 0.1, shapes in sRGB 0.879 -> 0.842 at 0.2, all five 0.185
#: without the bound.
UNTOUCHED_EXTREMES = 0.1
#: Towards O (:func:`toward_original`), F's colour at each of the model's extremes may lie at
#: most this far from O's colour line between them (working space, Euclidean).
KEPT_EXTREMES = 0.1
#: :func:`best_pair` looks for a better pair where the principal line misses the centre by
#: more than this share of ``sigma_d``. Measured with a NumPy prototype of the search (which
#: the calibration used too, and without its near-tie rule) on the tuning half's 104 PNG cases
#: of eight scenes (five drawings, two photos, the poster) under eight point-wise tools: mean
#: error reduction 0.777 without the search, 0.784 at 1, 0.786 at 0.5, 0.790 at 0.2, 0.791 at
#: 0.1 (no case down), 0.790 at 0 (every fitted pixel: 18 cases down, the star burst under
#: GEGL's levels 0.689 -> 0.631, its smooth spokes' blends explained by near neighbours).
BEST_PAIR_MISS = 0.1
#: A pair replaces the line's extremes only where it misses the centre by at most this share
#: of the line's miss (the same prototype at a miss threshold of 0.5: 0.786 here, 0.785 at
#: 0.25, 0.787 at 0.8 with an icon down).
BEST_PAIR_GAIN = 0.5
#: ... and spans at least this share of the line's extremes' distance, so that two near
#: neighbours of a ramp do not explain its centre as a blend of themselves (the same: 0.787
#: at 0.25, 0.783 at 0.8).
BEST_PAIR_SPAN = 0.5
#: ... and holds the centre as a blend strictly inside the pair: a coverage within this of 0
#: or 1 is one of the pair's colours, not a blend.
BEST_PAIR_COVERAGE = 0.02
#: A pair replaces the best so far only where its squared miss of the centre is less by this
#: share (or by BEST_PAIR_TIE_FLOOR): pairs of equal colours tie exactly, and float rounding,
#: which differs between NumPy and a GPU, must not pick between near ties differently. Two
#: pairs whose misses were 1.2e-6 apart at 1.26e-3 (a 16-bit pair) swapped places between the
#: backends at a tie of 1e-3 and 1e-6. Within the floor (a miss of 3e-3, under an 8-bit step)
#: the pairs are equally good and the first stands.
BEST_PAIR_TIE = 2e-2
BEST_PAIR_TIE_FLOOR = 1e-5


@dataclass
class BlendModel:
    """The two-colour blend model fitted at every pixel of O.

    Attributes
    ----------
    alpha : ndarray of float32, shape (H, W)
        Coverage of colour ``c_a`` in the centre pixel.
    beta : ndarray of float32, shape (H, W)
        Confidence in the model, equation 5.
    index_a, index_b : ndarray of uint8, shape (H, W)
        Positions of the extreme colours as indices into ``NEIGHBOUR_OFFSETS``.
    residual : ndarray of float32, shape (H, W)
        Distance ``d_p`` of the centre colour from its best blend, equation 2.
    edge : ndarray of float32, shape (H, W)
        Edge strength ``e_p`` from :func:`edge_strength`.
    pure_a, pure_b : ndarray of bool, shape (H, W), or None
        With a pure-colour prior (``aarecovery.spec.pure_colours``): where the extreme was a
        thin feature's partial colour, and the Jacobi step blends the fixed colour below
        instead of R at the extreme pixel. None without a prior.
    fixed_a, fixed_b : ndarray of float32, shape (H, W, 4), or None
        The filtered pure colours (working space), meaningful where `pure_a` / `pure_b`.
    colour_a, colour_b : ndarray of float32, shape (H, W, 4), or None
        The pure colours themselves (working space), where `pure_a` / `pure_b`: what the safe
        plan checks its choice of table on.
    toward : ndarray of float32, shape (H, W), or None
        Under a smoothing filter (:func:`toward_original`): the weight ``g`` of O's own colour
        in every Jacobi step, which `beta` already excludes; None: none.
    original : ndarray of float32, shape (H, W, 4), or None
        O in the working space, where `toward` is given.
    """

    alpha: np.ndarray
    beta: np.ndarray
    index_a: np.ndarray
    index_b: np.ndarray
    residual: np.ndarray
    edge: np.ndarray
    pure_a: np.ndarray = None
    pure_b: np.ndarray = None
    fixed_a: np.ndarray = None
    fixed_b: np.ndarray = None
    colour_a: np.ndarray = None
    colour_b: np.ndarray = None
    toward: np.ndarray = None
    original: np.ndarray = None

    #: The fields that every model has (the pure-colour ones exist only with a prior).
    MAP_FIELDS = ("alpha", "beta", "index_a", "index_b", "residual", "edge")


def edge_strength(original, filtered):
    """Edge strength ``e_p``: the product of the Sobel magnitudes of O and F.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 4)
        Working-space images.

    Returns
    -------
    ndarray of float32, shape (H, W)
    """
    return (sobel_magnitude(neighbours(planes(original)))
            * sobel_magnitude(neighbours(planes(filtered)))).astype(np.float32)


def principal_direction(colours):
    """First principal direction of 9 colours per pixel, as unit vectors ``(4, N)``.

    Roweis' EM for one component without noise alternates ``z = Y x / |x|^2`` and
    ``x = Y^T z / |z|^2``, which is ``x <- Y^T Y x`` up to scale: power iteration on the 4x4
    scatter matrix. Forming the matrix once costs 10 products per neighbour instead of 16
    per neighbour per iteration, which matters in the GL pass. The start is the neighbour
    farthest from the mean; each step is normalised so that faint neighbourhoods do not
    underflow.
    """
    total = colours[0].copy()
    for colour in colours[1:]:
        total += colour
    mean = total / np.float32(9)
    deviations = [colour - mean for colour in colours]
    # The first neighbour of largest spread; a later one replaces it only when further by
    # more than a tie (SPREAD_TIE), as in the GL pass.
    x = deviations[0].copy()
    farthest = dot(x, x)
    for y in deviations[1:]:
        spread = dot(y, y)
        further = spread > farthest + np.maximum(farthest * SPREAD_TIE, SPREAD_TIE_FLOOR)
        np.copyto(farthest, spread, where=further)
        np.copyto(x, y, where=further)
    scatter = {}
    for j in range(4):
        for k in range(j, 4):
            total = deviations[0][j] * deviations[0][k]
            for y in deviations[1:]:
                total += y[j] * y[k]
            scatter[j, k] = scatter[k, j] = total
    for _ in range(_EM_ITERATIONS):
        x = np.stack([scatter[j, 0] * x[0] + scatter[j, 1] * x[1] + scatter[j, 2] * x[2] + scatter[j, 3] * x[3]
                      for j in range(4)])
        x = x / np.sqrt(dot(x, x) + _FAINT)
    return x


def fit_extremes(colours, sigma_d, best=False):
    """Extremes, coverage and residual on neighbourhood columns.

    Parameters
    ----------
    colours : list of 9 ndarray of float32, shape (4, N)
        O's neighbourhoods as columns, in ``NEIGHBOUR_OFFSETS`` order.
    sigma_d : float
    best : bool
        Where the principal line misses the centre, look for a better pair of neighbours
        (:func:`best_pair`; the safe default).

    Returns
    -------
    alpha, residual : ndarray of float32, shape (N,)
    index_a, index_b : ndarray of uint8, shape (N,)
    colour_a, colour_b : ndarray of float32, shape (4, N)
    """
    centre = colours[0]
    direction = principal_direction(colours)
    reach = np.float32(3) * np.float32(sigma_d)
    # Extremes along the line through the centre among candidates within 3 sigma_d of it; the
    # centre starts as both (t = 0), and only a strictly larger t replaces, so the first of
    # equal candidates wins.
    count = centre.shape[1:]
    index_a = np.zeros(count, np.uint8)
    index_b = np.zeros(count, np.uint8)
    t_max = np.zeros(count, np.float32)
    t_min = np.zeros(count, np.float32)
    colour_a, colour_b = centre.copy(), centre.copy()
    for i, colour in enumerate(colours[1:], start=1):
        offset = colour - centre
        along = dot(offset, direction)
        # Squared distance to the line by Pythagoras (direction is a unit vector).
        near = dot(offset, offset) - along * along < reach * reach
        higher = near & (along > t_max)
        lower = near & (along < t_min)
        np.copyto(t_max, along, where=higher)
        np.copyto(t_min, along, where=lower)
        np.copyto(index_a, i, where=higher)
        np.copyto(index_b, i, where=lower)
        np.copyto(colour_a, colour, where=higher)
        np.copyto(colour_b, colour, where=lower)
    # The principal direction's sign is arbitrary, and where two neighbours are equally far
    # from the mean (a straight edge's N and S) rounding picks it: -x swaps a and b, and alpha
    # becomes 1 - alpha, the same model. Naming the extremes in neighbour order makes the
    # model, and its maps, the same whatever the sign (GL and NumPy had swapped extremes on
    # 2 of 40000 pixels of a synthetic scene).
    swap = index_a > index_b
    index_a, index_b = np.where(swap, index_b, index_a), np.where(swap, index_a, index_b)
    colour_a, colour_b = np.where(swap, colour_b, colour_a), np.where(swap, colour_a, colour_b)
    alpha = coverage(centre, colour_a, colour_b)
    miss = alpha * colour_a + (1 - alpha) * colour_b - centre
    residual = np.sqrt(dot(miss, miss)).astype(np.float32)
    if best:
        return best_pair(colours, sigma_d, alpha, residual, index_a, index_b, colour_a, colour_b)
    return alpha, residual, index_a, index_b, colour_a, colour_b


def best_pair(colours, sigma_d, alpha, residual, index_a, index_b, colour_a, colour_b):
    """Where the principal line misses the centre, the pair of neighbours that explains it best.

    Where the line's extremes miss the centre by more than ``BEST_PAIR_MISS * sigma_d``, every
    pair of the eight neighbours (in ``NEIGHBOUR_OFFSETS`` order, the first of near ties
    winning: :data:`BEST_PAIR_TIE`) that spans at least :data:`BEST_PAIR_SPAN` of the
    extremes' distance and holds the centre strictly inside (:data:`BEST_PAIR_COVERAGE`) is
    tried; the one that misses it least replaces the extremes where it misses by at most
    :data:`BEST_PAIR_GAIN` of the line's miss. At a pixel beside a junction of three colours
    the line through the nine passes between them, and the pixel is a blend of two.

    Parameters
    ----------
    colours : list of 9 ndarray of float32, shape (4, N)
    sigma_d : float
    alpha, residual, index_a, index_b, colour_a, colour_b
        The principal line's model, as :func:`fit_extremes` returns it.

    Returns
    -------
    The same six, with the better pairs in place (``index_a < index_b`` still).
    """
    centre = colours[0]
    missed = residual > np.float32(BEST_PAIR_MISS) * np.float32(sigma_d)
    if not missed.any():
        return alpha, residual, index_a, index_b, colour_a, colour_b
    chosen = np.nonzero(missed)[0]
    near = [colour[:, chosen] for colour in colours]
    extremes = colour_a[:, chosen] - colour_b[:, chosen]
    least_span = np.float32(BEST_PAIR_SPAN * BEST_PAIR_SPAN) * dot(extremes, extremes)
    largest_miss = np.float32(BEST_PAIR_GAIN) * residual[chosen]
    best_miss_sq = largest_miss * largest_miss
    best_alpha = alpha[chosen].copy()
    best_a, best_b = index_a[chosen].copy(), index_b[chosen].copy()
    found = np.zeros(chosen.shape, bool)
    low, high = np.float32(BEST_PAIR_COVERAGE), np.float32(1 - BEST_PAIR_COVERAGE)
    # Each pair's squared miss measured as the line's is (the blend minus the centre), as the GL
    # pass does: by Pythagoras from dot products it cancelled to 3e-8, and near ties fell on
    # either side between the backends.
    for i in range(1, 9):
        for j in range(i + 1, 9):
            span = near[i] - near[j]
            span_sq = dot(span, span)
            wide = span_sq >= least_span
            pair_alpha = dot(near[0] - near[j], span) / np.where(wide, span_sq, np.float32(1))
            blend = pair_alpha * near[i] + (1 - pair_alpha) * near[j] - near[0]
            miss_sq = dot(blend, blend)
            better = (wide & (pair_alpha > low) & (pair_alpha < high)
                      & (miss_sq < best_miss_sq - np.maximum(best_miss_sq * np.float32(BEST_PAIR_TIE),
                                                              np.float32(BEST_PAIR_TIE_FLOOR))))
            np.copyto(best_miss_sq, miss_sq, where=better)
            np.copyto(best_alpha, pair_alpha, where=better)
            np.copyto(best_a, i, where=better)
            np.copyto(best_b, j, where=better)
            found |= better
    alpha, residual = alpha.copy(), residual.copy()
    index_a, index_b = index_a.copy(), index_b.copy()
    colour_a, colour_b = colour_a.copy(), colour_b.copy()
    at = chosen[found]
    taken = np.arange(at.size)
    stacked = np.stack(near)[:, :, found]  # (9, 4, n)
    pair_a = stacked[best_a[found], :, taken].T
    pair_b = stacked[best_b[found], :, taken].T
    alpha[at] = best_alpha[found]
    residual[at] = np.sqrt(best_miss_sq[found])
    index_a[at], index_b[at] = best_a[found], best_b[found]
    colour_a[:, at], colour_b[:, at] = pair_a, pair_b
    return alpha, residual, index_a, index_b, colour_a, colour_b


def coverage(centre, colour_a, colour_b):
    """Coverage alpha of `colour_a` that best explains `centre` (equation 2), in [0, 1]."""
    span = colour_a - colour_b
    span_sq = dot(span, span)
    defined = span_sq > _TINY
    alpha = np.where(defined, dot(centre - colour_b, span) / np.where(defined, span_sq, 1), 0.5)
    return np.clip(alpha, 0, 1).astype(np.float32)


def confidence(residual, edge, sigma_d, sigma_e, strength):
    """Equation 5, ``beta = G(d_p, sigma_d) (1 - G(e_p, sigma_e))``, times `strength`."""
    residual_ratio = residual / np.float32(sigma_d)
    edge_ratio = edge / np.float32(sigma_e)
    return scaled_confidence(np.exp(-residual_ratio * residual_ratio) * (1 - np.exp(-edge_ratio * edge_ratio)),
                             strength)


def scaled_confidence(beta, strength):
    """``beta`` times `strength` as :func:`confidence` applies it (1 leaves it bit-identical):
    the model fitted at strength 1 gives any strength's ``beta`` exactly (the safe plan's
    calibration fits once for all its strengths)."""
    if strength != 1.0:
        beta = beta * np.float32(strength)
    return beta.astype(np.float32)


def fit_paper_model(original, filtered, sigma_d, sigma_e, strength=1.0, only=None, best=False):
    """The paper's model at every pixel of O: extremes, coverage, residual, confidence.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 4)
        O and F in the working space.
    sigma_d : float
        Colour-line distance scale: neighbours further than ``3 sigma_d`` from the line are
        not candidate extremes, and the residual is weighted by ``G(d_p, sigma_d)``.
    sigma_e : float
        Edge-strength scale of the confidence ``1 - G(e_p, sigma_e)``.
    strength : float
        Multiplies the confidence ``beta`` (the safe default's per-image repair strength);
        1 is the paper's method and leaves ``beta`` bit-identical.
    only : ndarray of bool, shape (H, W), optional
        Fit these pixels only, the others keep the unfitted model (a caller that reads a
        few rows, as the safe plan's blend-space test does); each fitted pixel's model is
        the same, bit for bit, as without it.
    best : bool
        Where the principal line misses the centre, a better pair of neighbours
        (:func:`best_pair`): the safe default; False is the paper's model.

    Returns
    -------
    BlendModel
    """
    colours = neighbours(planes(original))
    edge = (sobel_magnitude(colours) * sobel_magnitude(neighbours(planes(filtered)))).astype(np.float32)
    # Where e_p == 0 beta is exactly 0 and the model unused: fit only the other pixels (most
    # of a thresholded or posterized image is flat), as (4, N) columns.
    fitted = edge > 0
    if only is not None:
        fitted &= only
    alpha = np.full(edge.shape, 0.5, np.float32)
    beta = np.zeros(edge.shape, np.float32)
    residual = np.zeros(edge.shape, np.float32)
    index_a = np.zeros(edge.shape, np.uint8)
    index_b = np.zeros(edge.shape, np.uint8)
    if fitted.any():
        col_alpha, col_residual, col_a, col_b, _, _ = fit_extremes([colour[:, fitted] for colour in colours],
                                                                   sigma_d, best)
        alpha[fitted] = col_alpha
        beta[fitted] = confidence(col_residual, edge[fitted], sigma_d, sigma_e, strength)
        residual[fitted] = col_residual
        index_a[fitted] = col_a
        index_b[fitted] = col_b
    return BlendModel(alpha, beta, index_a, index_b, residual, edge)


def _moved_extremes(change, index_a, index_b):
    """float ``(H, W)``: the larger of `change` (F's largest channel change from O) at the two
    extremes of each pixel's model."""
    near = np.stack(neighbours(change[None]))[:, 0]
    return np.maximum(np.take_along_axis(near, index_a[None].astype(np.intp), 0)[0],
                      np.take_along_axis(near, index_b[None].astype(np.intp), 0)[0])


def _off_the_line(original, filtered, index_a, index_b):
    """float32 ``(H, W)``: how far F's colour at either extreme of each pixel's model lies from
    O's colour line between the two extremes (the segment; working space, Euclidean)."""
    def at(image, index):
        near = np.stack(neighbours(planes(image)))
        return np.take_along_axis(near, index[None, None].astype(np.intp), 0)[0]

    colour_a, colour_b = at(original, index_a), at(original, index_b)
    span = colour_a - colour_b
    span_sq = dot(span, span)
    defined = span_sq > _TINY

    def miss(colour):
        t = np.where(defined, dot(colour - colour_b, span) / np.where(defined, span_sq, 1), 0)
        off = colour - (colour_b + np.clip(t, 0, 1).astype(np.float32) * span)
        return np.sqrt(dot(off, off))

    return np.maximum(miss(at(filtered, index_a)), miss(at(filtered, index_b))).astype(np.float32)


def untouched_factor(original, filtered, index_a, index_b, untouched_span):
    """float32 ``(H, W)``: the factor of ``beta`` where a smoothing filter left O's pixel as it was.

    A smoothstep from 0 where F's pixel is O's to 1 where some channel (of the working space,
    alpha included) changed by `untouched_span` or more (``aarecovery.plan.smoothing``), where
    F moved both extremes of the pixel's model by at most :data:`UNTOUCHED_EXTREMES`; 1
    elsewhere.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 4)
        O and F in the working space.
    index_a, index_b : ndarray of uint8, shape (H, W)
        The model's extremes (:class:`BlendModel`).
    untouched_span : float
        Above 0.
    """
    change = np.abs(filtered - original).max(axis=-1)
    moved = _moved_extremes(change, index_a, index_b)
    t = np.clip(change / np.float32(untouched_span), 0, 1).astype(np.float32)
    return np.where(moved <= UNTOUCHED_EXTREMES, t * t * (np.float32(3) - np.float32(2) * t),
                    np.float32(1)).astype(np.float32)


def toward_weight(gate):
    """The weight of O's own colour towards O (:func:`toward_original`): the largest gate of
    drawn content over the pixel's 3 x 3 neighbourhood (borders replicated).

    The pixels that move are the edge pixels between a drawing's flat colours, which are
    blends that recur nowhere: the gate reads them as less drawn than the flat colours and the
    ink beside them, which are the model's extremes there. Measured on the real-tools suite's
    tuning half (PNG, the three smoothing filters), against the pixel's own gate: 39 cases up,
    2 down by at most 0.003 (the icons under G'MIC's bilateral filter): the star burst under
    OpenCV's bilateral filter 0.918 -> 0.987, the map 0.812 -> 0.938, the mixed scenes' text
    and graphics +0.01 to +0.03 with their photo regions unchanged; drawings 0.832 -> 0.836,
    neighbourhood filters on drawings 0.803 -> 0.820, F's flat paper of the scans untouched.
    The 5 x 5 neighbourhood added little more (25 cases moved, by 0.006 on average; the memo
    under OpenCV's bilateral filter fell 0.790 -> 0.776).

    Parameters
    ----------
    gate : ndarray of float32, shape (H, W)
        The gate of drawn content (``aarecovery.spec.local_plan.LocalStrength.gate``; where
        the pure colours' gate leaves the drawn ink out, the larger of it and
        ``LocalStrength.kept_ink``, the ink where F kept O's contrast).

    Returns
    -------
    ndarray of float32, shape (H, W)
    """
    return np.maximum.reduce(neighbours(gate[None])).astype(np.float32)[0]


def toward_original(model, original, filtered, weight):
    """Move `model`'s edge pixels towards O's own colour by `weight`: a smoothing filter.

    A smoothing filter that keeps O's flat colours (a bilateral or edge-preserving filter on
    text and drawings) changes nothing but the antialiased edges between them, and its
    reference (the scene filtered at a higher resolution) keeps the scene's flat areas and
    hard edges: there the blend of F's colours with O's coverage is O's own pixel, whatever
    the number of colours the pixel mixes, where the paper's model sees two and is
    confident only where they fit (``aarecovery.plan.smoothing`` has the measurements).
    Each Jacobi step becomes ``beta' (alpha R[p_a] + (1 - alpha) R[p_b]) + (1 - beta' - g) F
    + g O`` with ``beta' = (1 - g) beta``: ``(1 - g)`` times the paper's step plus ``g O``.
    ``g`` is `weight` (:func:`toward_weight`: the local plan's gate of drawn content, flat
    regions read as drawn or a stroke's ink recurring exactly nearby, where the pure colours'
    gate leaves the ink out (text over a photo) the ink only where F kept O's contrast
    (``LocalStrength.kept_ink``), its largest over the pixel's 3 x 3 neighbourhood) at the
    pixels with an edge strength above 0 where F's colour at both extremes of the model lies
    within :data:`KEPT_EXTREMES` of O's colour line between them (working space): where F moved
    one off that line it changed a colour (a colour replacement, which the smoothing test also
    reads as smoothing), and O's pixel would bring the old colour back; 0 elsewhere. Along the
    line is what a smoothing filter moves them: it mixes a thin line with its surroundings.
    With F's change at the extremes bound instead (by the same 0.1, largest channel), the
    tuning half's drawings under the three smoothing filters kept up to 0.69 of their edge
    error where O's own pixels keep none (the map under OpenCV's edge-preserving filter).
    Measured on the tuning half against that bound: 25 cases up, 2 down by 0.001 (the map
    under OpenCV's edge-preserving filter 0.310 -> 0.936, the manga under G'MIC's bilateral
    filter 0.789 -> 0.971), and the built-in star under the bilateral filter 0.898 -> 0.996;
    without any bound (the plan's tests alone: ``plan.smoothing.FLAT_COLOUR_MOVE``) a little
    more (26 up, none down), but a colour changed only where it is never flat would go back.

    Parameters
    ----------
    model : BlendModel
        Changed in place: `beta`, `toward` and `original`.
    original, filtered : ndarray of float32, shape (H, W, 4)
        O and F in the working space.
    weight : ndarray of float32, shape (H, W)
        From 0 (F's repair as before) to 1 (O's pixel).
    """
    off_line = _off_the_line(original, filtered, model.index_a, model.index_b)
    g = np.where((model.edge > 0) & (off_line <= KEPT_EXTREMES), weight, np.float32(0)).astype(np.float32)
    model.beta = ((np.float32(1) - g) * model.beta).astype(np.float32)
    model.toward = g
    model.original = original
    return model
