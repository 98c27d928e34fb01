"""Hard-edged drawings for the real-tools suite: the kinds of content users filter in editors.

Each family is drawn without antialiasing at ``k`` times the target resolution (hard edges,
flat 8-bit colours), like :mod:`aarecovery.lab.scenes`, so that the box-downsampled original
is an exact blend of the colours either side of every edge. Widths below are in target
pixels; at ``k = 8`` a 0.3 px contour is 2 to 3 scene pixels wide.

* ``maps``: contour lines 0.3-0.8 px, a river, roads 0.6-2 px with casings, a railway,
  park and lake fills;
* ``hatching``: shapes filled with dense parallel and cross hatching (period 1.6-3.5 px,
  strokes 0.4-1.2 px) in black, sepia and blue ink;
* ``serif``: text in DejaVu Serif (the Debian package ``fonts-dejavu-core``) at 7-14 px, on
  four ink/paper pairs;
* ``icons``: flat pictograms on coloured tiles, twelve colours;
* ``pies``: pie and donut charts with thin white separators, and a legend;
* ``inkart``: ink strokes whose width varies along curves (0.4-2.5 px), blots and ticks;
* ``starburst``: thin dark-blue spokes on tan (tapered wedges and 0.6 px lines);
* ``plots``: a line chart: grid, axes, curves 0.8-1.5 px, markers and tick labels.

Everything is deterministic (fixed seeds, fixed fonts).
"""

import os

import numpy as np

from ..errors import InputError
from .scenes import _pil_canvas, _rgb8, _to_float

__all__ = ["DRAWINGS", "SERIF_FONT"]

#: DejaVu Serif as the Debian package ``fonts-dejavu-core`` installs it (packaging/test.sh).
SERIF_FONT = "/usr/share/fonts/truetype/dejavu/DejaVuSerif.ttf"


def _serif(size, bold=False):
    from PIL import ImageFont
    path = SERIF_FONT.replace(".ttf", "-Bold.ttf") if bold else SERIF_FONT
    if not os.path.exists(path):
        raise InputError(f"the serif scene needs the font {path}; install the Debian package fonts-dejavu-core "
                         "(packaging/test.sh does)")
    return ImageFont.truetype(path, size)


def _grid(height, width, k):
    """Scene-pixel centres in target-pixel units: (y, x), each float64 of shape (H * k, W * k)."""
    yy, xx = np.mgrid[0:height * k, 0:width * k].astype(np.float64)
    return (yy + 0.5) / k, (xx + 0.5) / k


def _paint(canvas, mask, colour):
    canvas[mask] = np.array(_rgb8(colour), np.float32) / 255


def _polyline(draw, points, width, k, colour):
    scaled = [(float(x) * k, float(y) * k) for x, y in points]
    draw.line(scaled, fill=_rgb8(colour), width=max(1, int(round(width * k))), joint="curve")


