"""Where O was antialiased: linear light or sRGB-encoded values.

The model must be fitted and imposed in the space in which the image was antialiased. An
edge between two colours, box-filtered in one space, lies exactly on a straight colour line
in that space and off it in the other, so the space whose edge pixels fit their colour line
better wins. Grey-only edges cannot tell; they keep linear light, the paper's choice and
right for cameras. Measured and not taken: grey drawings under a sharpening filter in sRGB
values. On the tuning half's only grey drawing, the manga pages under the two tuning unsharp
masks, it gained at every size (96 px PNG 0.653 -> 0.751, JPEG 0.682 -> 0.903; 768 px 0.595
-> 0.759), but grey renderings of the held-out drawings under the held-out sharpening tools
(G'MIC's and Pillow's unsharp masks, OpenCV's detail enhancement; 96 px, PNG and JPEG, 48
cases) fell 0.533 -> 0.490: the unsharp masks lost, the detail enhancement gained.

Text, logos and interface chrome over a photo are told by their own edges: a photo's
texture fits colour lines alike in both spaces (or, grey, votes for neither) and, with more
edge pixels than the drawing, ties the whole window's means and votes. Where the whole window
does not tell sRGB values and O shows no JPEG compression, the edge pixels that the local
plan reads as drawn (``mixed_content.drawn_at``: flat regions or recurring ink) decide alone,
with the same tests, when they are at least ``mixed_content.MIXED_DRAWN_SHARE`` of the
window's confident edge pixels (see :func:`choose_blend_space` for the figures).
"""

import numpy as np

from ..params import BLEND_SPACES, SIGMA_D, SIGMA_E
from ..spec import to_working_space
from ..spec.blend_model import fit_paper_model
from ..spec.neighbourhood import neighbours, planes
from .mixed_content import MIXED_DRAWN_SHARE

__all__ = ["choose_blend_space", "colour_line_residual", "means_tell_srgb", "sampled_rows"]

# The blend-space test fits the model on up to this many pixels of the crop (all of a
# 256 x 256 crop; strips around every twelfth row of a 512 x 512 one): its mean residual
# settles long before,
# and the two full fits took 0.63 s of the 0.92 s analysis of a 1080p pair (measured).
_FIT_SAMPLE = 65536
# Blend space: the other space must fit colour lines this much worse (ratio of mean
# normalised residuals) and by this much in absolute terms before linear light is left.
# Measured on the synthetic scenes: the right space gives 0.000-0.005, the wrong one
# 0.008-0.04; photos give ~0.03-0.05 in both (ratio < 1.1).
_SPACE_RATIO = 1.5
_SPACE_MARGIN = 0.003
# Where the means tie, the edge pixels vote (_pixels_vote_srgb). Measured and not taken: the
# medians of the normalised residuals deciding instead of the means. They told the sRGB map
# too, but read the linear memo at q 95 in sRGB values (0.747 -> 0.451 under a threshold),
# and the built-in chart, whose edge pixels mostly fit exactly, has medians of 0 in both.


def sampled_rows(image, limit=_FIT_SAMPLE):
    """At most about `limit` pixels of `image` as stacked 3-row strips, and their middle rows.

    The fit reads a 3x3 neighbourhood, so a strip of three rows gives its middle row exactly
    the model of the whole image. Crops up to `limit` pixels (every eval image) are used whole.
    """
    rows = _strip_rows(*image.shape[:2], limit)
    return (image, slice(None)) if rows is None else (image[rows], slice(1, None, 3))


