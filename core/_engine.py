"""The reusable recovery engine: one backend, one pair of images, parameters that change."""

import time
import warnings
from dataclasses import dataclass

import numpy as np

from ._contract import check_same_size, from_rgba_float, layout_of, to_rgba_float
from ._errors import InputError
from ._params import Parameters, check_blend_space, check_mode

__all__ = ["Engine", "RecoveryMaps", "BACKENDS"]

BACKENDS = ("auto", "gl", "numpy")


@dataclass
class RecoveryMaps:
    """Per-pixel intermediate maps of the last recovery, for viewers and debugging.

    Attributes
    ----------
    alpha : ndarray of float32, shape (H, W)
        Coverage of the first extreme colour.
    beta : ndarray of float32, shape (H, W)
        Confidence in [0, 1]: 0 keeps F, 1 imposes O's blend.
    edge_strength : ndarray of float32, shape (H, W)
        Product of the Sobel magnitudes of O and F.
    residual : ndarray of float32, shape (H, W)
        Distance of O's colour from its two-colour blend.
    """

    alpha: np.ndarray
    beta: np.ndarray
    edge_strength: np.ndarray
    residual: np.ndarray

    NAMES = ("alpha", "beta", "edge_strength", "residual")


def plan_for_pair(original, filtered, linear):
    """The safe default's per-image decisions (:func:`aarecovery._safeguards.plan_recovery`).

    The plan is a property of the pair, not of the parameters: its strength calibration runs
    at the paper's parameters, so an engine plans once per pair and a slider change in the
    viewer re-runs only the passes (1080p, safe mode: 360 ms -> the paper mode's 70 ms per
    change, measured). The analysis reads only a central crop, so only the crop is converted
    to float: a 20000 x 20000 pair would otherwise take 13 GB just for the conversion.
    """
    from ._safeguards import _analysis_crop, plan_recovery
    o_crop, f_crop = _analysis_crop(original), _analysis_crop(filtered)
    return plan_recovery(to_rgba_float(o_crop, layout_of(o_crop, "original"), "original"),
                         to_rgba_float(f_crop, layout_of(f_crop, "filtered"), "filtered"),
                         linear_input=bool(linear))


def _make_backend(backend, context):
    if backend not in BACKENDS:
        raise InputError(f"backend must be one of {', '.join(BACKENDS)}, got {backend!r}")
    if backend == "numpy":
        if context is not None:
            raise InputError("a GL context was passed with backend='numpy'; pass backend='gl' or drop the context")
        from ._numpy_backend import NumpyBackend
        return NumpyBackend()
    from ._gl.backend import GLBackend, GLUnavailable
    try:
        return GLBackend(context)
    except GLUnavailable as error:
        if backend == "gl":
            raise
        warnings.warn(f"aarecovery: no OpenGL 3.3 context ({error}); using the NumPy backend", RuntimeWarning,
                      stacklevel=3)
        from ._numpy_backend import NumpyBackend
        return NumpyBackend()