def _maps(height, width, k):
    """A topographic map: contours, a river, roads with casings, a railway, park and lake."""
    from PIL import Image, ImageDraw
    h, w = height, width
    y, x = _grid(h, w, k)
    canvas = np.empty((h * k, w * k, 3), np.float32)
    canvas[:] = np.array(_rgb8((0.96, 0.94, 0.87)), np.float32) / 255
    lake = ((x - 0.72 * w) / (0.16 * w)) ** 2 + ((y - 0.3 * h) / (0.1 * h)) ** 2 < 1
    park = (x > 0.08 * w) & (x < 0.4 * w) & (y > 0.62 * h) & (y < 0.9 * h) & (x + y < 1.2 * (w + h) / 2)
    _paint(canvas, park, (0.75, 0.88, 0.66))
    # Contours of a smooth height field: |z - level| / |grad z| is the distance to the line.
    bumps = ((0.3, 0.35, 0.22, 1.0), (0.7, 0.7, 0.18, 0.8), (0.55, 0.15, 0.12, -0.5))
    z = np.zeros_like(x)
    gz_x, gz_y = np.zeros_like(x), np.zeros_like(x)
    for cx, cy, radius, amplitude in bumps:
        g = amplitude * np.exp(-(((x - cx * w) ** 2 + (y - cy * h) ** 2) / (2 * (radius * w) ** 2)))
        z += g
        gz_x += -g * (x - cx * w) / (radius * w) ** 2
        gz_y += -g * (y - cy * h) / (radius * w) ** 2
    interval = 0.08
    index = np.round(z / interval)
    distance = np.abs(z - index * interval) / np.maximum(np.hypot(gz_x, gz_y), 1e-9)
    line_width = np.where(index % 5 == 0, 0.8, 0.3)
    _paint(canvas, (distance < line_width / 2) & ~lake, (0.62, 0.42, 0.22))
    _paint(canvas, lake, (0.62, 0.8, 0.93))
    image = Image.fromarray(np.rint(canvas * 255).astype(np.uint8))
    draw = ImageDraw.Draw(image)
    t = np.linspace(0, 1, 60)
    river = [(w * (0.05 + 0.9 * s), h * (0.55 + 0.12 * np.sin(6 * s) + 0.05 * np.sin(17 * s))) for s in t]
    _polyline(draw, river, 1.2, k, (0.2, 0.45, 0.8))
    roads = ((((0.0, 0.15), (0.35, 0.25), (0.6, 0.45), (1.0, 0.5)), 2.0, (0.95, 0.6, 0.2)),
             (((0.2, 0.0), (0.25, 0.4), (0.45, 0.75), (0.5, 1.0)), 1.4, (1.0, 0.95, 0.55)),
             (((0.6, 0.45), (0.8, 0.8), (0.95, 1.0)), 1.0, (1.0, 1.0, 1.0)),
             (((0.0, 0.8), (0.3, 0.7), (0.55, 0.95)), 0.6, (1.0, 1.0, 1.0)))
    for points, road_width, colour in roads:
        scaled = [(px * w, py * h) for px, py in points]
        _polyline(draw, scaled, road_width + 0.5, k, (0.35, 0.3, 0.3))
        _polyline(draw, scaled, road_width, k, colour)
    rail = [(w * 0.05, h * 0.95), (w * 0.5, h * 0.6), (w * 0.98, h * 0.08)]
    _polyline(draw, rail, 0.5, k, (0.1, 0.1, 0.1))
    for s in np.linspace(0.05, 0.95, 24):  # sleepers across the railway
        px, py = w * (0.05 + 0.93 * s), h * (0.95 - 0.87 * s)
        _polyline(draw, [(px - 0.7, py - 0.8), (px + 0.7, py + 0.8)], 0.4, k, (0.1, 0.1, 0.1))
    return _to_float(image)


def _stripes(y, x, angle, period, stroke):
    theta = np.deg2rad(angle)
    across = x * np.cos(theta) + y * np.sin(theta)
    return (across % period) < stroke


