"""The NumPy backend: the executable specification of every recovery pass.

Each function here is one pass, and the GL backend has a shader pass of the same name
(``shaders/<name>.frag``) that tests compare with it. All passes work on the *working
space*: float32 ``(H, W, 4)`` premultiplied RGBA whose colour is in the blend space (linear
light by default). Borders replicate edge pixels everywhere (neighbourhood, Sobel, Jacobi).

Decisions where the paper (Yang et al. 2011, sections 3.1-3.3) is ambiguous, each measured
against supersampled ground truth (see ``docs/quality.md`` and ``shared/notes/paper-notes.md``):

* The neighbourhood is ordered centre, 4-neighbours, diagonals, and extremes take the first
  of equal candidates: on a flat pixel beside an edge all ``t_i`` tie, and preferring a
  row-major neighbour would copy that neighbour into flat pixels.
* The centre is itself a candidate extreme (t = 0, d = 0), so ``(a, b) = argmax(t_i - t_j)``
  is simply ``a = argmax t, b = argmin t`` over candidates within ``3 sigma_d`` of the line.
* Roweis EM starts from the deviation of the neighbour farthest from the mean: a fixed start
  such as (1, 1, 1) is orthogonal to a red/green edge and never leaves it.
* Sobel is divided by 8 (a unit ramp gives 1), the magnitude is the Euclidean norm over all
  channels of (gx, gy), and ``e_p = |grad O| |grad F|``: the scale at which the paper's
  ``sigma_e = 0.01`` separates real edges (black/white gives 0.75) from noise.
* The paper's extra rule "if e_p > 3 sigma_e set beta_p = 0" is not applied: read literally it
  switches recovery off on every real edge (pooled error reduction 0.79 -> 0.02), and the
  other readings cost up to 1 dB. Equation 5 alone is used.
* If ``c_a`` and ``c_b`` coincide, alpha is undefined and set to 0.5 (beta is 0 there anyway).
* Where the edge strength is exactly 0 (O or F flat around the pixel), beta is exactly 0
  and the model is never used; it is not fitted there (alpha 0.5, extremes at the centre,
  residual 0). The GL pass skips those pixels, which most of a filtered image is.
* Colour is premultiplied by alpha before the fit, so a transparent pixel is the colour
  (0, 0, 0, 0) and blending towards it lowers coverage without bleeding its hidden colour.
"""

from dataclasses import dataclass

import numpy as np

from ._colour import linear_to_srgb, srgb_to_linear

__all__ = [
    "NEIGHBOUR_OFFSETS",
    "BlendModel",
    "to_working_space",
    "from_working_space",
    "edge_strength",
    "fit_blend_model",
    "fit_pure_colour_model",
    "jacobi_step",
    "recover_working",
]

#: (row, column) offsets of the 3x3 neighbourhood in tie-breaking order: centre, N, W, E, S, diagonals.
NEIGHBOUR_OFFSETS = ((0, 0), (-1, 0), (0, -1), (0, 1), (1, 0), (-1, -1), (-1, 1), (1, -1), (1, 1))
_EM_ITERATIONS = 3
_TINY = np.float32(1e-12)
_FAINT = np.float32(1e-30)


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
        Positions of the extreme colours as indices into :data:`NEIGHBOUR_OFFSETS`.
    residual : ndarray of float32, shape (H, W)
        Distance ``d_p`` of the centre colour from its best blend, equation 2.
    edge : ndarray of float32, shape (H, W)
        Edge strength ``e_p`` from :func:`edge_strength`.
    pure_a, pure_b : ndarray of bool, shape (H, W), or None
        With a pure-colour prior (``aarecovery._pure_colours``): where the extreme was a thin
        feature's partial colour, and the Jacobi step blends the fixed colour below instead
        of R at the extreme pixel. None without a prior.
    fixed_a, fixed_b : ndarray of float32, shape (H, W, 4), or None
        The filtered pure colours (working space), meaningful where `pure_a` / `pure_b`.
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


