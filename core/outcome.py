"""What a recovery did, in one line: the share of edge pixels repaired, the strength, the blend
space, and when F came back unchanged, why and how to force a repair.

The command line prints it after ``recover`` and ``filter --recover``; the viewer shows it in
its status line and the GIMP plug-in in its message; the Python API gives it with
:func:`summarize_recovery` (the plan is ``Engine.last_plan``).
"""

from dataclasses import dataclass

import numpy as np

from .contract import layout_of, to_rgba_float
from .plan.calibration import EDGE_GRADIENT
from .sample import analysis_window
from .spec.local_plan import encoded_colour
from .spec.sobel import gradient_magnitude

__all__ = ["RecoverySummary", "summarize_recovery", "count_changed_pixels"]

# A pixel counts as repaired when R differs from F there by more than half an 8-bit step.
_CHANGED = 0.5 / 255
# Rows compared at once: the count stays a few MB of memory on a gigapixel pair.
_STRIP_ROWS = 256


@dataclass(frozen=True)
class RecoverySummary:
    """What one recovery did.

    Attributes
    ----------
    plan : Plan
        Mode, blend space, strength, pure colours, the decision's name and the reason.
    changed_pixels : int or None
        Pixels of the whole image where R differs from F by more than half an 8-bit step
        (None when not counted: a pair streamed from file to file is never whole in memory).
    edge_share : float or None
        The share of O's edge pixels (a Sobel / 8 of 0.02 or more) where R differs from F,
        measured on the window of at most 512 x 512 pixels that the safe default analyses
        (0 when it has no edge; None when not measured).
    hard_edged_share : float or None
        With a local plan: the share of those edge pixels that lie in regions read as
        hard-edged (repaired at full strength); None without one.
    """

    plan: object
    changed_pixels: int
    edge_share: float
    hard_edged_share: float = None

    @property
    def decision(self):
        """Decision: which exit of the plan was taken (``plan.decision``)."""
        return self.plan.decision

    def line(self, force="strength=1"):
        """The one line; `force` names the way to ask for a repair (``--strength 1`` on
        the command line, the dialog's control in the plug-in)."""
        plan = self.plan
        if plan.keeps_filtered:
            return f"returned F unchanged ({plan.mode} mode, {plan.decision}): {plan.reason}; {_forcing(plan, force)}"
        pure = ", pure colours of thin features" if plan.pure_colours is not None else ""
        ramps = ", the filter's steps antialiased across smooth gradients" if plan.ramp_table is not None else ""
        what = ("repaired the edges" if self.edge_share is None else
                f"repaired {self.edge_share:.0%} of the edge pixels ({self.changed_pixels} pixels changed)")
        return (f"{what} in {plan.mode} mode ({plan.decision}): {self._strength()}, blend in {plan.blend_space}"
                f"{pure}{ramps}")

    def _strength(self):
        plan = self.plan
        if plan.local is None:
            return f"strength {plan.strength:g}"
        if self.hard_edged_share is None:
            return f"strength {plan.strength:g} where hard-edged, {plan.strength * plan.local.textured:g} where textured"
        return (f"text and drawings {self.hard_edged_share:.0%} of the edges at strength {plan.strength:g}, "
                f"{plan.local.textured_regions} {1 - self.hard_edged_share:.0%} at "
                f"{plan.strength * plan.local.textured:g}")


def _forcing(plan, force):
    """How to force a repair where the analysis found it may help, else what forcing risks."""
    forcing = plan.forcing
    if forcing is None:
        return f"to repair anyway, use {force}"
    if forcing.helps:
        return f"a forced repair may help ({forcing.why}): use {force}"
    return f"forcing a repair ({force}) risks {forcing.why}"


def _changed(filtered, recovered):
    """bool array: R differs from F by more than half an 8-bit step in some channel."""
    scale = {np.dtype(np.uint8): 255, np.dtype(np.uint16): 65535}.get(filtered.dtype, 1)
    if scale == 1:
        def differs(f, r):
            return np.abs(r.astype(np.float32) - f) > np.float32(_CHANGED)
    else:
        # Integers differ by more than a fraction x when they differ by more than floor(x),
        # counted in their own type: no float copies.
        steps = filtered.dtype.type(int(_CHANGED * scale))

        def differs(f, r):
            return np.maximum(f, r) - np.minimum(f, r) > steps
    if filtered.ndim == 2:
        return differs(filtered, recovered)
    # Channel by channel: a maximum over a last axis of 3 or 4 is NumPy's slowest reduction
    # (1.9 s against 0.1 s for a 4096 x 4096 RGB pair).
    changed = np.zeros(filtered.shape[:2], bool)
    for channel in range(filtered.shape[2]):
        changed |= differs(filtered[..., channel], recovered[..., channel])
    return changed


def count_changed_pixels(filtered, recovered):
    """Pixels where `recovered` differs from `filtered` by more than half an 8-bit step, in
    strips of rows (a few MB of memory whatever the size: it can run beside the encoder)."""
    height = layout_of(filtered, "filtered").height
    return sum(int(_changed(filtered[top:top + _STRIP_ROWS], recovered[top:top + _STRIP_ROWS]).sum())
               for top in range(0, height, _STRIP_ROWS))


def summarize_recovery(plan, original, filtered, recovered, linear=False, *, changed_pixels=None,
                       original_window=None):
    """Summarize a recovery of `original` and `filtered` into `recovered` under `plan`.

    Parameters
    ----------
    plan : Plan
        The plan it ran (``Engine.last_plan``; :func:`aarecovery.recover` keeps it on the
        engine it is given).
    original, filtered, recovered : ndarray
        As given to and returned by :func:`aarecovery.recover`; `recovered` has the shape
        and dtype of `filtered`. `original` may be None with `original_window`.
    linear : bool
        The images hold linear-light values (as given to ``recover``).
    changed_pixels : int, optional
        :func:`count_changed_pixels` of the pair when already counted.
    original_window : ndarray, optional
        ``original[plan.window]``, the only part of O the summary reads, when the caller kept
        that and freed the rest (the command line does, before it encodes the result).

    Returns
    -------
    RecoverySummary
    """
    if original_window is not None and plan.window is None:
        raise ValueError("original_window needs the plan's window (Plan.window): give the whole original instead")
    f_layout = layout_of(filtered, "filtered")
    if changed_pixels is None:
        changed_pixels = count_changed_pixels(filtered, recovered)
    # The window the plan analysed, when it says (choosing it again costs 50 ms at 4096^2).
    window = plan.window or analysis_window(lambda rows, cols: original[rows, cols], f_layout.height, f_layout.width)
    o_window = original[window] if original_window is None else original_window
    o_rgba = to_rgba_float(o_window, layout_of(o_window, "original"), "original")
    edges = gradient_magnitude(o_rgba[..., :3]) >= EDGE_GRADIENT
    share = float(_changed(filtered[window], recovered[window])[edges].mean()) if edges.any() else 0.0
    return RecoverySummary(plan, changed_pixels, share, _hard_edged_share(plan, o_rgba, edges, linear))


def _hard_edged_share(plan, o_rgba, edges, linear):
    """The share of the window's edge pixels that the local plan repairs nearer full strength."""
    if plan.local is None or not edges.any():
        return None
    return plan.local.hard_edged_share(encoded_colour(o_rgba, linear), edges)
