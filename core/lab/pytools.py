"""The image libraries run in-process as tools: OpenCV (``opencv-python-headless``) and Pillow.

Scripts and web back-ends filter images with these libraries rather than with an editor,
so the real-tools suite runs them beside GEGL, G'MIC and ImageMagick. An operation is named
by a command like a tool's: ``("bilateral", "sigma_space=3", "sigma_colour=40")``, the
operation first, then ``key=value`` numbers (lengths among them are already multiplied by
the scene's ``k``, see :meth:`aarecovery.lab.realtools.ToolFilter.command`).

Both libraries work on the 8-bit file a user has, and so does this runner: images go in as
8-bit RGB (OpenCV's channel order is handled here) and come back as the 8-bit result. The
reference is then quantised once on the scene before its box filter, a rounding that the
filter averages over ``k * k`` pixels (at most half a step, and only where the output is not
on the 8-bit grid already).
"""

import importlib.util
from dataclasses import dataclass

import numpy as np

__all__ = ["PythonTool", "OPENCV", "PILLOW"]


def _to_uint8(image):
    return np.rint(np.clip(image, 0, 1) * 255).astype(np.uint8)


def _to_float(pixels):
    values = np.asarray(pixels, np.float32) / np.float32(255)
    if values.ndim == 2:
        values = np.repeat(values[..., None], 3, axis=2)
    return np.ascontiguousarray(values)


# OpenCV: colour operations take BGR; the wrappers take and give RGB.

def _bgr(cv2, rgb, function):
    return cv2.cvtColor(function(cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR)), cv2.COLOR_BGR2RGB)


def _cv_bilateral(cv2, rgb, p):
    # d = -1: the window follows sigma_space, so that it grows with the scene's k.
    return cv2.bilateralFilter(rgb, -1, p["sigma_colour"], p["sigma_space"])


def _cv_edge_preserving(cv2, rgb, p):
    # flags 1: the recursive domain transform filter (OpenCV's default), 2: normalized convolution.
    return _bgr(cv2, rgb, lambda bgr: cv2.edgePreservingFilter(bgr, flags=int(p["flags"]), sigma_s=p["sigma_s"],
                                                                sigma_r=p["sigma_r"]))


def _cv_detail_enhance(cv2, rgb, p):
    return _bgr(cv2, rgb, lambda bgr: cv2.detailEnhance(bgr, sigma_s=p["sigma_s"], sigma_r=p["sigma_r"]))


def _cv_threshold(cv2, rgb, p):
    # Each channel on its own, as cv2.threshold treats a colour image.
    return cv2.threshold(rgb, p["value"], 255, cv2.THRESH_BINARY)[1]


def _cv_gamma(cv2, rgb, p):
    table = np.rint((np.arange(256) / 255.0) ** p["gamma"] * 255).astype(np.uint8)
    return cv2.LUT(rgb, table)


def _cv_equalize(cv2, rgb, p):
    # The usual recipe for colour images: equalize the luma of YCrCb, keep the chroma.
    ycrcb = cv2.cvtColor(rgb, cv2.COLOR_RGB2YCrCb)
    ycrcb[..., 0] = cv2.equalizeHist(np.ascontiguousarray(ycrcb[..., 0]))
    return cv2.cvtColor(ycrcb, cv2.COLOR_YCrCb2RGB)


def _colour_map(cv2, rgb, colour_map):
    grey = cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY)
    return cv2.cvtColor(cv2.applyColorMap(grey, colour_map), cv2.COLOR_BGR2RGB)


def _cv_turbo(cv2, rgb, p):
    return _colour_map(cv2, rgb, cv2.COLORMAP_TURBO)


def _cv_jet(cv2, rgb, p):
    return _colour_map(cv2, rgb, cv2.COLORMAP_JET)


def _pil_posterize(pil, image, p):
    return pil.ImageOps.posterize(image, int(p["bits"]))


def _pil_solarize(pil, image, p):
    return pil.ImageOps.solarize(image, int(p["threshold"]))


def _pil_equalize(pil, image, p):
    return pil.ImageOps.equalize(image)


def _pil_ycbcr_equalize(pil, image, p):
    # Pillow's recipe for colour images: equalize the luma of JPEG's YCbCr, keep the chroma.
    luma, blue, red = image.convert("YCbCr").split()
    return pil.Image.merge("YCbCr", (pil.ImageOps.equalize(luma), blue, red)).convert("RGB")