def _hatching(height, width, k):
    """Shapes filled with parallel and cross hatching, outlined, on paper."""
    from PIL import Image, ImageDraw
    h, w = height, width
    y, x = _grid(h, w, k)
    canvas = np.empty((h * k, w * k, 3), np.float32)
    canvas[:] = np.array(_rgb8((0.99, 0.98, 0.95)), np.float32) / 255
    black, sepia, blue = (0.05, 0.05, 0.05), (0.4, 0.24, 0.12), (0.12, 0.2, 0.55)
    # (shape, box in fractions, hatch angles, period, stroke, ink)
    regions = (("ellipse", (0.04, 0.04, 0.46, 0.46), (30,), 2.0, 0.6, black),
               ("rectangle", (0.54, 0.06, 0.96, 0.42), (0, 90), 3.0, 0.8, black),
               ("polygon", (0.05, 0.52, 0.45, 0.96), (-45,), 1.6, 0.4, sepia),
               ("ellipse", (0.5, 0.5, 0.95, 0.95), (60, 120), 3.5, 1.2, blue),
               ("rectangle", (0.3, 0.3, 0.7, 0.7), (15,), 2.4, 0.5, sepia))
    for shape, (x0, y0, x1, y1), angles, period, stroke, ink in regions:
        mask_image = Image.new("L", (w * k, h * k), 0)
        draw = ImageDraw.Draw(mask_image)
        box = (x0 * w * k, y0 * h * k, x1 * w * k, y1 * h * k)
        if shape == "polygon":
            draw.polygon([(box[0], box[3]), ((box[0] + box[2]) / 2, box[1]), (box[2], box[3])], fill=255)
        else:
            getattr(draw, shape)(box, fill=255)
        inside = np.asarray(mask_image) > 0
        _paint(canvas, inside, (0.99, 0.98, 0.95))
        hatched = np.zeros_like(inside)
        for angle in angles:
            hatched |= _stripes(y, x, angle, period, stroke)
        _paint(canvas, inside & hatched, ink)
        outline = Image.new("L", (w * k, h * k), 0)
        draw = ImageDraw.Draw(outline)
        outline_width = max(1, int(round(0.7 * k)))
        if shape == "polygon":
            points = [(box[0], box[3]), ((box[0] + box[2]) / 2, box[1]), (box[2], box[3]), (box[0], box[3])]
            draw.line(points, fill=255, width=outline_width, joint="curve")
        else:
            getattr(draw, shape)(box, outline=255, width=outline_width)
        _paint(canvas, np.asarray(outline) > 0, ink)
    return canvas


def _serif_text(height, width, k):
    """DejaVu Serif at four sizes, on four ink/paper pairs."""
    bands = (((1, 0.99, 0.94), (0, 0, 0), 7, False), ((1, 1, 1), (0.05, 0.1, 0.4), 9, False),
             ((0.55, 0.05, 0.08), (1, 1, 1), 11, True), ((0.88, 0.9, 0.88), (0.0, 0.35, 0.15), 14, False))
    image, draw = _pil_canvas(height * k, width * k, (1, 1, 1))
    band = height * k / len(bands)
    words = "Quartz fjords vex the jackdaw; 1234567890 Sphinx of black quartz, judge my vow. "
    for i, (paper, ink, size, bold) in enumerate(bands):
        top = int(round(i * band))
        draw.rectangle((0, top, width * k, int(round((i + 1) * band))), fill=_rgb8(paper))
        font = _serif(size * k, bold)
        y, line = top + k, 0
        while y + size * k < (i + 1) * band:
            draw.text((k * (1 - 4 * line), y), words[line * 5:] + words, font=font, fill=_rgb8(ink))
            y += int(1.25 * size * k)
            line += 1
    return _to_float(image)


_ICON_COLOURS = ((0.9, 0.2, 0.2), (0.2, 0.6, 0.9), (0.15, 0.7, 0.3), (0.98, 0.75, 0.1), (0.55, 0.25, 0.75),
                 (0.1, 0.1, 0.1), (0.95, 0.45, 0.1), (0.0, 0.55, 0.55), (0.85, 0.3, 0.6), (0.4, 0.4, 0.45),
                 (0.2, 0.25, 0.7), (0.6, 0.8, 0.2))


