"""The panel's status lines: the pair, what the last recovery did, timings, zoom, the pixel.

The plan line says what the engine's last run did (``Engine.last_plan``) in one short line,
e.g. ``safe: point-wise filter on hard-edged content, full strength, blend in sRGB``; its
tooltip is the plan's whole reason. The line is made of :data:`PLAN_PHRASES`, so a new
figure of the last run is one more function there.
"""

import re
from typing import NamedTuple, Optional

from imgui_bundle import imgui

from .view_input import window_to_view

__all__ = ["StatusLine", "status_lines", "plan_line", "PLAN_PHRASES"]


class StatusLine(NamedTuple):
    """One status line and, optionally, more about it (shown as a tooltip)."""

    text: str
    detail: Optional[str] = None


# A plan's reason reads "finding (figures): decision, ..."; its first clause, without the
# figures, is what was found.
_FIGURES = re.compile(r"\s*\([^()]*\)")
_CLAUSE_END = re.compile(r"[:;,]")


def _finding(engine, summary):
    """What the plan found: the first clause of its reason (``point-wise filter ...``)."""
    return _CLAUSE_END.split(_FIGURES.sub("", engine.last_plan.reason), maxsplit=1)[0].strip() or None


def _strength(engine, summary):
    plan = engine.last_plan
    strength = plan.strength
    if strength == 0:
        return "F shown unchanged"
    if plan.local is not None:
        return f"strength {strength:.2g} on text and drawings, {strength * plan.local.textured:.2g} on photo"
    return "full strength" if strength == 1 else f"strength {strength:.2g}"


def _blend_space(engine, summary):
    plan = engine.last_plan
    if plan.strength == 0:
        return None
    return "blend in sRGB" if plan.blend_space == "srgb" else "blend in linear light"


def _how_to_force(engine, summary):
    plan = engine.last_plan
    if plan.strength != 0:
        return None
    if plan.forcing is None or plan.forcing.helps:
        return "untick auto strength to force a repair"
    return f"forcing a repair risks {plan.forcing.why}"


def _repaired_share(engine, summary):
    """The share of edge pixels repaired, once the shown R has been summarized."""
    if summary is None or summary.plan != engine.last_plan or engine.last_plan.strength == 0:
        return None
    return f"{summary.edge_share:.0%} of edge pixels repaired"


#: The phrases of the plan line, in order. Each takes the engine after a run (its
#: ``last_plan``) and the summary of the shown R (``aarecovery.RecoverySummary`` or None
#: while it is being made) and returns a short phrase, or None to say nothing.
PLAN_PHRASES = (_finding, _repaired_share, _strength, _blend_space, _how_to_force)


def plan_line(engine, summary=None):
    """What the engine's last run did, as one :class:`StatusLine`, or None before the first run.

    Parameters
    ----------
    engine : aarecovery.Engine
    summary : aarecovery.RecoverySummary, optional
        What the shown R repaired (``LiveRecovery.summary``).
    """
    if engine.last_plan is None:
        return None
    phrases = [phrase for phrase in (describe(engine, summary) for describe in PLAN_PHRASES) if phrase]
    return StatusLine(f"{engine.last_plan.mode}: {', '.join(phrases)}", engine.last_plan.reason)


def status_lines(app):
    """The status lines of one frame, top to bottom.

    Parameters
    ----------
    app : ViewerApp

    Returns
    -------
    list of StatusLine
    """
    engine = app.engine
    pair = app.recovery.pair
    lines = []
    if pair is not None:
        width, height = pair.size
        lines.append(StatusLine(f"{width} x {height}  {pair.filtered.dtype}  backend {engine.backend}"))
        plan = plan_line(engine, app.recovery.summary)
        if plan is not None:
            lines.append(plan)
        order = app.recovery.order
        if order is not None and order.looks_reversed:
            lines.append(StatusLine("ORIGINAL and FILTERED look swapped", order.reason))
        if engine.last_seconds is not None:
            lines.append(StatusLine(f"last recovery {engine.last_seconds * 1000:.1f} ms"))
        area, scale = app.image_area()
        mouse = imgui.get_io().mouse_pos
        pixel = app.view.pixel_at(*window_to_view(mouse.x, mouse.y, area, scale))
        where = f"  pixel ({pixel[0]}, {pixel[1]})" if pixel else ""
        lines.append(StatusLine(f"zoom {app.view.zoom * 100:.4g}%{where}"))
    else:
        lines.append(StatusLine(f"no images  backend {engine.backend}"))
    if app.frame_seconds is not None:
        lines.append(StatusLine(f"frame {app.frame_seconds * 1000:.1f} ms"))
    return lines