def _pil_autocontrast(pil, image, p):
    return pil.ImageOps.autocontrast(image, cutoff=p["cutoff"])


def _pil_unsharp(pil, image, p):
    return image.filter(pil.ImageFilter.UnsharpMask(radius=p["radius"], percent=int(p["percent"]),
                                                    threshold=int(p["threshold"])))


def _pil_quantize(pil, image, p):
    # A palette of a few colours by median cut, each pixel mapped to its nearest entry without
    # dithering: what indexed-colour conversion does (GIF, PNG-8, GIMP's Image > Mode > Indexed).
    return image.quantize(colors=int(p["colours"]), method=pil.Image.Quantize.MEDIANCUT,
                          dither=pil.Image.Dither.NONE).convert("RGB")


def _pil_gradient_map(pil, image, p):
    # A duotone: grey to a dark blue through orange to a pale yellow.
    return pil.ImageOps.colorize(pil.ImageOps.grayscale(image), black=(20, 24, 80), white=(255, 248, 200),
                                 mid=(230, 110, 40))


def _run_opencv(operation, pixels, parameters):
    import cv2
    return operation(cv2, pixels, parameters)


def _run_pillow(operation, pixels, parameters):
    import types

    from PIL import Image, ImageFilter, ImageOps
    pil = types.SimpleNamespace(Image=Image, ImageFilter=ImageFilter, ImageOps=ImageOps)
    return np.asarray(operation(pil, Image.fromarray(pixels), parameters).convert("RGB"))


@dataclass(frozen=True)
class PythonTool:
    """An image library run in-process, with the interface of :class:`aarecovery.lab.tools.Tool`.

    Attributes
    ----------
    name : str
    label : str
    module : str
        The import name that must be present.
    package : str
        The pip package that provides it (in the ``eval`` and ``test`` extras).
    operations : dict of str to callable
        ``operation(library, pixels, parameters)``.
    """

    name: str
    label: str
    module: str
    package: str
    operations: dict
    _apply: object

    def available(self):
        """bool: the library is importable."""
        try:
            return importlib.util.find_spec(self.module) is not None
        except (ImportError, ValueError):
            return False

    def install_hint(self):
        """What to install when it is missing."""
        return f"Python module '{self.module}' not importable; pip package '{self.package}' (extras eval, test)"

    def run(self, arguments, images, *, support=0.0, whole_image=False):
        """Apply ``arguments = (operation, "key=value", ...)`` to each image of a batch.

        No arguments: each image as the library gets and gives it (8-bit), like a command
        line without operations. `support` and `whole_image` are accepted for the runner's
        interface: each image is processed on its own, so neither matters here.

        Returns
        -------
        list of ndarray of float32, shape (H, W, 3)
        """
        if not self.available():
            raise RuntimeError(f"{self.label} is not installed ({self.install_hint()})")
        if not arguments:
            return [_to_float(_to_uint8(image)) for image in images]
        operation, *pairs = arguments
        if operation not in self.operations:
            raise RuntimeError(f"{self.label} has no operation {operation!r}; it has {', '.join(self.operations)}")
        parameters = {}
        for pair in pairs:
            key, _, value = pair.partition("=")
            parameters[key] = float(value)
        return [_to_float(self._apply(self.operations[operation], _to_uint8(image), parameters))
                for image in images]


OPENCV = PythonTool("opencv", "OpenCV", "cv2", "opencv-python-headless",
                    {"bilateral": _cv_bilateral, "edge-preserving": _cv_edge_preserving,
                     "detail-enhance": _cv_detail_enhance,
                     "threshold": _cv_threshold, "gamma": _cv_gamma, "equalize": _cv_equalize,
                     "turbo": _cv_turbo, "jet": _cv_jet}, _run_opencv)
PILLOW = PythonTool("pillow", "Pillow (ImageOps, ImageFilter)", "PIL", "Pillow",
                    {"posterize": _pil_posterize, "solarize": _pil_solarize, "equalize": _pil_equalize,
                     "ycbcr-equalize": _pil_ycbcr_equalize, "autocontrast": _pil_autocontrast, "unsharp": _pil_unsharp,
                     "gradient-map": _pil_gradient_map, "quantize": _pil_quantize}, _run_pillow)
