"""aarecovery: repair antialiased edges damaged by nonlinear image filters.

The method is "Antialiasing Recovery" (Yang, Sander, Lawrence and Hoppe, ACM TOG 2011):
fit a two-colour blend model at every edge pixel of the original image O and make the
filtered image F show the same blend with its own colours.

Every function takes images as NumPy arrays ``(H, W)`` or ``(H, W, C)`` with C in 1..4
(grey, grey+alpha, RGB, RGBA), uint8, uint16 or float in [0, 1], sRGB-encoded unless
declared linear, row 0 at the top, straight alpha.

The public API is what ``__all__`` lists; the subpackages are the implementation, laid out
in ``docs/architecture.md``.
"""

__version__ = "0.1.0"

from . import filters
from .backends.base import Decision, Plan, RecoveryMaps
from .backends import GLUnavailable
from .batch import recover_many
from .engine import Engine
from .errors import InputError, OrderWarning, OrientationWarning
from .io import read_image, read_quantization, write_image
from .outcome import RecoverySummary, summarize_recovery
from .params import BACKENDS, BLEND_SPACES, GL_PATHS, MODES, PARAMETERS
from .pipeline import recover
from .plan.order import check_order

__all__ = ["recover", "recover_many", "check_order", "summarize_recovery", "Engine", "Plan", "Decision", "RecoveryMaps",
           "RecoverySummary", "InputError", "GLUnavailable", "OrderWarning", "OrientationWarning", "read_image",
           "read_quantization",
           "write_image", "filters", "PARAMETERS", "BACKENDS", "GL_PATHS", "MODES", "BLEND_SPACES", "__version__"]
