"""Scenes that mix content, for the real-tools suite: graphics over photos, and scanned pages.

Both are rendered like the drawings (:mod:`aarecovery.lab.drawings`): hard-edged shapes at
``k`` times O's size, so that the box-downsampled O is an exact blend at every edge. Each
renderer also returns where it drew (a boolean mask at the scene's size), from which the
suite builds its per-pixel regions at O's size.

* **Mixed content** (``render(photo, k)``): text, logos, UI chrome and map lines drawn over a
  photo at its full resolution (the photo is its own scene, as in the suite's photo cases);
  the mask is the overlay.
* **Scans** (``render(height, width, k)``): a page of text on tinted, grained paper (the
  grain a few O pixels across, so that it survives the box filter, as a scanner sees the
  fibres); the mask is the ink. Their JPEG twins are the scans people threshold.

Fonts are the DejaVu faces of the Debian package ``fonts-dejavu-core``; everything else is
fixed by seeds, so each scene is the same on every run.
"""

import numpy as np

from .drawings import SERIF_FONT, _serif
from .scenes import _rgb8

__all__ = ["MIXED", "SCANS", "overlay_regions", "paper_background"]

_SANS_FONT = SERIF_FONT.replace("DejaVuSerif", "DejaVuSans")
_WORDS = ("Open daily from nine. Fresh roast, quiet corners and the best view of the harbour in town; "
          "bring a friend, 2 for 1 on Tuesdays. ")


def _font(size, sans=True, bold=False):
    if not sans:
        return _serif(size, bold)
    from PIL import ImageFont

    from ..errors import InputError
    path = _SANS_FONT.replace(".ttf", "-Bold.ttf") if bold else _SANS_FONT
    try:
        return ImageFont.truetype(path, size)
    except OSError:
        raise InputError(f"the mixed and scan scenes need the font {path}; install the Debian package "
                         "fonts-dejavu-core (packaging/test.sh does)") from None


class _Pen:
    """Draws each shape on the scene and, at full value, on the overlay mask."""

    def __init__(self, image, k):
        from PIL import Image, ImageDraw
        self.k = k
        self.image, self.mask = image, Image.new("L", image.size, 0)
        self.draws = (ImageDraw.Draw(self.image), ImageDraw.Draw(self.mask))
        for draw in self.draws:
            draw.fontmode = "1"  # hard-edged glyphs: the box downsample is the only antialiasing

    def __call__(self, method, *args, **kwargs):
        """``draw.method(*args, **kwargs)`` with coordinates in O pixels (scaled by ``k`` here)."""
        args = [self._scaled(a) for a in args]
        for key in ("width", "radius"):
            if key in kwargs:
                kwargs[key] = max(1, int(round(kwargs[key] * self.k)))
        colours = {key: _rgb8(value) for key, value in kwargs.items() if key in ("fill", "outline")}
        getattr(self.draws[0], method)(*args, **{**kwargs, **colours})
        getattr(self.draws[1], method)(*args, **{**kwargs, **{key: 255 for key in colours}})

    def text(self, x, y, words, size, colour, sans=True, bold=False):
        self("text", (x, y), words, font=_font(int(round(size * self.k)), sans, bold), fill=colour)

    def _scaled(self, value):
        if isinstance(value, (int, float)):
            return value * self.k
        if isinstance(value, (tuple, list)):
            return type(value)(self._scaled(v) for v in value)
        return value

    def result(self):
        return np.asarray(self.image, np.float32) / np.float32(255), np.asarray(self.mask) > 0


def _start(photo, k):
    from PIL import Image
    image = Image.fromarray(np.rint(np.clip(photo, 0, 1) * 255).astype(np.uint8))
    return _Pen(image, k), photo.shape[0] / k, photo.shape[1] / k


def _logo(pen, x, y, size, ring, core):
    pen("ellipse", (x, y, x + size, y + size), outline=ring, width=0.12 * size)
    s = size
    pen("polygon", [(x + 0.35 * s, y + 0.28 * s), (x + 0.75 * s, y + 0.5 * s), (x + 0.35 * s, y + 0.72 * s)],
        fill=core)


