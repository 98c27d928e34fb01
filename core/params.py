"""Every recovery parameter once: its default, its valid range, its help text.

The command line, the viewer's sliders, the GIMP plug-in's dialog and the Python API all
take their defaults, ranges and help from :data:`PARAMETERS` (the plug-in script runs in
GIMP's own Python, which may not import the core, so it repeats them; a test checks that
they match). Nothing else in the project writes these numbers.
"""

import math
import numbers
from dataclasses import dataclass

from .errors import InputError

__all__ = ["ParameterSpec", "PARAMETERS", "SIGMA_D", "SIGMA_E", "ITERATIONS", "STRENGTH", "Parameters", "MODES",
           "DEFAULT_MODE", "BLEND_SPACES", "BACKENDS", "GL_PATHS", "check_mode", "check_blend_space", "check_backend",
           "check_gl_path"]


@dataclass(frozen=True)
class ParameterSpec:
    """One recovery parameter.

    Attributes
    ----------
    name : str
        The Python keyword (``sigma_d``); the command-line option is :attr:`option`.
    default : float or int
        The paper's value (Yang et al. 2011, section 3.3).
    minimum, maximum : float or int
        The valid range, inclusive. Beyond it the passes either overflow float32 or stop
        changing the result, so values outside are refused, not clipped.
    kind : type
        ``float`` or ``int``.
    logarithmic : bool
        Whether a slider over the range should be logarithmic.
    label : str
        A short name for dialogs and sliders.
    help : str
        One line for ``--help`` and tooltips.
    automatic : str
        Empty for a parameter that always has a value. Otherwise None is a valid value (and
        the default), meaning what this says: the safe default decides.
    """

    name: str
    default: object
    minimum: object
    maximum: object
    kind: type
    logarithmic: bool
    label: str
    help: str
    automatic: str = ""

    @property
    def option(self):
        """str: the command-line option, ``--sigma-d``."""
        return "--" + self.name.replace("_", "-")

    def check(self, value):
        """Return `value` as this parameter's kind, or raise :class:`InputError`.

        NumPy scalars are accepted (``np.float32(0.1)``, ``np.int64(3)``); booleans are not.
        """
        if value is None and self.automatic:
            return None
        number = numbers.Integral if self.kind is int else numbers.Real
        if isinstance(value, bool) or not isinstance(value, number) or (
                self.kind is float and not math.isfinite(value)) or not self.minimum <= value <= self.maximum:
            usual = (f"leave it out for {self.automatic}" if self.automatic
                     else f"the paper's value is {self.default:g}")
            raise InputError(f"{self.name} must be {'a whole number' if self.kind is int else 'a number'} "
                             f"from {self.minimum:g} to {self.maximum:g}, got {value!r}; {usual}")
        return self.kind(value)


SIGMA_D = ParameterSpec(
    "sigma_d", 0.1, 0.001, 1.0, float, True, "sigma_d",
    "colour-line distance scale: neighbours further than 3 sigma_d from the colour line are not "
    "blend candidates, and a poor fit lowers the confidence; larger accepts noisier colour lines")
SIGMA_E = ParameterSpec(
    "sigma_e", 0.01, 0.0001, 1.0, float, True, "sigma_e",
    "edge-strength scale: an edge of strength e gets confidence 1 - exp(-(e/sigma_e)^2); "
    "smaller repairs weaker edges")
ITERATIONS = ParameterSpec(
    "iterations", 3, 0, 64, int, False, "iterations",
    "Jacobi iterations of the recovery solve; 0 returns the filtered image")

STRENGTH = ParameterSpec(
    "strength", None, 0.0, 1.0, float, False, "strength",
    "how much to repair, from 0 (F as it is) to 1 (the full repair); overrides the strength the "
    "safe default chooses, and forces a repair where it keeps F",
    automatic="the strength the safe default chooses per image")

#: The parameters by name, in the order interfaces show them.
PARAMETERS = {spec.name: spec for spec in (SIGMA_D, SIGMA_E, ITERATIONS, STRENGTH)}

#: ``"safe"``: the default, with per-image safeguards (``aarecovery.plan``); ``"paper"``:
#: Yang et al. 2011 exactly.
MODES = ("safe", "paper")
DEFAULT_MODE = MODES[0]
#: Where the two-colour model can be fitted: linear light or sRGB-encoded values.
BLEND_SPACES = ("linear", "srgb")
#: ``"auto"`` uses OpenGL and falls back to NumPy with a warning.
BACKENDS = ("auto", "gl", "numpy")
#: How the GL backend runs its passes: ``"auto"`` chooses by the context's capabilities and
#: a measured rule (``aarecovery.backends.gl.paths``), ``"fragment"`` draws (OpenGL 3.3),
#: ``"compute"`` dispatches compute shaders (OpenGL 4.3).
GL_PATHS = ("auto", "fragment", "compute")


@dataclass(frozen=True)
class Parameters:
    """The user's recovery parameters, checked against :data:`PARAMETERS`.

    Attributes
    ----------
    sigma_d, sigma_e : float
    iterations : int
    strength : float or None
        None: the safe default's (the paper's 1 in paper mode).
    """

    sigma_d: float = SIGMA_D.default
    sigma_e: float = SIGMA_E.default
    iterations: int = ITERATIONS.default
    strength: float = STRENGTH.default

    def __post_init__(self):
        for spec in PARAMETERS.values():
            object.__setattr__(self, spec.name, spec.check(getattr(self, spec.name)))


def _check_choice(value, name, choices, advice=""):
    if not isinstance(value, str) or value not in choices:
        raise InputError(f"{name} must be one of {', '.join(choices)}, got {value!r}{advice}")
    return value


def check_blend_space(blend_space):
    """Raise unless `blend_space` is one of :data:`BLEND_SPACES`."""
    return _check_choice(blend_space, "blend_space", BLEND_SPACES)


def check_mode(mode):
    """Raise unless `mode` is one of :data:`MODES`."""
    return _check_choice(mode, "mode", MODES, ": 'safe' (the default) guards against harming blurred or "
                                              "textured images, 'paper' is the published method exactly")


def check_backend(backend):
    """Raise unless `backend` is one of :data:`BACKENDS`."""
    return _check_choice(backend, "backend", BACKENDS)


def check_gl_path(gl_path):
    """Raise unless `gl_path` is one of :data:`GL_PATHS`."""
    return _check_choice(gl_path, "gl_path", GL_PATHS)
