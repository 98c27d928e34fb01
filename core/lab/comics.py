"""Comics for the real-tools suite: line art over screentone, drawn like the drawings.

Screentone is the texture a recovery must not take for edges: dots on a 45-degree screen
whose size follows a gradient, and hatching. Shapes are hard-edged at ``k`` times O's size.

* ``manga``: black ink on white: panel borders, a figure with a speech balloon, a sky of
  grey-free dot tone (pitch 2.4 px, dots 0.3-1 px in radius), hatched shadows, solid blacks;
* ``comicstrip``: a coloured page: Ben-Day dots in red and cyan over yellow, cross
  hatching, heavy outlines and a caption box.
"""

import numpy as np

from .drawings import _grid, _paint, _stripes
from .scenes import _rgb8

__all__ = ["COMICS"]


def _dots(y, x, pitch, radius, angle=45.0):
    """A dot screen: inside a dot where the distance to the nearest screen node is under `radius` (array)."""
    theta = np.deg2rad(angle)
    u = x * np.cos(theta) + y * np.sin(theta)
    v = -x * np.sin(theta) + y * np.cos(theta)
    du = (u / pitch + 0.5) % 1 - 0.5
    dv = (v / pitch + 0.5) % 1 - 0.5
    return np.hypot(du, dv) * pitch < radius


def _mask_of(size, draw_shapes):
    from PIL import Image, ImageDraw
    image = Image.new("L", size, 0)
    draw_shapes(ImageDraw.Draw(image))
    return np.asarray(image) > 0


def _outline(canvas, size, k, ink, draw_shapes):
    _paint(canvas, _mask_of(size, draw_shapes), ink)


def _manga(height, width, k):
    h, w = height, width
    y, x = _grid(h, w, k)
    size = (w * k, h * k)
    canvas = np.ones((h * k, w * k, 3), np.float32)
    black = (0.04, 0.04, 0.05)
    # Two panels side by side above one wide panel.
    panels = ((0.03, 0.03, 0.48, 0.52), (0.52, 0.03, 0.97, 0.52), (0.03, 0.56, 0.97, 0.97))
    boxes = [(x0 * w, y0 * h, x1 * w, y1 * h) for x0, y0, x1, y1 in panels]
    # Panel 1: a sky tone, dots growing downwards.
    x0, y0, x1, y1 = boxes[0]
    inside = (x > x0) & (x < x1) & (y > y0) & (y < y1)
    radius = 0.3 + 0.7 * np.clip((y - y0) / (y1 - y0), 0, 1)
    _paint(canvas, inside & _dots(y, x, 2.4, radius), black)
    # Panel 2: a head with hatched shadow and a speech balloon.
    x0, y0, x1, y1 = boxes[1]
    cx, cy, r = (x0 + x1) / 2 - 4, (y0 + y1) / 2 + 6, 0.28 * (x1 - x0)
    head = np.hypot(x - cx, y - cy) < r
    _paint(canvas, head & (x > cx + 0.2 * r) & _stripes(y, x, -45, 1.8, 0.5), black)
    _outline(canvas, size, k, black, lambda d: d.ellipse(((cx - r) * k, (cy - r) * k, (cx + r) * k,
                                                                 (cy + r) * k), outline=255,
                                                                width=max(1, round(0.9 * k))))
    _paint(canvas, np.hypot(x - (cx - 0.35 * r), y - (cy - 0.1 * r)) < 0.12 * r, black)  # eyes
    _paint(canvas, np.hypot(x - (cx + 0.25 * r), y - (cy - 0.1 * r)) < 0.12 * r, black)
    bx, by = x1 - 12, y0 + 6
    balloon = ((x - bx) / 9) ** 2 + ((y - by) / 4.5) ** 2
    _paint(canvas, (balloon < 1.0) & (balloon > 0.78), black)
    # Panel 3: a street: hatched wall, solid black windows, a dot-tone road with a gradient.
    x0, y0, x1, y1 = boxes[2]
    wall = (x > x0) & (x < x0 + 0.45 * (x1 - x0)) & (y > y0) & (y < y1)
    _paint(canvas, wall & (_stripes(y, x, 0, 2.0, 0.6) | _stripes(y, x, 90, 2.0, 0.6)), black)
    for i in range(3):
        wx = x0 + 3 + i * 0.14 * (x1 - x0)
        _paint(canvas, (x > wx) & (x < wx + 4) & (y > y0 + 4) & (y < y0 + 10), black)
    road = (x > x0 + 0.45 * (x1 - x0)) & (x < x1) & (y > y0) & (y < y1)
    fade = 0.25 + 0.6 * np.clip((x - x0) / (x1 - x0), 0, 1)
    _paint(canvas, road & _dots(y, x, 2.0, fade, angle=30), black)
    for box in boxes:  # panel borders over everything
        _outline(canvas, size, k, black,
                 lambda d, b=box: d.rectangle(tuple(v * k for v in b), outline=255, width=max(1, round(1.2 * k))))
    return canvas