def _poster(photo, k):
    """A café poster: a bold headline, a logo, body text on a band, a thin rule."""
    pen, h, w = _start(photo, k)
    pen.text(4, 2, "CAFE AURORA", 13, (1, 0.97, 0.85), bold=True)
    _logo(pen, w - 20, 3, 15, (0.95, 0.75, 0.1), (0.85, 0.15, 0.1))
    pen("line", [(4, 20), (w - 24, 20)], fill=(1, 1, 1), width=0.6)
    pen("rectangle", (0, h - 26, w, h - 9), fill=(0.12, 0.1, 0.09))
    for row in range(2):
        pen.text(3 - 7 * row, h - 25 + 8 * row, _WORDS[row * 19:], 7, (0.98, 0.93, 0.8), sans=False)
    pen.text(4, h - 8, "aurora.example  -  open 9 to 5", 7, (0.05, 0.05, 0.05))
    return pen.result()


def _screenshot(photo, k):
    """A photo viewer's window: title bar, buttons, tabs, a scroll bar, a caption and a frame."""
    pen, h, w = _start(photo, k)
    pen("rectangle", (0, 0, w, 9), fill=(0.2, 0.22, 0.27))
    for i, colour in enumerate(((0.93, 0.33, 0.31), (0.98, 0.74, 0.18), (0.2, 0.78, 0.35))):
        pen("ellipse", (2.5 + 5 * i, 2.5, 6.5 + 5 * i, 6.5), fill=colour)
    pen.text(20, 0.5, "camera.png - Viewer", 7, (0.92, 0.92, 0.95))
    for i, label in enumerate(("Edit", "View")):  # tabs: thin outlines under the title bar
        pen("rectangle", (2 + 20 * i, 10, 20 + 20 * i, 18), outline=(0.95, 0.95, 0.95), width=0.5)
        pen.text(4 + 20 * i, 10.5, label, 6, (1, 1, 1))
    pen("rectangle", (w - 5, 20, w - 1, h - 12), fill=(0.85, 0.85, 0.88))
    pen("rounded_rectangle", (w - 4.5, 30, w - 1.5, 48), radius=1.2, fill=(0.45, 0.45, 0.5))
    pen("rectangle", (0, h - 11, w, h), fill=(0.96, 0.96, 0.97))
    pen.text(3, h - 10.5, "384 x 384, 8-bit grey, 100%", 7, (0.1, 0.1, 0.12))
    pen("rectangle", (6, 24, w - 12, h - 16), outline=(1, 0.85, 0.2), width=0.7)
    return pen.result()


def _banner(photo, k):
    """A web banner: a headline in two colours, a call-to-action button, a logo and small print."""
    pen, h, w = _start(photo, k)
    pen.text(4, 3, "Meet the", 10, (1, 1, 1), bold=True)
    pen.text(4, 14, "new season", 12, (1, 0.8, 0.2), bold=True)
    pen("rounded_rectangle", (4, h - 20, 44, h - 9), radius=3, fill=(0.1, 0.45, 0.9))
    pen.text(8, h - 19, "Shop now", 8, (1, 1, 1), bold=True)
    _logo(pen, w - 17, h - 17, 13, (1, 1, 1), (0.1, 0.45, 0.9))
    pen.text(4, h - 7, "Terms apply. Offer ends Sunday.", 5.5, (0.9, 0.9, 0.9))
    return pen.result()


def _map_photo(photo, k):
    """A satellite view with map lines: cased roads, a dashed boundary, a route, pins and labels."""
    pen, h, w = _start(photo, k)
    rng = np.random.default_rng(19)
    for i in range(3):  # roads: a white casing under a yellow line
        y0, y1 = rng.uniform(0.1, 0.9, 2) * h
        points = [(0, y0), (0.45 * w, (y0 + y1) / 2 + rng.uniform(-8, 8)), (w, y1)]
        pen("line", points, fill=(1, 1, 1), width=2.2, joint="curve")
        pen("line", points, fill=(0.98, 0.8, 0.25), width=1.2, joint="curve")
    for t in np.arange(0, 1, 0.08):  # a dashed boundary
        x = 0.7 * w + 0.2 * w * np.sin(5 * t)
        pen("line", [(x, t * h), (x + 1.5, (t + 0.04) * h)], fill=(0.75, 0.3, 0.85), width=0.6)
    route = [(0.1 * w + 0.8 * w * s, 0.8 * h - 0.6 * h * s + 6 * np.sin(9 * s)) for s in np.linspace(0, 1, 40)]
    pen("line", route, fill=(0.15, 0.45, 0.95), width=0.9, joint="curve")
    for x, y in route[::13]:  # pins
        pen("ellipse", (x - 2, y - 5, x + 2, y - 1), fill=(0.9, 0.15, 0.15))
        pen("polygon", [(x - 1.5, y - 2), (x + 1.5, y - 2), (x, y)], fill=(0.9, 0.15, 0.15))
    pen.text(3, 2, "Harbour Rd", 7, (1, 1, 1), bold=True)
    pen.text(0.45 * w, 0.5 * h, "North Gate", 6, (1, 1, 0.85))
    return pen.result()


