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
"""

import numpy as np

from ..params import BLEND_SPACES, SIGMA_D, SIGMA_E
from ..spec import to_working_space
from ..spec.blend_model import fit_paper_model
from ..spec.neighbourhood import neighbours, planes

__all__ = ["choose_blend_space", "colour_line_residual", "sampled_rows"]

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
# Measured and not taken: the medians of the normalised residuals deciding instead of the
# means. A map's contour lines over its tints make pixels where three colours meet, which fit
# no colour line in either space: the sRGB map's means are 0.0236 (linear) and 0.0247, its
# medians 0.0136 and 0.0053, and read in linear light its thin lines are extended along the
# wrong line, to colours a threshold keeps white. Of the tuning half's 94 windows two change
# (the sRGB map, PNG; the linear memo at q 95 read in linear light, as it was made); its 920
# cases: 9 up (the map under GEGL's threshold 0.209 -> 0.695, OpenCV's JET 0.152 -> 0.661,
# Pillow's solarize 0.297 -> 0.574), 13 down (under G'MIC's luminance, affine in linear
# values and 53 dB from the reference, 0 -> -3.95; OpenCV's bilateral kept by the repair-to-
# error ratio 0.760 -> 0; the memo 0.747 -> 0.451 at q 95 under a threshold), drawings
# 0.763 -> 0.747, a third case over 0.1 dB. The built-in suite's chart has medians of 0 in
# both spaces (most of its edge pixels fit exactly) and would fall back to linear light.


def sampled_rows(image, limit=_FIT_SAMPLE):
    """At most about `limit` pixels of `image` as stacked 3-row strips, and their middle rows.

    The fit reads a 3x3 neighbourhood, so a strip of three rows gives its middle row exactly
    the model of the whole image. Crops up to `limit` pixels (every eval image) are used whole.
    """
    height, width = image.shape[:2]
    if height * width <= limit or height < 3:
        return image, slice(None)
    stride = -(-3 * height * width // limit)  # each sampled row brings its two neighbours
    if stride <= 3:
        return image, slice(None)
    return np.concatenate([image[row - 1:row + 2] for row in range(1, height - 1, stride)]), slice(1, None, 3)


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
    if selected.sum() < 16:
        return None
    return float(np.mean(model.residual[selected] / span[selected]))


def choose_blend_space(original_rgba, linear_input=False):
    """Pick the space in which O was antialiased, from how well its edges fit colour lines.

    Parameters
    ----------
    original_rgba : ndarray of float32, shape (H, W, 4)
        O in the core contract.
    linear_input : bool

    Returns
    -------
    space : {"linear", "srgb"}
    residuals : dict
        Mean normalised residual per space (None where too few edges were found).
    """
    residuals = {space: colour_line_residual(original_rgba, linear_input, space) for space in BLEND_SPACES}
    lin, srgb = residuals["linear"], residuals["srgb"]
    if lin is not None and srgb is not None and lin > _SPACE_RATIO * srgb and lin - srgb > _SPACE_MARGIN:
        return "srgb", residuals
    return "linear", residuals
