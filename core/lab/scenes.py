"""Test scenes rendered at ``k`` times a target resolution, for supersampled ground truth.

A scene is float32 ``(H * k, W * k, 3)`` sRGB-encoded RGB. Synthetic scenes are drawn
without antialiasing at the high resolution (hard edges, pure colours), so that every edge
pixel of the box-downsampled original is an exact blend of the colours either side. The
photos are bundled crops (``core/data/photo_*.jpg``, see ``core/data/LICENSE.md``) resized
to the requested resolution.

Everything is deterministic: the random shapes use a fixed seed, and the font is the
FreeType font that ships inside Pillow (``ImageFont.load_default(size=...)``), so scenes
render identically offline.
"""

from dataclasses import dataclass
from importlib import resources

import numpy as np

__all__ = ["Scene", "SCENES", "SYNTHETIC", "PHOTOS", "render", "sample_image"]


@dataclass(frozen=True)
class Scene:
    """A named scene generator.

    Attributes
    ----------
    name : str
    kind : {"synthetic", "photo"}
    render : callable
        ``render(height, width, k) -> ndarray of float32, shape (height * k, width * k, 3)``.
    aspect : float
        Height over width of the natural framing; :func:`render` keeps it.
    """

    name: str
    kind: str
    render: object
    aspect: float = 1.0


def _pil_canvas(height, width, background):
    from PIL import Image, ImageDraw
    image = Image.new("RGB", (width, height), tuple(int(round(c * 255)) for c in background))
    draw = ImageDraw.Draw(image)
    draw.fontmode = "1"  # hard-edged glyphs: the box downsample is the only antialiasing
    return image, draw


def _to_float(image):
    return np.asarray(image, np.float32) / np.float32(255)


def _rgb8(colour):
    return tuple(int(round(c * 255)) for c in colour)


def _text(height, width, k):
    """Text at several sizes and colours, on four coloured bands."""
    from PIL import ImageFont
    bands = (((1, 1, 1), (0, 0, 0)), ((0.08, 0.1, 0.35), (1, 1, 1)),
             ((1, 0.93, 0.6), (0.8, 0.05, 0.05)), ((0.85, 0.2, 0.75), (0.1, 0.7, 0.2)))
    image, draw = _pil_canvas(height * k, width * k, (1, 1, 1))
    band = height * k / len(bands)
    sizes = (7, 9, 12, 16)
    words = "Antialiasing recovery 0123 Sphinx of black quartz, judge my vow"
    for i, (background, ink) in enumerate(bands):
        top = int(round(i * band))
        draw.rectangle((0, top, width * k, int(round((i + 1) * band))), fill=_rgb8(background))
        size = sizes[i % len(sizes)]
        font = ImageFont.load_default(size=size * k)
        y = top + k
        line = 0
        while y + size * k < (i + 1) * band:
            draw.text((k * (1 + 3 * line), y), words[line * 7:] + " " + words, font=font, fill=_rgb8(ink))
            y += int(1.3 * size * k)
            line += 1
    return _to_float(image)