def to_working_space(rgba, *, linear_input=False, blend_space="linear"):
    """Move straight RGBA from its encoding into the premultiplied blend space.

    Parameters
    ----------
    rgba : ndarray of float32, shape (H, W, 4)
        Straight alpha, colour sRGB-encoded (or linear if `linear_input`).
    linear_input : bool
        True when `rgba`'s colour is already linear light.
    blend_space : {"linear", "srgb"}
        Where the model is fitted and the blend happens.

    Returns
    -------
    ndarray of float32, shape (H, W, 4)
        Premultiplied colour in the blend space, then alpha.
    """
    colour = rgba[..., :3]
    if blend_space == "linear" and not linear_input:
        colour = srgb_to_linear(colour)
    elif blend_space == "srgb" and linear_input:
        colour = linear_to_srgb(colour)
    alpha = rgba[..., 3:4]
    return np.concatenate([colour * alpha, alpha], axis=-1).astype(np.float32, copy=False)


def from_working_space(work, filtered_rgba, *, linear_input=False, blend_space="linear", filtered_work=None):
    """Undo :func:`to_working_space`: un-premultiply and re-encode.

    Parameters
    ----------
    work : ndarray of float32, shape (H, W, 4)
        Premultiplied RGBA in the blend space.
    filtered_rgba : ndarray of float32, shape (H, W, 4)
        F in its own encoding; its colour is kept where the result is fully transparent,
        where colour cannot be recovered from a premultiplied value.
    linear_input, blend_space
        As given to :func:`to_working_space`.
    filtered_work : ndarray of float32, shape (H, W, 4), optional
        F in the working space. Pixels the recovery left exactly at F take `filtered_rgba`
        as it was: decoding and re-encoding is not exact to the last bit, and a pixel
        recovery did not touch must come back bit for bit (16-bit and float images).

    Returns
    -------
    ndarray of float32, shape (H, W, 4)
        Straight RGBA in the input's encoding, clipped to [0, 1].
    """
    alpha = np.clip(work[..., 3:4], 0, 1)
    visible = alpha > 0
    colour = np.where(visible, work[..., :3] / np.where(visible, alpha, 1), 0)
    colour = np.clip(colour, 0, 1)
    if blend_space == "linear" and not linear_input:
        colour = linear_to_srgb(colour)
    elif blend_space == "srgb" and linear_input:
        colour = srgb_to_linear(colour)
    colour = np.where(visible, colour, filtered_rgba[..., :3])
    result = np.concatenate([colour, alpha], axis=-1).astype(np.float32, copy=False)
    if filtered_work is not None:
        untouched = np.all(work == filtered_work, axis=-1)
        result[untouched] = filtered_rgba[untouched]
    return result


# The fit works on channel planes, shape (4, H, W): NumPy is slow at reducing a last axis of
# length 4, and fast at elementwise work on whole planes. Sums run in the GLSL pass's order
# (left to right, neighbours in NEIGHBOUR_OFFSETS order), so that float rounding, and with
# it every argmax and threshold decision, is the same in both backends.

def _planes(image):
    return np.ascontiguousarray(np.moveaxis(image, -1, 0))


def _neighbours(planes):
    """The 9 neighbourhood images of channel planes, each (4, H, W), borders replicated."""
    height, width = planes.shape[1:]
    padded = np.pad(planes, ((0, 0), (1, 1), (1, 1)), mode="edge")
    return [padded[:, 1 + dy:1 + dy + height, 1 + dx:1 + dx + width] for dy, dx in NEIGHBOUR_OFFSETS]


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]


def _sobel_magnitude(v):
    # v in NEIGHBOUR_OFFSETS order: 1 N, 2 W, 3 E, 4 S, 5 NW, 6 NE, 7 SW, 8 SE. Differences
    # first: a flat neighbourhood then gives exactly 0 in any summation order, which the edge
    # test ``e_p == 0`` relies on.
    gx = ((v[6] - v[5]) + 2 * (v[3] - v[2]) + (v[8] - v[7])) * np.float32(0.125)
    gy = ((v[7] - v[5]) + 2 * (v[4] - v[1]) + (v[8] - v[6])) * np.float32(0.125)
    return np.sqrt(_dot(gx, gx) + _dot(gy, gy))


