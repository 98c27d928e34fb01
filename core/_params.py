"""Checks of the recovery parameters, shared by every entry point."""

import math
from dataclasses import dataclass

from ._errors import InputError

__all__ = ["Parameters", "BLEND_SPACES", "MODES", "check_mode"]

BLEND_SPACES = ("linear", "srgb")
#: ``"safe"``: the default, with per-image safeguards (``_safeguards.py``); ``"paper"``: Yang et al. 2011 exactly.
MODES = ("safe", "paper")
MAX_ITERATIONS = 64


@dataclass(frozen=True)
class Parameters:
    """Validated recovery parameters.

    Attributes
    ----------
    sigma_d : float
        Colour-line distance scale, > 0 (paper default 0.1).
    sigma_e : float
        Edge-strength scale, > 0 (paper default 0.01).
    iterations : int
        Jacobi iterations, 0 to 64 (paper default 3; 0 returns F).
    strength : float
        Multiplies the confidence ``beta``, in [0, 1]: the safe default's per-image repair
        strength (1 is the paper's method). Backends pass it to the model fit as a uniform.
    pure_colours : PureColourPrior or None
        The safe default's pure-colour extension for point-wise filters on hard-edged
        content (``aarecovery._pure_colours``): the filter's table and O's flat colours,
        which backends take as a small lookup texture and a uniform array. None (the
        paper's method) leaves every pass as published.
    """

    sigma_d: float = 0.1
    sigma_e: float = 0.01
    iterations: int = 3
    strength: float = 1.0
    pure_colours: object = None

    def __post_init__(self):
        for name in ("sigma_d", "sigma_e"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) \
                    or not math.isfinite(value) or value <= 0:
                raise InputError(f"{name} must be a finite number above 0, got {value!r}; "
                                 f"the paper's default is {type(self).__dataclass_fields__[name].default}")
        if isinstance(self.iterations, bool) or not isinstance(self.iterations, int) \
                or not 0 <= self.iterations <= MAX_ITERATIONS:
            raise InputError(f"iterations must be a whole number from 0 to {MAX_ITERATIONS}, "
                             f"got {self.iterations!r}; 3 is the paper's choice")
        if isinstance(self.strength, bool) or not isinstance(self.strength, (int, float)) \
                or not 0 <= self.strength <= 1:
            raise InputError(f"strength must be a number from 0 to 1, got {self.strength!r}")
        object.__setattr__(self, "strength", float(self.strength))
        object.__setattr__(self, "sigma_d", float(self.sigma_d))
        object.__setattr__(self, "sigma_e", float(self.sigma_e))


def check_blend_space(blend_space):
    """Raise unless `blend_space` is one of :data:`BLEND_SPACES`."""
    if blend_space not in BLEND_SPACES:
        raise InputError(f"blend_space must be one of {', '.join(BLEND_SPACES)}, got {blend_space!r}")
    return blend_space


def check_mode(mode):
    """Raise unless `mode` is one of :data:`MODES`."""
    if mode not in MODES:
        raise InputError(f"mode must be one of {', '.join(MODES)}, got {mode!r}: 'safe' (the default) guards "
                         "against harming blurred or textured images, 'paper' is the published method exactly")
    return mode
