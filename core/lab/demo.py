"""What ``aarecovery demo`` does, the first thing to run: filter a sample, recover it, show the difference.

The sample (``core/data/sample.png``: a photo beside hard-edged text and shapes) or the
user's image is treated as a scene at 4 times the working resolution, so that the demo can
show, next to O, F and R, the supersampled reference (:mod:`aarecovery.lab.groundtruth`) and
measure the gain. Images smaller than 256 pixels on a side are used as O directly, and then
there is no reference to measure against.
"""

import os

import numpy as np

__all__ = ["DEMO_FILTERS", "run_demo"]

#: The demo's filters: the damage users see most (hard threshold, banding, recolouring).
DEMO_FILTERS = ("threshold", "posterize", "gradientmap")
#: An image at least MIN_SCENE_SIDE a side is a supersampled scene: O is its SCENE_FACTOR x box
#: filter, and the reference the filter applied at full size, then box-filtered the same.
SCENE_FACTOR = 4
MIN_SCENE_SIDE = 256
_ZOOM = 2
_INSET = 24
_INSET_ZOOM = 6


def _to_uint8(image):
    return np.rint(np.clip(image, 0, 1) * 255).astype(np.uint8)


def _inset_box(filtered, reference, original):
    """The window where F is worst (against the reference, or where it changed O most)."""
    error = np.abs(filtered - (reference if reference is not None else original)).max(axis=-1)
    h, w = error.shape
    size = min(_INSET, h, w)
    integral = np.pad(error, ((1, 0), (1, 0))).cumsum(0).cumsum(1)
    sums = integral[size:, size:] - integral[:-size, size:] - integral[size:, :-size] + integral[:-size, :-size]
    top, left = np.unravel_index(np.argmax(sums), sums.shape)
    return int(top), int(left), size


def _sheet(rows, columns):
    """Rows of labelled panels: each panel the image at 2x, with a 6x inset below it."""
    from PIL import Image, ImageDraw, ImageFont
    font = ImageFont.load_default(size=14)
    first = rows[0][1][0]
    h, w = first.shape[:2]
    _, _, size = rows[0][2]
    panel_w = max(w * _ZOOM, size * _INSET_ZOOM)
    panel_h = h * _ZOOM + size * _INSET_ZOOM + 6
    label_h, gap = 20, 8
    sheet = Image.new("RGB", (110 + len(columns) * (panel_w + gap), label_h + len(rows) * (panel_h + gap)),
                      (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    for c, name in enumerate(columns):
        draw.text((110 + c * (panel_w + gap), 2), name, fill=(0, 0, 0), font=font)
    for r, (title, images, (top, left, size)) in enumerate(rows):
        y = label_h + r * (panel_h + gap)
        draw.text((4, y + 4), title, fill=(0, 0, 0), font=font)
        for c, image in enumerate(images):
            if image is None:
                continue
            x = 110 + c * (panel_w + gap)
            big = Image.fromarray(_to_uint8(image)).resize((w * _ZOOM, h * _ZOOM), Image.Resampling.NEAREST)
            sheet.paste(big, (x, y))
            draw.rectangle((x + left * _ZOOM - 1, y + top * _ZOOM - 1, x + (left + size) * _ZOOM,
                            y + (top + size) * _ZOOM), outline=(255, 0, 160))
            crop = image[top:top + size, left:left + size]
            inset = Image.fromarray(_to_uint8(crop)).resize((size * _INSET_ZOOM, size * _INSET_ZOOM),
                                                            Image.Resampling.NEAREST)
            sheet.paste(inset, (x, y + h * _ZOOM + 6))
    return sheet


def run_demo(image=None, folder="aarecovery-demo", *, backend="auto", paper=False, log=print):
    """Filter, recover and write O, F, R and a comparison sheet.

    Parameters
    ----------
    image : ndarray, optional
        Any layout the core accepts; by default the bundled sample.
    folder : str
        Output folder, created if missing.
    backend : {"auto", "gl", "numpy"}
    paper : bool
        Use the paper's method instead of the safe default.
    log : callable
        Where progress lines go.

    Returns
    -------
    dict
        ``{"folder", "sheet", "files", "gains", "shrunk"}``; gains maps each filter to
        ``(edge-band PSNR of F, of R)`` in dB, or None without a reference; shrunk is
        ``(width, height)`` of O when the image was box-filtered down to make it, else None.
    """
    from ..contract import layout_of, to_rgba_float
    from ..engine import Engine
    from ..plan.resample import box_downsample
    from .scenes import sample_image

    if image is None:
        scene = sample_image()
    else:
        scene = to_rgba_float(image, layout_of(image, "image"), "image")[..., :3]
    height, width = (scene.shape[0] // SCENE_FACTOR) * SCENE_FACTOR, (scene.shape[1] // SCENE_FACTOR) * SCENE_FACTOR
    shrunk = None
    if min(height, width) >= MIN_SCENE_SIDE:
        scene = scene[:height, :width]
        original = box_downsample(scene, SCENE_FACTOR, "linear")
        shrunk = (original.shape[1], original.shape[0])
    else:
        original, scene = scene, None
    # Before anything is written: a backend that cannot run stops the demo with no files made.
    with Engine(backend) as engine:
        return dict(_write_demo(original, scene, folder, engine, "paper" if paper else "safe"), shrunk=shrunk)


def _write_demo(original, scene, folder, engine, mode):
    from .. import filters
    from ..io import write_image
    from ..pipeline import recover
    from ..plan.resample import box_downsample
    from .metrics import edge_band, psnr

    os.makedirs(folder, exist_ok=True)
    files = [os.path.join(folder, "O.png")]
    write_image(files[0], _to_uint8(original))
    rows, gains = [], {}
    for name in DEMO_FILTERS:
        filtered = filters.apply(name, original)
        recovered = recover(original, filtered, engine=engine, mode=mode)
        reference = None
        if scene is not None:
            params = filters.FILTERS[name].defaults()
            reference = box_downsample(filters.apply(name, scene, scale=SCENE_FACTOR, **params), SCENE_FACTOR, "linear")
            band = edge_band(original, filtered, reference)
            gains[name] = (psnr(filtered, reference, band), psnr(recovered, reference, band))
        else:
            gains[name] = None
        for label, picture in (("F", filtered), ("R", recovered)):
            files.append(os.path.join(folder, f"{label}-{name}.png"))
            write_image(files[-1], _to_uint8(picture))
        rows.append((name, [original, filtered, recovered, reference],
                     _inset_box(filtered, reference, original)))
    columns = ["O (original)", "F (filtered)", "R (recovered)", "reference (4x supersampled)"]
    sheet_path = os.path.join(folder, "sheet.png")
    write_image(sheet_path, np.asarray(_sheet(rows, columns)))
    files.append(sheet_path)
    return {"folder": folder, "sheet": sheet_path, "files": files, "gains": gains}
