"""The panel's status lines: the pair, the backend, timings, the zoom and the pixel under the cursor."""

from imgui_bundle import imgui

from .view_input import window_to_view

__all__ = ["status_lines"]


def status_lines(app):
    """The status lines of one frame, top to bottom.

    Parameters
    ----------
    app : ViewerApp

    Returns
    -------
    list of str
    """
    engine = app.engine
    pair = app.recovery.pair
    lines = []
    if pair is not None:
        width, height = pair.size
        lines.append(f"{width} x {height}  {pair.filtered.dtype}  backend {engine.backend}")
        if engine.last_seconds is not None:
            lines.append(f"last recovery {engine.last_seconds * 1000:.1f} ms")
        area, scale = app.image_area()
        mouse = imgui.get_io().mouse_pos
        pixel = app.view.pixel_at(*window_to_view(mouse.x, mouse.y, area, scale))
        where = f"  pixel ({pixel[0]}, {pixel[1]})" if pixel else ""
        lines.append(f"zoom {app.view.zoom * 100:.4g}%{where}")
    else:
        lines.append(f"no images  backend {engine.backend}")
    if app.frame_seconds is not None:
        lines.append(f"frame {app.frame_seconds * 1000:.1f} ms")
    return lines
