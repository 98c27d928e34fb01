"""Would a repair be larger than the model's own error? The repair-to-error ratio of a pair.

The repair moves an edge pixel of F from its value to the model's blend of F at O's two
extremes, ``alpha F[a] + (1 - alpha) F[b]``. That move is right when the filter's
nonlinearity put F off the blend, and noise when the model itself is off: O's pixel lies
``d_p`` (the residual) from its colour line, and the filter carries that error into F
scaled by its slope along the line, ``|F[a] - F[b]| / |O[a] - O[b]|``. The ratio of the
two, as confidence-weighted mean squares over the pair's edge pixels, says which dominates.

Measured on the real-tools suite's hard-edged content under neighbourhood filters (those
with no fitted table, where nothing else tells whether the filter broke the blends): the
cases that lost to F had ratios 1.24-1.41 on the tuning half (GEGL's hue-chroma on maps,
1.4-2.8 dB) and every case that gained 3.16 and up (unsharp masks, bilateral filters,
hue changes of icons and serif text). On the held-out half, not looked at to choose the
limit, ImageMagick's ``-modulate 100,100,150`` on line art, pies, plots and hatching that
lost 1.5-11.9 dB scores 1.30-1.63, and the lowest-scoring gain 2.32. The limit, 2, lies
between on both halves.
"""

import numpy as np

from ..spec.blend_model import fit_paper_model
from ..spec.neighbourhood import neighbours, planes
from ..spec.working_space import to_working_space
from .blend_space import sampled_rows

__all__ = ["repair_to_error_ratio", "MIN_REPAIR_TO_ERROR"]

#: Below this ratio a neighbourhood filter's F is kept on hard-edged content.
MIN_REPAIR_TO_ERROR = 2.0
# Extremes closer than this (working-space distance) give no usable slope.
_MIN_SPAN = 1e-3


def repair_to_error_ratio(original_rgba, filtered_rgba, *, linear_input, blend_space, sigma_d, sigma_e):
    """Mean squared repair over mean squared model error carried through the filter.

    Parameters
    ----------
    original_rgba, filtered_rgba : ndarray of float32, shape (H, W, 4)
        The analysis crop of O and F in the core contract.
    linear_input : bool
    blend_space : {"linear", "srgb"}
    sigma_d, sigma_e : float
        The model's scales, as the passes use them.

    Returns
    -------
    float
        ``inf`` where the model fits O exactly; NaN where no pixel has confidence.
    """
    o_work, middle = sampled_rows(to_working_space(original_rgba, linear_input=linear_input,
                                                   blend_space=blend_space))
    f_work, _ = sampled_rows(to_working_space(filtered_rgba, linear_input=linear_input, blend_space=blend_space))
    model = fit_paper_model(o_work, f_work, sigma_d, sigma_e)
    o_near = np.stack(neighbours(planes(o_work)))[:, :3]
    f_near = np.stack(neighbours(planes(f_work)))[:, :3]
    index_a = model.index_a[None, None].astype(np.intp)
    index_b = model.index_b[None, None].astype(np.intp)
    o_a, o_b = (np.take_along_axis(o_near, index, 0)[0] for index in (index_a, index_b))
    f_a, f_b = (np.take_along_axis(f_near, index, 0)[0] for index in (index_a, index_b))
    blend = model.alpha * f_a + (1 - model.alpha) * f_b
    repair = np.sum(np.square(blend - planes(f_work)[:3]), axis=0)
    slope = np.sqrt(np.sum(np.square(f_a - f_b), axis=0)) / np.maximum(
        np.sqrt(np.sum(np.square(o_a - o_b), axis=0)), _MIN_SPAN)
    error = np.square(slope * model.residual)
    weight = np.zeros(model.beta.shape, np.float64)
    weight[middle] = model.beta[middle]
    if weight.sum() <= 0:
        return float("nan")
    repair_mean, error_mean = float(np.sum(weight * repair)), float(np.sum(weight * error))
    return repair_mean / error_mean if error_mean > 0 else float("inf")