def _icon(draw, kind, left, top, size, ink):
    s = size
    def at(fx, fy):
        return left + fx * s, top + fy * s
    if kind == 0:  # play triangle
        draw.polygon([at(0.32, 0.22), at(0.78, 0.5), at(0.32, 0.78)], fill=ink)
    elif kind == 1:  # plus
        draw.rectangle((*at(0.42, 0.2), *at(0.58, 0.8)), fill=ink)
        draw.rectangle((*at(0.2, 0.42), *at(0.8, 0.58)), fill=ink)
    elif kind == 2:  # house
        draw.polygon([at(0.5, 0.15), at(0.85, 0.48), at(0.15, 0.48)], fill=ink)
        draw.rectangle((*at(0.25, 0.48), *at(0.75, 0.82)), fill=ink)
    elif kind == 3:  # five-pointed star
        angles = np.deg2rad(np.arange(10) * 36 - 90)
        radii = np.where(np.arange(10) % 2 == 0, 0.38, 0.16)
        draw.polygon([at(0.5 + r * np.cos(a), 0.52 + r * np.sin(a)) for r, a in zip(radii, angles)], fill=ink)
    elif kind == 4:  # magnifier: ring and handle
        draw.ellipse((*at(0.18, 0.18), *at(0.62, 0.62)), outline=ink, width=max(1, int(0.09 * s)))
        draw.line([at(0.56, 0.56), at(0.82, 0.82)], fill=ink, width=max(1, int(0.12 * s)))
    elif kind == 5:  # check mark
        draw.line([at(0.2, 0.52), at(0.42, 0.74), at(0.8, 0.28)], fill=ink, width=max(1, int(0.12 * s)),
                  joint="curve")
    elif kind == 6:  # envelope
        draw.rectangle((*at(0.16, 0.28), *at(0.84, 0.72)), outline=ink, width=max(1, int(0.07 * s)))
        draw.line([at(0.16, 0.28), at(0.5, 0.54), at(0.84, 0.28)], fill=ink, width=max(1, int(0.07 * s)))
    else:  # heart
        draw.ellipse((*at(0.18, 0.22), *at(0.52, 0.56)), fill=ink)
        draw.ellipse((*at(0.48, 0.22), *at(0.82, 0.56)), fill=ink)
        draw.polygon([at(0.2, 0.45), at(0.8, 0.45), at(0.5, 0.82)], fill=ink)