def sobel_gradients(image):
    """Sobel derivatives divided by 8 (a unit ramp gives 1), borders replicated.

    Parameters
    ----------
    image : ndarray of float, shape (H, W, C)

    Returns
    -------
    gx, gy : ndarray, shape (H, W, C)
        Per channel, in the image's dtype.
    """
    planes = _neighbours(np.moveaxis(image, -1, 0))
    gx = ((planes[6] - planes[5]) + 2 * (planes[3] - planes[2]) + (planes[8] - planes[7])) / 8
    gy = ((planes[7] - planes[5]) + 2 * (planes[4] - planes[1]) + (planes[8] - planes[6])) / 8
    return np.moveaxis(gx, 0, -1), np.moveaxis(gy, 0, -1)


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
    return (_sobel_magnitude(_neighbours(_planes(original)))
            * _sobel_magnitude(_neighbours(_planes(filtered)))).astype(np.float32)


def _principal_direction(colours):
    """First principal direction of 9 colours per pixel, as unit vectors ``(4, H, W)``.

    Roweis' EM for one component without noise alternates ``z = Y x / |x|^2`` and
    ``x = Y^T z / |z|^2``, which is ``x <- Y^T Y x`` up to scale: power iteration on the 4x4
    scatter matrix. Forming the matrix once costs 10 products per neighbour instead of 16
    per neighbour per iteration, which matters in the GL pass. The start is the neighbour
    farthest from the mean (a fixed start such as (1, 1, 1) is orthogonal to a red/green edge
    and never leaves it); each step is normalised so that faint neighbourhoods do not
    underflow.
    """
    total = colours[0].copy()
    for colour in colours[1:]:
        total += colour
    mean = total / np.float32(9)
    deviations = [colour - mean for colour in colours]
    # The first neighbour of largest spread (strictly larger replaces, as in the GL pass).
    x = deviations[0].copy()
    farthest = _dot(x, x)
    for y in deviations[1:]:
        spread = _dot(y, y)
        further = spread > farthest
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
        x = x / np.sqrt(_dot(x, x) + _FAINT)
    return x


def fit_blend_model(original, filtered, sigma_d, sigma_e, strength=1.0, prior=None, blend_space="linear"):
    """Fit the two-colour blend model at every pixel of O (section 3.1) and its confidence.

    The GL pass of this name also writes the first Jacobi iterate, which it can form from
    the F texels it already fetched for Sobel; its twin here is ``jacobi_step(F, F, model)``.

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
        Multiplies the confidence ``beta`` (the safe default's per-image repair strength,
        see ``_safeguards.py``); 1 is the paper's method and leaves ``beta`` bit-identical.
    prior : PureColourPrior, optional
        The safe default's pure-colour extension for point-wise filters on hard-edged
        content (:func:`fit_pure_colour_model`); None is the paper's method.
    blend_space : {"linear", "srgb"}
        The working space's colour space, needed only with `prior` (its table is on
        sRGB-encoded values).

    Returns
    -------
    BlendModel
    """
    if prior is not None:
        return fit_pure_colour_model(original, filtered, sigma_d, sigma_e, strength, prior, blend_space)
    colours = _neighbours(_planes(original))
    edge = (_sobel_magnitude(colours) * _sobel_magnitude(_neighbours(_planes(filtered)))).astype(np.float32)
    # Where e_p == 0 beta is exactly 0 and the model unused: fit only the other pixels (most
    # of a thresholded or posterized image is flat), as (4, N) columns.
    fitted = edge > 0
    alpha = np.full(edge.shape, 0.5, np.float32)
    beta = np.zeros(edge.shape, np.float32)
    residual = np.zeros(edge.shape, np.float32)
    index_a = np.zeros(edge.shape, np.uint8)
    index_b = np.zeros(edge.shape, np.uint8)
    if fitted.any():
        columns = _fit_columns([colour[:, fitted] for colour in colours], edge[fitted], sigma_d, sigma_e,
                               strength)
        for target, values in zip((alpha, beta, residual, index_a, index_b), columns):
            target[fitted] = values
    return BlendModel(alpha, beta, index_a, index_b, residual, edge)