#: Mixed-content family -> ``render(photo, k) -> (scene, overlay mask)``.
MIXED = {"poster": _poster, "screenshot": _screenshot, "banner": _banner, "mapphoto": _map_photo}


def _grained_paper(height, width, k, tint, grain, seed):
    """Tinted paper whose grain is a few O pixels across, on the 8-bit grid."""
    from ..filters.spatial import gaussian_filter
    rng = np.random.default_rng(seed)
    noise = gaussian_filter(rng.standard_normal((height * k, width * k)), 0.8 * k, "reflect")
    noise *= grain / max(float(noise.std()), 1e-9)
    paper = np.asarray(tint, np.float64)[None, None, :] + noise[..., None] * np.array([1.0, 1.0, 0.9])
    return np.rint(np.clip(paper, 0, 1) * 255) / 255


def _page(height, width, k, tint, grain, ink, sizes, sans, seed):
    from PIL import Image
    paper = _grained_paper(height, width, k, tint, grain, seed)
    image = Image.fromarray(np.rint(paper * 255).astype(np.uint8))
    pen = _Pen(image, k)
    y, line = 2.0, 0
    while True:
        size = sizes[line % len(sizes)]
        if y + 1.2 * size > height - 1:
            break
        pen.text(3 - (line % 3) * 9, y, _WORDS[(line * 23) % 60:] + _WORDS, size, ink, sans=sans,
                 bold=line % 5 == 0)
        y += 1.45 * size
        line += 1
    return pen.result()


def _memo(height, width, k):
    """Serif text, 8-11 px, in near-black on cream paper with a light grain."""
    return _page(height, width, k, (0.95, 0.92, 0.8), 0.012, (0.08, 0.08, 0.1), (9, 8, 11, 8), False, 23)


def _letter(height, width, k):
    """Sans text, 7-10 px, in blue-black on grey-blue recycled paper with a coarse grain."""
    return _page(height, width, k, (0.84, 0.87, 0.9), 0.03, (0.12, 0.12, 0.3), (8, 7, 10, 7), True, 29)


def _notice(height, width, k):
    """Serif text, 7-10 px, in sepia on buff recycled paper with a coarse grain (the tuning half's grained page)."""
    return _page(height, width, k, (0.88, 0.84, 0.74), 0.03, (0.22, 0.14, 0.08), (8, 9, 7, 10), False, 31)


#: Scan family -> ``render(height, width, k) -> (scene, ink mask)``.
SCANS = {"memo": _memo, "letter": _letter, "notice": _notice}


def _blocks_any(mask, k):
    h, w = mask.shape[0] // k, mask.shape[1] // k
    return mask[:h * k, :w * k].reshape(h, k, w, k).any(axis=(1, 3))


def overlay_regions(mask, k):
    """O-sized regions of a mixed scene: ``{"text/graphics": any overlay in the pixel, "photo": the rest}``.

    The two partition the image: every pixel is in exactly one.
    """
    graphics = _blocks_any(mask, k)
    return {"text/graphics": graphics, "photo": ~graphics}


def paper_background(mask, k):
    """O pixels of a scan with no ink in them or in their 8 neighbours: the paper, where a repair must add nothing."""
    ink = np.pad(_blocks_any(mask, k), 1)
    h, w = ink.shape[0] - 2, ink.shape[1] - 2
    near = np.zeros((h, w), bool)
    for dy in range(3):
        for dx in range(3):
            near |= ink[dy:dy + h, dx:dx + w]
    return ~near
