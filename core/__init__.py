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

import importlib

# The public names are imported where first used (PEP 562, as scikit-image's are), so that a
# command imports what it runs: `import aarecovery` took 0.19 s when it imported the batch
# engine, the filters' catalogue and every subpackage behind them.
_PUBLIC = {
    "recover": "pipeline", "recover_many": "batch", "check_order": "plan.order",
    "summarize_recovery": "outcome", "RecoverySummary": "outcome", "Engine": "engine",
    "Plan": "backends.base", "Decision": "backends.base", "RecoveryMaps": "backends.base",
    "GLUnavailable": "backends", "InputError": "errors", "OrderWarning": "errors",
    "OrientationWarning": "errors", "read_image": "io", "read_quantization": "io", "write_image": "io",
    "PARAMETERS": "params", "BACKENDS": "params", "GL_PATHS": "params", "MODES": "params",
    "BLEND_SPACES": "params", "filters": None,  # None: the subpackage itself
}


def __getattr__(name):
    if name not in _PUBLIC:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    module = _PUBLIC[name]
    value = (importlib.import_module(f".{name}", __name__) if module is None
             else getattr(importlib.import_module(f".{module}", __name__), name))
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))


__all__ = ["recover", "recover_many", "check_order", "summarize_recovery", "Engine", "Plan", "Decision", "RecoveryMaps",
           "RecoverySummary", "InputError", "GLUnavailable", "OrderWarning", "OrientationWarning", "read_image",
           "read_quantization",
           "write_image", "filters", "PARAMETERS", "BACKENDS", "GL_PATHS", "MODES", "BLEND_SPACES", "__version__"]
