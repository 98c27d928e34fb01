"""What forcing a repair (``strength=1``) would do where the safe default keeps F.

The one-line summary offers the way to force a repair only where the analysis has evidence
that it may help; elsewhere it says what forcing risks, in the analysis's own terms (an
unsharp-masked portrait forced to full strength turned its irises grey and gained pale
halos, where the summary used to offer the force without a word of warning).
"""

from dataclasses import dataclass

from ..backends.base import Decision

__all__ = ["Forcing", "forcing_advice"]

_RISKS = {
    Decision.LOWPASS_KEPT: "re-sharpening the soft edges the blur made on purpose",
    Decision.AFFINE_KEPT: "changing edges that are already right (the filter commutes with antialiasing)",
    Decision.NEIGHBOURHOOD_TEXTURED_KEPT: ("flattening the photo's texture into two-colour edges and pale halos "
                                           "(the paper's method lost up to 3.4 dB on such pairs)"),
}


@dataclass(frozen=True)
class Forcing:
    """What a forced repair would do.

    Attributes
    ----------
    helps : bool
        The analysis measured that a repair may help (then the summary offers it).
    why : str
        The evidence, or what forcing risks.
    """

    helps: bool
    why: str


def forcing_advice(decision, ratio=None, errors=None):
    """The :class:`Forcing` of a plan that keeps F.

    Parameters
    ----------
    decision : Decision
    ratio : float, optional
        The repair-to-error ratio (``model_error``), where the decision read it.
    errors : dict of float to float, optional
        The calibration's half-resolution error per strength, where it ran.

    Returns
    -------
    Forcing
    """
    if errors:
        best = min((strength for strength in errors if strength > 0), key=errors.get)
        if errors[best] < errors[0.0]:
            gain = 1 - errors[best] / errors[0.0]
            return Forcing(True, f"at half resolution strength {best:g} was {gain:.1%} closer than F, "
                                 "too little to choose it")
        if errors[0.0] == 0:
            # F already reproduced the half-resolution truth exactly (a filter that commutes
            # with the box filter on these edges): there is no relative loss to quote.
            return Forcing(False, "a result farther from the truth than F: at half resolution F was exact and "
                                  "every strength tried moved it away")
        return Forcing(False, "a result farther from the truth than F: at half resolution every strength tried "
                              f"was worse than F (strength 1 by {errors[1.0] / errors[0.0] - 1:.0%})")
    if ratio is not None:
        return Forcing(False, f"changes no larger than the model's own error (repair-to-error ratio {ratio:.2f}): "
                              "noise along the edges rather than a repair")
    return Forcing(False, _RISKS[decision])