def _strip_rows(height, width, limit=_FIT_SAMPLE):
    """The image rows that :func:`sampled_rows` stacks, or None where it uses the image whole."""
    if height * width <= limit or height < 3:
        return None
    stride = -(-3 * height * width // limit)  # each sampled row brings its two neighbours
    if stride <= 3:
        return None
    return np.concatenate([np.arange(row - 1, row + 2) for row in range(1, height - 1, stride)])


def colour_line_residual(rgba, linear_input, blend_space):
    """Mean colour-line residual of O's confident edge pixels, relative to their contrast.

    Parameters
    ----------
    rgba : ndarray of float32, shape (H, W, 4)
        O in the core contract.
    linear_input : bool
    blend_space : {"linear", "srgb"}

    Returns
    -------
    float or None
        None where fewer than 16 such pixels were found.
    """
    return _mean_residual(_edge_residuals(rgba, linear_input, blend_space))


def _mean_residual(residuals):
    selected = ~np.isnan(residuals)
    return float(np.mean(residuals[selected])) if selected.sum() >= 16 else None


def _edge_residuals(rgba, linear_input, blend_space):
    """float32 ``(H', W')`` over the sampled rows: each confident edge pixel's colour-line
    residual relative to its contrast, NaN elsewhere (the same rows in both spaces)."""
    work, middle = sampled_rows(to_working_space(rgba, linear_input=linear_input, blend_space=blend_space))
    middle_rows = np.zeros(work.shape[:2], bool)
    middle_rows[middle] = True
    # Only the middle rows are read: fitting the strips' outer rows too took 2/3 of the time.
    model = fit_paper_model(work, work, SIGMA_D.default, SIGMA_E.default, only=middle_rows)
    colours = np.stack(neighbours(planes(work)))
    c_a = np.take_along_axis(colours, model.index_a[None, None].astype(np.intp), 0)[0]
    c_b = np.take_along_axis(colours, model.index_b[None, None].astype(np.intp), 0)[0]
    span = np.sqrt(np.sum(np.square(c_a - c_b)[:3], axis=0))
    selected = (model.beta > 0.5) & (span > 0.2) & (model.alpha > 0.03) & (model.alpha < 0.97)
    selected &= middle_rows
    return np.where(selected, model.residual / np.where(selected, span, 1), np.nan).astype(np.float32)


def choose_blend_space(original_rgba, linear_input=False, lossless=True, drawn=None):
    """Pick the space in which O was antialiased, from how well its edges fit colour lines.

    Parameters
    ----------
    original_rgba : ndarray of float32, shape (H, W, 4)
        O in the core contract.
    linear_input : bool
    lossless : bool, optional
        False where O shows a JPEG's compression (``compression.CompressionEvidence``): its
        edge pixels do not vote (:func:`means_tell_srgb`).
    drawn : callable or None, optional
        ``drawn(rows, cols)`` returns bool ``(K,)``: whether each pixel of O lies in a drawn
        region (text and graphics over a photo). Called for the confident edge pixels only
        where the whole window keeps linear light and `lossless`; those in drawn regions then
        decide alone when they are at least
        :data:`~aarecovery.plan.mixed_content.MIXED_DRAWN_SHARE` of the window's.

    Returns
    -------
    space : {"linear", "srgb"}
    residuals : dict
        Mean normalised residual per space (None where too few edges were found).
    """
    per_pixel = {space: _edge_residuals(original_rgba, linear_input, space) for space in BLEND_SPACES}
    residuals = {space: _mean_residual(values) for space, values in per_pixel.items()}
    if _tells_srgb(per_pixel, lossless):
        return "srgb", residuals
    # A photo's texture hides the space of the text and chrome drawn over it: the real-tools
    # suite's mixed scenes antialiased in sRGB values (tuning half: the poster's text over the
    # coffee photo, the screenshot's window chrome over the grey camera photo) tied in the
    # means (0.0368 against 0.0372, 0.0098 against 0.0079) and did not vote, where their drawn
    # pixels' 574 of 2742 and 413 of 1899 confident edge pixels told sRGB values (0.0138
    # against 0.0072 by the means, 0.0063 against 0.0037 by vote); those of the linear-light
    # scenes tell linear light (0.0072 against 0.0135, 0.0028 against 0.0051). Tuning half,
    # 44 cases moved, all the sRGB mixed scenes': 37 up (the poster under OpenCV's JET 0.546
    # -> 0.768, GEGL's threshold 0.422 -> 0.579, ImageMagick's unsharp mask 0.014 -> 0.155;
    # the screenshot under JET 0.400 -> 0.658; its photo regions under OpenCV's gamma and JET
    # no longer worse than F, by up to 1.94 dB before, nor the whole under Pillow's
    # autocontrast, 0.79 dB before: its affine map is seen in sRGB values), 7 down (the
    # screenshot under the two equalizations 0.589 -> 0.374 and 0.543 -> 0.440: the grey
    # photo's flat greys stopped its title's extension in sRGB values; since
    # spec.pure_colours.INK_LINE_TOLERANCE 0.544 and 0.543; the poster under Pillow's
    # autocontrast 0.000 -> -0.014). Below the share, a JPEG drawing at q 98 whose grid is not
    # seen (the star burst in linear light, 20 of 2634) votes with its noise, and a JPEG's
    # drawn pixels do not decide: its noise fits sRGB values better whatever the space.
    if drawn is not None and lossless:
        rows, cols = np.nonzero(~np.isnan(per_pixel["linear"]) | ~np.isnan(per_pixel["srgb"]))
        strips = _strip_rows(*original_rgba.shape[:2])
        in_drawn = drawn(rows if strips is None else strips[rows], cols)
        in_regions = {space: values[rows, cols][in_drawn] for space, values in per_pixel.items()}
        confident = np.count_nonzero(~np.isnan(per_pixel["linear"]))
        if np.count_nonzero(~np.isnan(in_regions["linear"])) >= MIXED_DRAWN_SHARE * confident:
            if _tells_srgb(in_regions, lossless):
                return "srgb", residuals
    return "linear", residuals


def _tells_srgb(per_pixel, lossless):
    """The mean residuals tell sRGB values, or (on a lossless O) the edge pixels vote for them."""
    means = {space: _mean_residual(values) for space, values in per_pixel.items()}
    return means_tell_srgb(means) or (lossless and _pixels_vote_srgb(per_pixel["linear"], per_pixel["srgb"]))


def means_tell_srgb(residuals):
    """Whether the mean residuals alone (``choose_blend_space``'s) tell sRGB values.

    Where they do not and O is sRGB all the same, its edge pixels voted: the two spaces'
    means tied, and ``analysis`` then takes an affine map of O in either space as F already
    right (the sRGB map under G'MIC's luminance, affine in linear light, 53 dB from the
    reference, lost 3.95 of its edge error repaired in sRGB values).
    """
    lin, srgb = residuals["linear"], residuals["srgb"]
    return lin is not None and srgb is not None and lin > _SPACE_RATIO * srgb and lin - srgb > _SPACE_MARGIN


# The edge pixels' vote, where the means tie: a pixel fits one space's colour line clearly
# better when its residual in the other exceeds twice its own by _VOTE_MARGIN; sRGB wins with
# _VOTE_SHARE of the pixels fitted in both, _VOTE_RATIO times those for linear light. Where
# three colours meet (a map's contour lines over its tints, a memo's grained paper) no space
# fits and the means tie; the two-colour edges still fit only their own space. Tuning half,
# the 20 PNG windows: sRGB ones vote 0.076-0.833 for sRGB against 0.000-0.020 (ratios 14.5
# and up: the map 0.297 / 0.020, the memo 0.076 / 0.000), linear-light ones 0.000-0.122
# against 0.000-0.802 (ratios up to 0.56, the coffee photo); held out, every PNG window votes
# for its own space (sRGB 0.286-0.610 against at most 0.030), and none changed its space, as
# the means had told them all. Tuning cases, the sRGB map and memo under the 23 tools: 27 up
# (the map under GEGL's threshold 0.209 -> 0.695, OpenCV's JET 0.151 -> 0.661; the memo up
# 0.03-0.41), 12 down (the map under OpenCV's bilateral kept by the repair-to-error ratio,
# 1.91 against 2, 0.763 -> 0; under ImageMagick's unsharp mask 0.392 -> 0.163; the memo
# under Pillow's autocontrast 0.542 -> 0.214), none below F. JPEG originals do not vote:
# their noise fits sRGB values better whatever the space (the linear memo and notice at q
# 75-95 0.13-0.38 against 0.00-0.01), and the serif page at q 95-98, whose grid the pixels do
# not show (lossless to the evidence), votes for sRGB in both spaces by ratios 4.2-6.9.
_VOTE_MARGIN = 0.005
_VOTE_SHARE = 0.05
_VOTE_RATIO = 10.0


def _pixels_vote_srgb(linear, srgb):
    both = ~np.isnan(linear) & ~np.isnan(srgb)
    if both.sum() < 16:
        return False
    lin, enc = linear[both], srgb[both]
    for_srgb = np.mean(lin > 2 * enc + _VOTE_MARGIN)
    for_linear = np.mean(enc > 2 * lin + _VOTE_MARGIN)
    return bool(for_srgb >= _VOTE_SHARE and for_srgb >= _VOTE_RATIO * for_linear)