def _comicstrip(height, width, k):
    h, w = height, width
    y, x = _grid(h, w, k)
    size = (w * k, h * k)
    canvas = np.empty((h * k, w * k, 3), np.float32)
    canvas[:] = np.array(_rgb8((0.99, 0.93, 0.55)), np.float32) / 255
    black, red, cyan = (0.05, 0.04, 0.06), (0.9, 0.18, 0.2), (0.1, 0.65, 0.85)
    left = x < 0.5 * w
    _paint(canvas, left & _dots(y, x, 2.2, np.full_like(x, 0.75), angle=15), red)
    _paint(canvas, ~left & _dots(y, x, 2.6, 0.35 + 0.6 * np.clip(y / h, 0, 1), angle=75), cyan)
    # A figure: a cross-hatched body, a round head, heavy outlines.
    cx, cy = 0.3 * w, 0.55 * h
    body = (np.abs(x - cx) < 0.12 * w) & (y > cy) & (y < 0.9 * h)
    canvas[body] = np.array(_rgb8((1, 1, 1)), np.float32) / 255
    _paint(canvas, body & (_stripes(y, x, 45, 2.2, 0.55) | _stripes(y, x, -45, 2.2, 0.55)), black)
    head = np.hypot(x - cx, y - (cy - 0.12 * h)) < 0.1 * w
    canvas[head] = np.array(_rgb8((0.98, 0.82, 0.68)), np.float32) / 255
    _outline(canvas, size, k, black, lambda d: (
        d.rectangle(((cx - 0.12 * w) * k, cy * k, (cx + 0.12 * w) * k, 0.9 * h * k), outline=255,
                    width=max(1, round(1.0 * k))),
        d.ellipse(((cx - 0.1 * w) * k, (cy - 0.12 * h - 0.1 * w) * k, (cx + 0.1 * w) * k,
                   (cy - 0.12 * h + 0.1 * w) * k), outline=255, width=max(1, round(0.8 * k)))))
    # A lightning bolt, solid red with a black outline, and a caption box.
    bolt = [(0.62 * w, 0.15 * h), (0.8 * w, 0.15 * h), (0.72 * w, 0.4 * h), (0.86 * w, 0.4 * h),
            (0.6 * w, 0.8 * h), (0.68 * w, 0.48 * h), (0.56 * w, 0.48 * h)]
    _paint(canvas, _mask_of(size, lambda d: d.polygon([(px * k, py * k) for px, py in bolt], fill=255)), red)
    _outline(canvas, size, k, black, lambda d: d.line([(px * k, py * k) for px, py in bolt + bolt[:1]],
                                                             fill=255, width=max(1, round(0.7 * k)), joint="curve"))
    caption = (x > 0.04 * w) & (x < 0.46 * w) & (y > 0.04 * h) & (y < 0.2 * h)
    canvas[caption] = np.array(_rgb8((1, 1, 1)), np.float32) / 255
    _outline(canvas, size, k, black, lambda d: d.rectangle((0.04 * w * k, 0.04 * h * k, 0.46 * w * k,
                                                                   0.2 * h * k), outline=255,
                                                                  width=max(1, round(0.6 * k))))
    for i in range(2):  # lettering stand-ins: short thick strokes in the caption
        ty = (0.09 + 0.06 * i) * h
        _paint(canvas, (x > 0.07 * w) & (x < (0.42 - 0.1 * i) * w) & (np.abs(y - ty) < 0.5) &
               ((x * 0.9) % 4 < 3.0), black)
    return canvas


#: Family name -> ``render(height, width, k) -> float32 (height * k, width * k, 3)``, sRGB.
COMICS = {"manga": _manga, "comicstrip": _comicstrip}