def _fit_extremes(colours, sigma_d):
    """Extremes, coverage and residual on neighbourhood columns: 9 arrays (4, N)."""
    centre = colours[0]
    direction = _principal_direction(colours)
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
        along = _dot(offset, direction)
        # Squared distance to the line by Pythagoras (direction is a unit vector).
        near = _dot(offset, offset) - along * along < reach * reach
        higher = near & (along > t_max)
        lower = near & (along < t_min)
        np.copyto(t_max, along, where=higher)
        np.copyto(t_min, along, where=lower)
        np.copyto(index_a, i, where=higher)
        np.copyto(index_b, i, where=lower)
        np.copyto(colour_a, colour, where=higher)
        np.copyto(colour_b, colour, where=lower)
    alpha = _coverage(centre, colour_a, colour_b)
    miss = alpha * colour_a + (1 - alpha) * colour_b - centre
    residual = np.sqrt(_dot(miss, miss)).astype(np.float32)
    return alpha, residual, index_a, index_b, colour_a, colour_b


def _coverage(centre, colour_a, colour_b):
    span = colour_a - colour_b
    span_sq = _dot(span, span)
    defined = span_sq > _TINY
    alpha = np.where(defined, _dot(centre - colour_b, span) / np.where(defined, span_sq, 1), 0.5)
    return np.clip(alpha, 0, 1).astype(np.float32)


def _confidence(residual, edge, sigma_d, sigma_e, strength):
    residual_ratio = residual / np.float32(sigma_d)
    edge_ratio = edge / np.float32(sigma_e)
    beta = np.exp(-residual_ratio * residual_ratio) * (1 - np.exp(-edge_ratio * edge_ratio))
    if strength != 1.0:
        beta = beta * np.float32(strength)
    return beta.astype(np.float32)


def _fit_columns(colours, edge, sigma_d, sigma_e, strength):
    """The fit on neighbourhood columns: 9 arrays (4, N) and edge strengths (N,)."""
    alpha, residual, index_a, index_b, _, _ = _fit_extremes(colours, sigma_d)
    return alpha, _confidence(residual, edge, sigma_d, sigma_e, strength), residual, index_a, index_b


