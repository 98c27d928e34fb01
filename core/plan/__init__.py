"""The plan layer: the mode and every per-image decision, resolved once into a Plan.

``mode="paper"`` is the published method: linear light, full strength. ``mode="safe"``
(the default) first analyses the pair (:mod:`aarecovery.plan.analysis`, which says what
it decides and why) and may change the blend space, lower the strength or leave F as it is.
Either way the result is a :class:`~aarecovery.backends.base.Plan` that the engine and
every backend take as it is.
"""

from ..backends.base import Decision, Plan
from ..params import check_blend_space, check_mode
from .analysis import PairAnalysis, analyse, analyse_pair
from .blas import one_blas_thread

__all__ = ["make_plan", "Decision", "Plan", "PairAnalysis", "analyse", "analyse_pair"]


def make_plan(original, filtered, parameters, *, mode="safe", linear=False, blend_space=None, analysis=None,
              quantization=None):
    """Resolve the mode for one pair into a :class:`Plan`.

    Parameters
    ----------
    original, filtered : ndarray
        The checked pair as the caller gave it (read only with ``mode="safe"``, and then
        only a central crop).
    parameters : Parameters
        The checked user parameters.
    mode : {"safe", "paper"}
    linear : bool
        The images hold linear-light values.
    blend_space : {"linear", "srgb"}, optional
        Overrides the space the mode would choose.
    analysis : PairAnalysis, optional
        The pair's analysis when it is already known (an engine keeps it per pair, so that a
        slider change does not analyse again).
    quantization : sequence of sequence of int, optional
        The quantization tables of O's JPEG file (``aarecovery.io.read_quantization``);
        without them the analysis looks for a block grid in O's pixels.

    Returns
    -------
    Plan
    """
    check_mode(mode)
    if blend_space is not None:
        check_blend_space(blend_space)
    common = dict(sigma_d=parameters.sigma_d, sigma_e=parameters.sigma_e, iterations=parameters.iterations)
    asked = parameters.strength
    if mode == "paper":
        return Plan(**common, blend_space=blend_space or "linear", mode="paper",
                    strength=1.0 if asked is None else asked,
                    reason="the published method (Yang et al. 2011), without the safe default's analysis"
                           + ("" if asked is None else f"; strength {asked:g} as asked"), decision=Decision.PAPER)
    if analysis is None:
        # One BLAS thread (plan/blas.py): the same analysis, without spinning threads.
        with one_blas_thread():
            analysis = analyse_pair(original, filtered, linear, quantization)
    # A strength the user gives overrides the analysis's, its local plan and its untouched
    # span (both per-pixel readings of the strength), and forces a repair where it keeps F;
    # the other decisions (blend space, pure colours) stand.
    # A coarse paper grain raises the edge-strength scale (plan/paper_grain.py).
    common["sigma_e"] = parameters.sigma_e * analysis.edge_scale
    # Pure colours gated by the local plan (over a photo) go with it: without its weight they
    # would act on the photo too.
    prior = analysis.pure_colours
    if asked is not None and prior is not None and prior.drawn_only:
        prior = None
    return Plan(**common, blend_space=blend_space or analysis.blend_space,
                strength=analysis.strength if asked is None else asked, pure_colours=prior,
                mode="safe", decision=analysis.decision, local=analysis.local if asked is None else None,
                untouched_span=analysis.untouched_span if asked is None else 0.0,
                toward_original=analysis.toward_original and asked is None, forcing=analysis.forcing,
                # The ramp lookup's delta is in sRGB-encoded values, the table's.
                ramp_table=None if linear else analysis.ramp_table, best_pair=analysis.best_pair,
                pure_colour_blocks=analysis.pure_colour_blocks and prior is not None,
                reason=analysis.reason + ("" if asked is None else f"; strength {asked:g} as asked instead"))