class Engine:
    """A recovery engine that keeps its backend, shaders and images between runs.

    Load a pair once with :meth:`set_images`, then call :meth:`recover` (or :meth:`compute`
    when the result stays on the GPU) as often as the parameters change: nothing is
    recompiled and nothing is uploaded again.

    Parameters
    ----------
    backend : {"auto", "gl", "numpy"}
        ``"auto"`` uses GL and falls back to NumPy with a one-line warning when no OpenGL 3.3
        context can be created.
    context : moderngl.Context, optional
        A context to borrow (a viewer's window); by default the engine makes a standalone
        EGL (or platform default) context and owns it.

    Examples
    --------
    >>> engine = Engine(backend="numpy")
    >>> engine.set_images(original, filtered)              # doctest: +SKIP
    >>> for sigma_e in (0.005, 0.01, 0.02):                 # doctest: +SKIP
    ...     result = engine.recover(sigma_e=sigma_e)
    """

    def __init__(self, backend="auto", *, context=None):
        self._impl = _make_backend(backend, context)
        self._layout = None
        self._pair = None
        self._plan_made = None
        self.last_seconds = None
        #: SafePlan or None: what the last ``compute(mode="safe")`` decided (blend space, strength, why).
        self.last_plan = None

    @property
    def backend(self):
        """str: ``"gl"`` or ``"numpy"``, the backend actually in use."""
        return self._impl.name

    @property
    def context(self):
        """moderngl.Context or None: the GL context the engine renders in."""
        return getattr(self._impl, "context", None)

    @property
    def size(self):
        """tuple of int: ``(width, height)`` of the loaded pair, or None."""
        return None if self._layout is None else (self._layout.width, self._layout.height)

    def set_images(self, original, filtered, *, linear=False, blend_space=None):
        """Check and load an image pair (uploads it once for GL).

        Parameters
        ----------
        original, filtered : ndarray, shape (H, W) or (H, W, C), C in 1..4
            uint8, uint16, or float in [0, 1]; grey, grey+alpha, RGB or RGBA. Channel counts
            and dtypes may differ (a colour-to-grey filter gives a grey F for an RGB O).
        linear : bool
            True when both images hold linear-light values; by default they are sRGB-encoded.
        blend_space : {"linear", "srgb"}, optional
            Where the blend model is fitted and imposed. By default ``mode="safe"`` picks it
            per image and ``mode="paper"`` uses ``"linear"``, the paper's choice and right for
            optical (camera) antialiasing.

        Raises
        ------
        InputError
            On a shape, dtype, size mismatch, NaN or range the core cannot use.
        """
        o_layout = layout_of(original, "original")
        f_layout = layout_of(filtered, "filtered")
        check_same_size(o_layout, f_layout)
        if blend_space is not None:
            check_blend_space(blend_space)
        loaded = blend_space or "linear"
        self._impl.load(original, o_layout, filtered, f_layout, bool(linear), loaded)
        self._layout = f_layout
        self._pair = (original, o_layout, filtered, f_layout, bool(linear), blend_space, loaded)
        self._plan_made = None

    def _load_space(self, space):
        original, o_layout, filtered, f_layout, linear, requested, loaded = self._pair
        if space != loaded:
            self._impl.load(original, o_layout, filtered, f_layout, linear, space)
            self._pair = (original, o_layout, filtered, f_layout, linear, requested, space)

    def _plan(self):
        """The safe default's decisions for the loaded pair (made once per pair)."""
        if self._plan_made is None:
            original, o_layout, filtered, f_layout, linear = self._pair[:5]
            self._plan_made = plan_for_pair(original, filtered, linear)
        return self._plan_made

    def _require_images(self):
        if self._layout is None:
            raise InputError("no images loaded: call set_images(original, filtered) first")

    def compute(self, *, sigma_d=0.1, sigma_e=0.01, iterations=3, maps=False, mode="safe"):
        """Run the recovery and keep the result in the backend (on the GPU for GL).

        Parameters
        ----------
        sigma_d, sigma_e : float
            Model and edge scales, > 0.
        iterations : int
            Jacobi iterations, 0 to 64.
        maps : bool
            Also keep the intermediate maps for :meth:`maps`.
        mode : {"safe", "paper"}
            ``"safe"`` first analyses the whole loaded pair once (blend space, blur and
            point-wise detection, strength calibration; see :attr:`last_plan`) so that
            recovery does not make F worse; ``"paper"`` is Yang et al. (2011) exactly.
        """
        self._require_images()
        check_mode(mode)
        params = Parameters(sigma_d, sigma_e, iterations)
        requested = self._pair[5]
        if mode == "safe":
            plan = self._plan()
            self.last_plan = plan
            self._load_space(requested or plan.blend_space)
            params = Parameters(sigma_d, sigma_e, iterations, plan.strength, plan.pure_colours)
        else:
            self.last_plan = None
            self._load_space(requested or "linear")
        self._run(params, maps)

    def _run(self, params, maps):
        """Run the passes with fully decided parameters (used by ``recover`` on tiles)."""
        start = time.perf_counter()
        self._impl.run(params, maps)
        self._impl.finish()
        self.last_seconds = time.perf_counter() - start

    def result(self):
        """Read the last result back in the filtered image's shape and dtype.

        Returns
        -------
        ndarray
            Same shape and dtype as the `filtered` given to :meth:`set_images`.
        """
        self._require_images()
        return from_rgba_float(self._impl.read_result(), self._layout)

    def recover(self, *, sigma_d=0.1, sigma_e=0.01, iterations=3, mode="safe"):
        """Compute and return R: :meth:`compute` then :meth:`result`."""
        self.compute(sigma_d=sigma_d, sigma_e=sigma_e, iterations=iterations, mode=mode)
        return self.result()

    def maps(self):
        """Return the intermediate maps of the last :meth:`compute` with ``maps=True``.

        Returns
        -------
        RecoveryMaps
        """
        self._require_images()
        return self._impl.read_maps()

    def texture(self, name="result"):
        """GL only: a texture of the engine, in its (possibly borrowed) context, for display.

        Parameters
        ----------
        name : {"result", "original", "filtered", "alpha", "beta", "edge_strength", "residual"}
            Images are straight RGBA; maps exist after ``compute(maps=True)``.

        Returns
        -------
        EngineTexture
            ``(texture, channel, linear)``: the moderngl texture, the channel holding a map
            (None for RGBA images), and whether sampled values are linear light (display code
            must then sRGB-encode them).
        """
        if self.backend != "gl":
            raise InputError("textures exist only on the GL backend; create the engine with backend='gl'")
        self._require_images()
        return self._impl.texture(name)

    def release(self):
        """Free textures and programs (and the context, if the engine made it)."""
        self._impl.release()
        self._layout = None
        self._pair = None
        self._plan_made = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.release()