def fit_pure_colour_model(original, filtered, sigma_d, sigma_e, strength, prior, blend_space):
    """:func:`fit_blend_model` with the pure colours of thin features (the safe default).

    For point-wise filters on hard-edged content (see ``aarecovery._pure_colours`` for the
    rule and its measurements): an extreme that is a thin feature's partial colour is
    extended along the colour line to the colour cube, its filtered colour is taken from
    the filter's table, and alpha is measured against the extended colours. The edge
    strength uses O's gradient times the larger of F's gradient and the contrast of the
    two filtered extremes, since a thin feature that the filter erased from F (a light
    stroke thresholded away) leaves F flat where it must be restored; measured, this added
    0.05 to the quick suite's mean error reduction on linear-light scenes.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 4)
        O and F in the working space.
    sigma_d, sigma_e, strength
        As for :func:`fit_blend_model`.
    prior : PureColourPrior
    blend_space : {"linear", "srgb"}

    Returns
    -------
    BlendModel
        With `pure_a`, `pure_b`, `fixed_a` and `fixed_b` set.
    """
    from ._pure_colours import extend_extreme

    height, width = original.shape[:2]
    o_planes, f_planes = _planes(original), _planes(filtered)
    colours = _neighbours(o_planes)
    f_colours = _neighbours(f_planes)
    original_gradient = _sobel_magnitude(colours).astype(np.float32)
    filtered_gradient = _sobel_magnitude(f_colours).astype(np.float32)
    shape = (height, width)
    alpha = np.full(shape, 0.5, np.float32)
    beta = np.zeros(shape, np.float32)
    residual = np.zeros(shape, np.float32)
    edge = np.zeros(shape, np.float32)
    index_a = np.zeros(shape, np.uint8)
    index_b = np.zeros(shape, np.uint8)
    pure_a = np.zeros(shape, bool)
    pure_b = np.zeros(shape, bool)
    fixed_a = np.zeros(shape + (4,), np.float32)
    fixed_b = np.zeros(shape + (4,), np.float32)
    # Where O is flat, e_p is 0 whatever F does: nothing to fit.
    fitted = original_gradient > 0
    if fitted.any():
        rows, cols = np.nonzero(fitted)
        columns = [colour[:, fitted] for colour in colours]
        col_alpha, col_residual, col_a, col_b, colour_a, colour_b = _fit_extremes(columns, sigma_d)
        offsets = np.asarray(NEIGHBOUR_OFFSETS, dtype=np.int64)
        padded_o = np.pad(o_planes, ((0, 0), (2, 2), (2, 2)), mode="edge")
        palette = prior.palette_in(blend_space)

        def at(planes, pad, row, col):
            return planes[:, np.clip(row, -pad, height - 1 + pad) + pad, np.clip(col, -pad, width - 1 + pad) + pad]

        def extend(index, far, near):
            q_row, q_col = rows + offsets[index, 0], cols + offsets[index, 1]
            border = (q_row <= 0) | (q_row >= height - 1) | (q_col <= 0) | (q_col >= width - 1)
            around = [at(padded_o, 2, q_row + dy, q_col + dx) for dy, dx in NEIGHBOUR_OFFSETS]
            filtered_far = f_planes[:, np.clip(q_row, 0, height - 1), np.clip(q_col, 0, width - 1)]
            extended, pure, fixed = extend_extreme(far, near, around, filtered_far, border, palette, prior,
                                                   blend_space)
            return extended, pure, np.where(extended, fixed, filtered_far)

        extended_a, pure_colour_a, start_a = extend(col_a, colour_a, colour_b)
        extended_b, pure_colour_b, start_b = extend(col_b, colour_b, colour_a)
        either = extended_a | extended_b
        col_alpha = np.where(either, _coverage(columns[0], pure_colour_a, pure_colour_b), col_alpha)
        contrast = np.sqrt(_dot(start_a - start_b, start_a - start_b))
        col_edge = (original_gradient[fitted] * np.maximum(filtered_gradient[fitted], contrast)).astype(np.float32)
        alpha[fitted] = col_alpha
        residual[fitted] = col_residual
        edge[fitted] = col_edge
        beta[fitted] = _confidence(col_residual, col_edge, sigma_d, sigma_e, strength)
        index_a[fitted], index_b[fitted] = col_a, col_b
        pure_a[fitted], pure_b[fitted] = extended_a, extended_b
        fixed_a[fitted] = np.where(extended_a, start_a, 0).T
        fixed_b[fitted] = np.where(extended_b, start_b, 0).T
    return BlendModel(alpha, beta, index_a, index_b, residual, edge, pure_a, pure_b, fixed_a, fixed_b)


def _gather_indices(index, height, width):
    offsets = np.asarray(NEIGHBOUR_OFFSETS, dtype=np.int64)
    rows = np.clip(np.arange(height)[:, None] + offsets[index, 0], 0, height - 1)
    cols = np.clip(np.arange(width)[None, :] + offsets[index, 1], 0, width - 1)
    return rows * width + cols


def jacobi_step(recovered, filtered, model):
    """One Jacobi iteration of equation 6.

    ``R'[p] = beta (alpha R[p_a] + (1 - alpha) R[p_b]) + (1 - beta) F[p]``, reading only the
    previous iterate (ping-pong), as a fragment pass does.

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
    return (beta * (alpha * at_a + (1 - alpha) * at_b) + (1 - beta) * filtered).astype(np.float32)


def recover_working(original, filtered, sigma_d, sigma_e, iterations, strength=1.0, prior=None,
                    blend_space="linear"):
    """Run every pass on working-space images (`strength`, `prior`, `blend_space` as in
    :func:`fit_blend_model`).

    Returns
    -------
    recovered : ndarray of float32, shape (H, W, 4)
    model : BlendModel
    """
    model = fit_blend_model(original, filtered, sigma_d, sigma_e, strength, prior, blend_space)
    recovered = filtered
    for _ in range(iterations):
        recovered = jacobi_step(recovered, filtered, model)
    return recovered, model