def _lines(height, width, k):
    """Thin parallel lines at several angles, widths and colours."""
    yy, xx = np.mgrid[0:height * k, 0:width * k].astype(np.float32) / k
    out = np.ones((height * k, width * k, 3), np.float32)
    panels = ((5.0, 0.7, (0, 0, 0), (1, 1, 1)), (23.0, 1.0, (0.9, 0.1, 0.1), (1, 1, 0.9)),
              (47.0, 1.3, (0.1, 0.2, 0.8), (0.95, 0.95, 0.95)), (71.0, 0.5, (1, 1, 1), (0.1, 0.1, 0.1)))
    half = width / 2
    for i, (angle, line_width, ink, paper) in enumerate(panels):
        rows = slice(int(i // 2 * height * k / 2), int((i // 2 + 1) * height * k / 2))
        cols = slice(int(i % 2 * half * k), int((i % 2 + 1) * half * k))
        theta = np.deg2rad(angle)
        across = xx[rows, cols] * np.cos(theta) + yy[rows, cols] * np.sin(theta)
        period = 2.2 * line_width + 1.1
        on = (across % period) < line_width
        out[rows, cols] = np.where(on[..., None], np.float32(ink), np.float32(paper))
    return out


def _chart(height, width, k):
    """Resolution chart: converging wedges, bar groups of falling pitch, and a circle."""
    image, draw = _pil_canvas(height * k, width * k, (1, 1, 1))
    h, w = height * k, width * k
    # Converging-line wedges: lines that meet at a point, so the pitch sweeps through the
    # sampling limit (where aliasing appears).
    for j in range(12):
        x0 = w * (0.05 + 0.035 * j)
        draw.polygon([(x0, h * 0.05), (x0 + w * 0.017, h * 0.05), (w * 0.26, h * 0.6), (w * 0.25, h * 0.6)],
                     fill=(0, 0, 0))
    pitch = 4.0
    x = w * 0.55
    for group in range(5):
        for bar in range(3):
            left = x + 2 * bar * pitch * k / 2
            draw.rectangle((left, h * 0.06, left + pitch * k / 2 - 1, h * 0.4), fill=(0, 0, 0))
        x += 7 * pitch * k / 2
        pitch *= 0.75
    draw.ellipse((w * 0.55, h * 0.5, w * 0.95, h * 0.95), outline=(20, 20, 140), width=max(1, k))
    draw.line((0, h * 0.97, w, h * 0.62), fill=(160, 0, 0), width=k)
    draw.rectangle((w * 0.05, h * 0.7, w * 0.45, h * 0.95), fill=(230, 200, 40))
    draw.polygon([(w * 0.1, h * 0.93), (w * 0.25, h * 0.72), (w * 0.42, h * 0.9)], fill=(0, 90, 160))
    return _to_float(image)


def _star(height, width, k, spokes=36):
    """Siemens star: `spokes` black and white sectors meeting at the centre."""
    yy, xx = np.mgrid[0:height * k, 0:width * k].astype(np.float64) + 0.5
    cy, cx = height * k / 2, width * k / 2
    angle = np.arctan2(yy - cy, xx - cx)
    radius = np.hypot(yy - cy, xx - cx)
    dark = (np.floor((angle + np.pi) / (2 * np.pi) * 2 * spokes) % 2) == 0
    inside = radius < 0.48 * min(height, width) * k
    value = np.where(inside & dark, 0.0, 1.0)
    value = np.where(radius < 0.04 * min(height, width) * k, 0.5, value)
    return np.repeat(value[..., None], 3, axis=-1).astype(np.float32)


def _shapes(height, width, k, seed=7, count=28):
    """Random shapes in pure primaries and mixed colours, overlapping, on a grey background."""
    rng = np.random.default_rng(seed)
    primaries = [(1, 0, 0), (0, 1, 0), (0, 0, 1), (0, 1, 1), (1, 0, 1), (1, 1, 0), (0, 0, 0), (1, 1, 1)]
    image, draw = _pil_canvas(height * k, width * k, (0.5, 0.5, 0.5))
    h, w = height * k, width * k
    for i in range(count):
        colour = primaries[i % len(primaries)] if i % 2 == 0 else tuple(rng.uniform(0.1, 0.95, 3))
        cx, cy = rng.uniform(0, w), rng.uniform(0, h)
        size = rng.uniform(0.04, 0.18) * min(h, w)
        kind = i % 3
        if kind == 0:
            draw.ellipse((cx - size, cy - size * rng.uniform(0.4, 1), cx + size, cy + size), fill=_rgb8(colour))
        elif kind == 1:
            angles = np.sort(rng.uniform(0, 2 * np.pi, 5))
            draw.polygon([(cx + size * np.cos(a), cy + size * np.sin(a)) for a in angles], fill=_rgb8(colour))
        else:
            theta = rng.uniform(0, np.pi)
            u, v = np.array([np.cos(theta), np.sin(theta)]), np.array([-np.sin(theta), np.cos(theta)])
            corners = [(cx, cy) + su * size * u + sv * size * 0.3 * v for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
            draw.polygon([tuple(c) for c in corners], fill=_rgb8(colour))
    return _to_float(image)


def _photo(name):
    def render(height, width, k):
        from PIL import Image
        with resources.files("aarecovery").joinpath(f"data/photo_{name}.jpg").open("rb") as handle:
            image = Image.open(handle).convert("RGB")
        size = (width * k, height * k)
        if image.size != size:
            image = image.resize(size, Image.Resampling.LANCZOS)
        return _to_float(image)
    return render


SCENES = {s.name: s for s in (
    Scene("text", "synthetic", _text),
    Scene("lines", "synthetic", _lines),
    Scene("chart", "synthetic", _chart),
    Scene("star", "synthetic", _star),
    Scene("shapes", "synthetic", _shapes),
    Scene("astronaut", "photo", _photo("astronaut"), 1.0),
    Scene("coffee", "photo", _photo("coffee"), 0.75),
    Scene("chelsea", "photo", _photo("chelsea"), 296 / 448),
)}
SYNTHETIC = tuple(n for n, s in SCENES.items() if s.kind == "synthetic")
PHOTOS = tuple(n for n, s in SCENES.items() if s.kind == "photo")


def render(name, width, k):
    """Render a scene by name.

    Parameters
    ----------
    name : str
        A key of :data:`SCENES`.
    width : int
        Target width in pixels; the height follows the scene's aspect.
    k : int
        Supersampling factor.

    Returns
    -------
    ndarray of float32, shape (height * k, width * k, 3)
        sRGB-encoded.
    """
    scene = SCENES[name]
    height = max(8, int(round(width * scene.aspect)))
    return scene.render(height, width, k)


def sample_image():
    """The demo's bundled sample: ``core/data/sample.png`` as float32 ``(H, W, 3)`` sRGB."""
    from PIL import Image
    with resources.files("aarecovery").joinpath("data/sample.png").open("rb") as handle:
        return _to_float(Image.open(handle).convert("RGB"))
