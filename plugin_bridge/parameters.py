"""The recovery parameters as the plug-ins' dialogs offer them.

A host's Python may not import the core, so the table repeats ``aarecovery.PARAMETERS``;
tests/gimp/test_install.py checks that every row matches.
"""

__all__ = ["RECOVERY_ARGUMENTS", "AUTOMATIC_ARGUMENTS", "BACKENDS", "dialog_order", "core_params"]

# (argument name, dialog label, kind, minimum, maximum, default, help). A default of None
# means the safe default chooses: the dialog then has a box ticked for that
# (AUTOMATIC_ARGUMENTS: its argument name, label and help), and the value starts at the maximum.
RECOVERY_ARGUMENTS = (
    ("sigma-d", "Sigma _d", "float", 0.001, 1.0, 0.1,
     "colour-line distance scale: neighbours further than 3 sigma_d from the colour line are "
     "not blend candidates, and a poor fit lowers the confidence; larger accepts noisier "
     "colour lines"),
    ("sigma-e", "Sigma _e", "float", 0.0001, 1.0, 0.01,
     "edge-strength scale: an edge of strength e gets confidence 1 - exp(-(e/sigma_e)^2); "
     "smaller repairs weaker edges"),
    ("iterations", "_Iterations", "int", 0, 64, 3,
     "Jacobi iterations of the recovery solve; 0 returns the filtered image"),
    ("strength", "_Strength", "float", 0.0, 1.0, None,
     "how much to repair, from 0 (F as it is) to 1 (the full repair); overrides the strength the "
     "safe default chooses, and forces a repair where it keeps F"),
)
AUTOMATIC_ARGUMENTS = {
    "strength": ("auto-strength", "_Automatic strength", "the strength the safe default chooses per image"),
}
BACKENDS = ("auto", "gl", "numpy")


def core_params(value, backend, linear, clip_filtered):
    """The worker's parameters from the dialog's values.

    Parameters
    ----------
    value : callable
        Returns a dialog value by argument name ("sigma-d", "auto-strength", ...).
    backend : str
        One of BACKENDS.
    linear : bool
        The pixels are linear light.
    clip_filtered : bool
        Clip F to [0, 1] first: a host filter may overshoot on a float layer, which an integer
        layer would have clipped.
    """
    recovery = {name.replace("-", "_"): None if name in AUTOMATIC_ARGUMENTS and value(
                    AUTOMATIC_ARGUMENTS[name][0]) else value(name)
                for name, *_ in RECOVERY_ARGUMENTS}
    return {**recovery, "backend": backend, "linear": linear, "clip_filtered": clip_filtered}


def dialog_order():
    """The argument names in the order a dialog shows them, each automatic box first."""
    return [part for name, *_ in RECOVERY_ARGUMENTS
            for part in ([AUTOMATIC_ARGUMENTS[name][0]] if name in AUTOMATIC_ARGUMENTS else []) + [name]]
