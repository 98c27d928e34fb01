"""aarecovery: repair antialiased edges damaged by nonlinear image filters.

The method is "Antialiasing Recovery" (Yang, Sander, Lawrence and Hoppe, ACM TOG 2011):
fit a two-colour blend model at every edge pixel of the original image O and make the
filtered image F show the same blend with its own colours.

Every function takes images as NumPy arrays ``(H, W)`` or ``(H, W, C)`` with C in 1..4
(grey, grey+alpha, RGB, RGBA), uint8, uint16 or float in [0, 1], sRGB-encoded unless
declared linear, row 0 at the top, straight alpha.
"""

from . import filters
from ._engine import BACKENDS, Engine, RecoveryMaps
from ._errors import InputError
from ._io import read_image, write_image
from ._params import BLEND_SPACES, MODES
from ._recover import recover

__version__ = "0.1.0"

__all__ = ["recover", "Engine", "RecoveryMaps", "InputError", "read_image", "write_image", "filters",
           "BACKENDS", "MODES", "BLEND_SPACES", "__version__"]