def _icons(height, width, k):
    """Flat pictograms on rounded tiles of twelve colours, 18 px apart."""
    image, draw = _pil_canvas(height * k, width * k, (1, 1, 1))
    pitch, size = 18, 15
    rows, cols = max(1, (height - 2) // pitch), max(1, (width - 2) // pitch)
    n = 0
    for r in range(rows):
        for c in range(cols):
            left, top = (2 + c * pitch + (c % 2) * 0.37) * k, (2 + r * pitch + (r % 3) * 0.29) * k
            tile = _ICON_COLOURS[n % len(_ICON_COLOURS)]
            draw.rounded_rectangle((left, top, left + size * k, top + size * k), radius=3 * k, fill=_rgb8(tile))
            ink = (1, 1, 1) if n % 3 else _ICON_COLOURS[(n + 5) % len(_ICON_COLOURS)]
            _icon(draw, n % 8, left, top, size * k, _rgb8(ink))
            n += 1
    return _to_float(image)


_PIE_COLOURS = ((0.12, 0.47, 0.71), (1.0, 0.5, 0.05), (0.17, 0.63, 0.17), (0.84, 0.15, 0.16),
                (0.58, 0.4, 0.74), (0.55, 0.34, 0.29), (0.89, 0.47, 0.76), (0.5, 0.5, 0.5))


def _pie(draw, centre, radius, shares, k, hole=0.0):
    cx, cy = centre
    box = (cx - radius, cy - radius, cx + radius, cy + radius)
    start = -90.0
    edges = []
    for i, share in enumerate(shares):
        end = start + 360 * share
        draw.pieslice(box, start, end, fill=_rgb8(_PIE_COLOURS[i % len(_PIE_COLOURS)]))
        edges.append(start)
        start = end
    for angle in edges:  # thin white separators, 0.75 px
        a = np.deg2rad(angle)
        draw.line([(cx, cy), (cx + radius * np.cos(a), cy + radius * np.sin(a))], fill=(255, 255, 255),
                  width=max(1, int(round(0.75 * k))))
    if hole:
        draw.ellipse((cx - hole, cy - hole, cx + hole, cy + hole), fill=(255, 255, 255))


def _pies(height, width, k):
    """A pie chart, a donut chart and a small pie, with a legend of swatches and labels."""
    from PIL import ImageFont
    image, draw = _pil_canvas(height * k, width * k, (1, 1, 1))
    h, w = height * k, width * k
    _pie(draw, (0.3 * w, 0.3 * h), 0.26 * min(h, w), (0.31, 0.22, 0.14, 0.11, 0.09, 0.07, 0.04, 0.02), k)
    _pie(draw, (0.72 * w, 0.68 * h), 0.24 * min(h, w), (0.4, 0.25, 0.2, 0.15), k, hole=0.12 * min(h, w))
    _pie(draw, (0.78 * w, 0.22 * h), 0.12 * min(h, w), (0.55, 0.3, 0.15), k)
    font = ImageFont.load_default(size=7 * k)
    for i in range(6):
        top = (0.62 + 0.06 * i) * h
        draw.rectangle((0.06 * w, top, 0.06 * w + 4 * k, top + 4 * k), fill=_rgb8(_PIE_COLOURS[i]))
        draw.text((0.06 * w + 6 * k, top - 2 * k), f"item {i + 1}: {31 - 4 * i}%", font=font, fill=(40, 40, 40))
    return _to_float(image)


def _stroke_polygon(points, widths):
    """The outline of a stroke of varying width along `points`: left side, then right reversed."""
    points = np.asarray(points, np.float64)
    tangent = np.gradient(points, axis=0)
    tangent /= np.maximum(np.linalg.norm(tangent, axis=1, keepdims=True), 1e-9)
    normal = np.stack([-tangent[:, 1], tangent[:, 0]], axis=1)
    left = points + normal * widths[:, None] / 2
    right = points - normal * widths[:, None] / 2
    return [tuple(p) for p in np.concatenate([left, right[::-1]])]


def _inkart(height, width, k):
    """Ink line art: curved strokes of varying width, cross-hatch ticks and blots."""
    image, draw = _pil_canvas(height * k, width * k, (0.98, 0.96, 0.9))
    h, w = height, width
    rng = np.random.default_rng(11)
    ink, sepia = _rgb8((0.05, 0.05, 0.08)), _rgb8((0.35, 0.2, 0.1))
    t = np.linspace(0, 1, 240)
    for i in range(14):
        x0, y0 = rng.uniform(0.15, 0.85) * w, rng.uniform(0.15, 0.85) * h
        length, turn = rng.uniform(0.3, 0.55) * w, rng.uniform(-3.5, 3.5)
        phase = rng.uniform(0, 2 * np.pi)
        angle = phase + turn * t
        steps = np.stack([np.cos(angle), np.sin(angle)], axis=1) * length / len(t)
        points = np.cumsum(steps, axis=0)
        points += np.array([x0, y0]) - points.mean(axis=0)  # centred on (x0, y0)
        # Pressure: thin at both ends, 0.4 to 2.5 px along the stroke.
        widths = 0.4 + rng.uniform(0.8, 2.1) * np.sin(np.pi * t) ** 1.5
        draw.polygon([(x * k, y * k) for x, y in _stroke_polygon(points, widths)], fill=ink if i % 3 else sepia)
    for i in range(40):  # short hatching ticks, 0.5 px
        x0, y0 = rng.uniform(0.55, 0.95) * w, rng.uniform(0.5, 0.95) * h
        draw.line([(x0 * k, y0 * k), ((x0 + 3) * k, (y0 - 2) * k)], fill=ink, width=max(1, int(0.5 * k)))
    for i in range(5):  # blots
        cx, cy, r = rng.uniform(0.1, 0.9) * w, rng.uniform(0.1, 0.9) * h, rng.uniform(0.6, 2.0)
        draw.ellipse(((cx - r) * k, (cy - r * 0.8) * k, (cx + r) * k, (cy + r * 0.8) * k), fill=ink)
    return _to_float(image)


def _starburst(height, width, k, spokes=36):
    """Thin dark-blue spokes on tan: tapered wedges (1.6 px at the rim) between 0.6 px lines."""
    y, x = _grid(height, width, k)
    cy, cx = height / 2, width / 2
    radius = 0.47 * min(height, width)
    r = np.hypot(y - cy, x - cx)
    angle = np.arctan2(y - cy, x - cx) + np.pi
    pitch = 2 * np.pi / spokes
    # Angle from the nearest wedge axis (j * pitch) and from the nearest line (half way between).
    to_wedge = (angle + pitch / 2) % pitch - pitch / 2
    to_line = angle % pitch - pitch / 2
    wedge = np.abs(to_wedge) * radius < 0.8  # 1.6 px wide at the rim, narrowing to the centre
    line = (np.abs(to_line) * r < 0.3) & (r > 2)  # 0.6 px wide all along
    canvas = np.empty((height * k, width * k, 3), np.float32)
    canvas[:] = np.array(_rgb8((0.82, 0.7, 0.52)), np.float32) / 255
    blue = (0.1, 0.14, 0.45)
    _paint(canvas, (wedge | line) & (r < radius), blue)
    _paint(canvas, np.abs(r - radius) < 0.4, blue)
    _paint(canvas, r < 1.2, blue)
    return canvas


def _plots(height, width, k):
    """A line chart: grid, axes, three curves, markers, tick labels and a legend."""
    from PIL import ImageFont
    image, draw = _pil_canvas(height * k, width * k, (1, 1, 1))
    h, w = height, width
    left, right, top, bottom = 0.14 * w, 0.96 * w, 0.06 * h, 0.84 * h
    grey = _rgb8((0.82, 0.82, 0.85))
    for gx in np.linspace(left, right, 7):
        draw.line([(gx * k, top * k), (gx * k, bottom * k)], fill=grey, width=max(1, int(0.5 * k)))
    for gy in np.linspace(top, bottom, 6):
        draw.line([(left * k, gy * k), (right * k, gy * k)], fill=grey, width=max(1, int(0.5 * k)))
    draw.line([(left * k, top * k), (left * k, bottom * k), (right * k, bottom * k)], fill=(0, 0, 0), width=k)
    t = np.linspace(0, 1, 80)
    curves = (((0.5 + 0.35 * np.sin(9 * t)), 1.0, (0.84, 0.15, 0.16)),
              ((0.9 * np.exp(-3 * t) + 0.05), 1.5, (0.12, 0.47, 0.71)),
              ((0.3 + 0.25 * t + 0.08 * np.sin(37 * t)), 0.8, (0.17, 0.63, 0.17)))
    for values, line_width, colour in curves:
        points = [(left + (right - left) * s, bottom - (bottom - top) * v) for s, v in zip(t, values)]
        _polyline(draw, points, line_width, k, colour)
    for s, v in list(zip(t, curves[1][0]))[::8]:
        px, py = left + (right - left) * s, bottom - (bottom - top) * v
        draw.rectangle(((px - 1.5) * k, (py - 1.5) * k, (px + 1.5) * k, (py + 1.5) * k), fill=_rgb8(curves[1][2]))
    font = ImageFont.load_default(size=7 * k)
    for i, gx in enumerate(np.linspace(left, right, 4)):
        draw.text(((gx - 2) * k, (bottom + 2) * k), f"{i * 5}", font=font, fill=(0, 0, 0))
    for i, gy in enumerate(np.linspace(bottom, top, 3)):
        draw.text((1 * k, (gy - 4) * k), f"{i / 2:.1f}", font=font, fill=(0, 0, 0))
    return _to_float(image)


#: Family name -> ``render(height, width, k) -> float32 (height * k, width * k, 3)``, sRGB.
DRAWINGS = {"maps": _maps, "hatching": _hatching, "serif": _serif_text, "icons": _icons, "pies": _pies,
            "inkart": _inkart, "starburst": _starburst, "plots": _plots}
