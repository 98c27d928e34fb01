"""The reusable recovery engine: one backend, one pair of images, plans that change."""

import dataclasses
import functools
import threading
import time

from .backends import make_backend
from .backends.base import RecoveryMaps
from .contract import check_same_size, from_rgba_float, layout_of, native_byte_order
from .errors import InputError
from .params import DEFAULT_MODE, ITERATIONS, SIGMA_D, SIGMA_E, STRENGTH, Parameters, check_blend_space
from .plan import analyse_pair, make_plan
from .sample import array_window

__all__ = ["Engine", "RecoveryMaps"]


def _exclusive(method):
    """Run a method holding the engine's lock: one thread at a time loads, runs or reads."""
    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        with self.lock:
            return method(self, *args, **kwargs)
    return wrapper


class Engine:
    """A recovery engine that keeps its backend, shaders and images between runs.

    Load a pair once with :meth:`set_images`, then call :meth:`recover` (or :meth:`compute`
    when the result stays on the GPU) as often as the parameters change: nothing is
    recompiled and nothing is uploaded again, and the safe default analyses each pair once.

    Parameters
    ----------
    backend : {"auto", "gl", "numpy"}
        ``"auto"`` uses GL and falls back to NumPy with a one-line warning when no OpenGL 3.3
        context can be created.
    context : moderngl.Context, optional
        A context to borrow (a viewer's window); by default the engine makes a standalone
        EGL (or platform default) context and owns it.
    gl_path : {"auto", "fragment", "compute"}
        How the GL backend runs its passes: ``"auto"`` chooses by the context's capabilities
        and a measured rule; ``"compute"`` needs OpenGL 4.3. Only ``"auto"`` with NumPy.

    Notes
    -----
    An engine may be shared by threads. Each call holds :attr:`lock`, and
    :func:`aarecovery.recover` (``engine=``) holds it for the whole pair, so concurrent
    ``recover`` calls on one engine run one after the other and each gets its own result
    (on GL the engine's own context is made current in the calling thread for each call,
    which EGL allows once no other thread holds it). A pair loaded with :meth:`set_images`
    belongs to the thread that loaded it: :meth:`compute`, :meth:`result` and the other
    calls on it from another thread are refused with :class:`InputError`, as they would
    read another thread's pair; hold :attr:`lock` around ``set_images`` and ``recover`` to
    share the engine that way, or make one engine per thread to run in parallel. A
    borrowed `context` (a window's) is used only in the thread that owns it.

    Examples
    --------
    >>> engine = Engine(backend="numpy")
    >>> engine.set_images(original, filtered)              # doctest: +SKIP
    >>> for sigma_e in (0.005, 0.01, 0.02):                 # doctest: +SKIP
    ...     result = engine.recover(sigma_e=sigma_e)
    """

    def __init__(self, backend="auto", *, context=None, gl_path="auto"):
        #: threading.RLock: held by every call; hold it around :meth:`set_images` and what
        #: follows to use one engine from several threads.
        self.lock = threading.RLock()
        self._impl = make_backend(backend, context, gl_path)
        if context is None and self.context is not None:
            # A new context is current in the thread that made it, and a context current in
            # one thread cannot be made current in another (EGL_BAD_ACCESS, which showed as a
            # texture that could not be made). Leaving its scope once leaves it current in no
            # thread; each call then makes it current in the calling thread (under the lock).
            with self.context:
                pass
        self._released = False
        # The thread that loaded the pair: calls on it from others would read that thread's pair.
        self._loader = None
        # None, or {"maps": bool} once a run finished on the loaded pair.
        self._computed = None
        self._layout = None
        self._pair = None
        self._loaded_space = None
        self._analysis = None
        self._window = None
        self._quantization = None
        self.last_seconds = None
        #: Plan or None: what the last :meth:`compute` or :meth:`run` did (mode, blend space,
        #: strength, and why), or what :func:`aarecovery.recover` decided with this engine
        #: (also when it returned F unchanged without running it).
        self.last_plan = None

    @property
    def backend(self):
        """str: ``"gl"`` or ``"numpy"``, the backend actually in use."""
        return self._impl.name

    @property
    def capabilities(self):
        """Capabilities: the backend's largest and preferred tile sides and its GL paths."""
        return self._impl.capabilities

    @property
    def gl_path(self):
        """str or None: ``"fragment"`` or ``"compute"``, how the GL backend runs its passes."""
        return self._impl.capabilities.gl_path

    @property
    def context(self):
        """moderngl.Context or None: the GL context the engine renders in."""
        return getattr(self._impl, "context", None)

    @property
    def size(self):
        """tuple of int: ``(width, height)`` of the loaded pair, or None."""
        return None if self._layout is None else (self._layout.width, self._layout.height)

    @_exclusive
    def set_images(self, original, filtered, *, linear=False, blend_space=None, quantization=None):
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
        quantization : sequence of sequence of int, optional
            The quantization tables of O's JPEG file (``aarecovery.read_quantization``), for
            the safe default's compression evidence; without them it looks for a JPEG block
            grid in O's pixels.

        Raises
        ------
        InputError
            On a shape, dtype, size mismatch, NaN or range the core cannot use.
        """
        self._require_unreleased()
        original, filtered = native_byte_order(original), native_byte_order(filtered)
        o_layout = layout_of(original, "original")
        f_layout = layout_of(filtered, "filtered")
        check_same_size(o_layout, f_layout)
        if blend_space is not None:
            check_blend_space(blend_space)
        self._computed = None
        self._loader = threading.get_ident()
        self._layout = f_layout
        self._pair = (original, o_layout, filtered, f_layout, bool(linear), blend_space)
        self._analysis = None
        self._window = None
        self._quantization = quantization
        self._load(blend_space or "linear")

    def _load(self, space):
        original, o_layout, filtered, f_layout, linear, _ = self._pair
        self._computed = None
        self._impl.load(original, o_layout, filtered, f_layout, linear, space)
        self._loaded_space = space

    # Every backend reaches the same states, and each call that needs a later one says which
    # call comes first: before, NumPy raised a TypeError, GL returned black or the previous
    # pair's result, and a released GL engine an AttributeError.
    def _require_unreleased(self):
        if self._released:
            raise InputError("this engine was released; create a new aarecovery.Engine")

    def _require_images(self):
        self._require_unreleased()
        if self._layout is None:
            raise InputError("no images loaded: call set_images(original, filtered) first")
        if self._loader != threading.get_ident():
            raise InputError("the images in this engine were loaded by another thread, so this call would use "
                             "that thread's pair: call set_images in this thread first (holding engine.lock "
                             "around set_images and recover), or make one Engine per thread")

    def _require_computed(self, maps=False):
        self._require_images()
        if self._computed is None:
            raise InputError("nothing computed for the loaded images: call "
                             + ("compute(maps=True)" if maps else "compute() or recover()") + " first")
        if maps and not self._computed["maps"]:
            raise InputError("the last compute() kept no maps: call compute(maps=True) first")

    @_exclusive
    def plan(self, *, sigma_d=SIGMA_D.default, sigma_e=SIGMA_E.default, iterations=ITERATIONS.default,
             mode=DEFAULT_MODE, strength=STRENGTH.default):
        """The Plan that :meth:`compute` would run for the loaded pair (analysed once per pair).

        Returns
        -------
        Plan
        """
        self._require_images()
        original, _, filtered, _, linear, blend_space = self._pair
        parameters = Parameters(sigma_d, sigma_e, iterations, strength)
        if mode != "safe":
            return make_plan(original, filtered, parameters, mode=mode, linear=linear, blend_space=blend_space)
        if self._analysis is None:
            self._window = array_window(original)
            self._analysis = analyse_pair(original[self._window], filtered[self._window], linear, self._quantization)
        return dataclasses.replace(make_plan(original, filtered, parameters, mode=mode, linear=linear,
                                             blend_space=blend_space, analysis=self._analysis), window=self._window)

    @_exclusive
    def compute(self, *, sigma_d=SIGMA_D.default, sigma_e=SIGMA_E.default, iterations=ITERATIONS.default,
                maps=False, mode=DEFAULT_MODE, strength=STRENGTH.default):
        """Run the recovery and keep the result in the backend (on the GPU for GL).

        Parameters
        ----------
        sigma_d, sigma_e : float
            Model and edge scales (ranges in ``aarecovery.PARAMETERS``).
        iterations : int
            Jacobi iterations.
        maps : bool
            Also keep the intermediate maps for :meth:`maps`.
        mode : {"safe", "paper"}
            ``"safe"`` first analyses the loaded pair once (blend space, blur and point-wise
            detection, strength calibration; see :attr:`last_plan`) so that recovery does
            not make F worse; ``"paper"`` is Yang et al. (2011) exactly.
        strength : float, optional
            How much to repair, 0 to 1, instead of the strength the mode chooses.
        """
        self.run(self.plan(sigma_d=sigma_d, sigma_e=sigma_e, iterations=iterations, mode=mode, strength=strength),
                 maps=maps)

    @_exclusive
    def run(self, plan, *, maps=False, wait=True):
        """Run a resolved :class:`Plan` on the loaded pair; the result stays in the backend.

        The plan may come from :meth:`plan` or, when one pair is recovered in tiles, from
        ``aarecovery.plan.make_plan`` on the whole pair. With ``wait=False`` the GL backend
        returns as soon as the passes are queued (and :attr:`last_seconds` is None), so
        that a tiled caller can read the previous tile back meanwhile (:meth:`start_result`).
        """
        self._require_images()
        if plan.blend_space != self._loaded_space:
            self._load(plan.blend_space)
        start = time.perf_counter()
        self._computed = None
        self._impl.run(plan, maps)
        self.last_seconds = None
        if wait:
            self._impl.finish()
            self.last_seconds = time.perf_counter() - start
        self._computed = {"maps": bool(maps)}
        self.last_plan = plan

    @_exclusive
    def result(self):
        """Read the last result back in the filtered image's shape and dtype.

        Returns
        -------
        ndarray
            Same shape and dtype as the `filtered` given to :meth:`set_images`.

        Raises
        ------
        InputError
            Before :meth:`set_images` and :meth:`compute`, and after :meth:`release`.
        """
        self._require_computed()
        return from_rgba_float(self._impl.start_readback().wait(), self._layout)

    @_exclusive
    def start_result(self, window=None):
        """Start reading the last result back, for a caller that overlaps tiles.

        Parameters
        ----------
        window : (slice, slice), optional
            The rows and columns to read (a tile's own part); all by default.

        Returns
        -------
        object
            Its ``wait()`` returns the result as the backend holds it (see
            ``Backend.start_readback``), to be folded into F's layout with
            ``aarecovery.contract.from_rgba_float``; valid until two more results are started.
        """
        self._require_computed()
        return self._impl.start_readback(window)

    @_exclusive
    def recover(self, *, sigma_d=SIGMA_D.default, sigma_e=SIGMA_E.default, iterations=ITERATIONS.default,
                mode=DEFAULT_MODE, strength=STRENGTH.default):
        """Compute and return R: :meth:`compute` then :meth:`result`."""
        self.compute(sigma_d=sigma_d, sigma_e=sigma_e, iterations=iterations, mode=mode, strength=strength)
        return self.result()

    @_exclusive
    def maps(self):
        """Return the intermediate maps of the last :meth:`compute` with ``maps=True``.

        Returns
        -------
        RecoveryMaps

        Raises
        ------
        InputError
            When the last :meth:`compute` on the loaded pair did not keep maps.
        """
        self._require_computed(maps=True)
        return self._impl.read_maps()

    @_exclusive
    def texture(self, name="result"):
        """GL only: a texture of the engine, in its (possibly borrowed) context, for display.

        Parameters
        ----------
        name : {"result", "original", "filtered", "alpha", "beta", "edge_strength", "residual", "strength"}
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
        if name in RecoveryMaps.NAMES:
            self._require_computed(maps=True)
        return self._impl.texture(name)

    @_exclusive
    def release(self):
        """Free textures and programs (and the context, if the engine made it); idempotent.

        Every later call but :meth:`release` raises :class:`InputError`.
        """
        if self._released:
            return
        self._released = True
        self._computed = None
        self._impl.release()
        self._layout = None
        self._pair = None
        self._analysis = None
        self._window = None
        self._loaded_space = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.release()
