"""The GL backend behind :class:`aarecovery.Engine`: the passes on moderngl, as fragment or compute shaders.

Passes (each has a NumPy twin of the same name in ``aarecovery.spec.passes``):

0. ``to_working_space``: O and F decoded and premultiplied into float textures, where the
   passes read them (the active blocks and those around them), once per image pair and
   block list, so that parameter changes never decode again. Opaque 8 and 16-bit inputs
   whose working space is their own encoding need no pass: the passes read the uploaded
   textures, whose texel values are exactly what the pass would store.
1. ``fit_blend_model``: O and F neighbourhoods -> model (alpha, beta, extremes, residual)
   and the first Jacobi iterate, which needs no pass of its own because the F texels it
   gathers were already fetched for Sobel.
2. ``jacobi_step`` (iterations 2..n), the last one fused with ``from_working_space``.
3. ``keep_filtered``: R = F wherever the recovery leaves F as it is.

Passes 1 and 2 cover only the blocks of 16 x 16 pixels where the edge strength can be
non-zero (``blocks.py``): where F is not flat for the paper's model, where O is not flat with
pure colours (whose edge strength does not need F's gradient); with pure colours and the
GPU classification, pass 1 covers only those of O's blocks near a pixel that could be a thin
feature's ridge or where F varies, where the plan asks for it (``pure_colour_blocks.glsl``),
without the extension tests where no ridge could be extended, and pass 2 only the blocks
where pass 1 found that a step can change anything (``live_blocks.glsl``). Pass 3 covers the
other blocks. The block lists are made on the GPU when a run first needs them
(``classify.py``) and drive the draws and dispatches indirectly. On llvmpipe, which shades
every covered fragment, this is what makes mostly flat results (threshold, posterize) fast;
on a GPU it saves the work of idle lanes.

Each pass runs as a fragment pass or as a compute pass (``paths.py``), chosen by capability
and a measured rule, or by the caller (``gl_path``).

Colour conversion happens on fetch, in the shader (colour.glsl), for every bit depth.
sRGB textures would decode 8-bit inputs for free, but llvmpipe's decode is off by up to
1.2e-3 from the exact curve, and the fit's argmax and 3 sigma_d decisions turn such errors
into visible differences from the NumPy specification (up to 140/255 on noisy edges,
measured); the exact shader decode matched NumPy on every test image.

Textures and block lists are made once per image size and kept (``recover`` gives every
tile the same size, ``aarecovery.tiling``); the result texture has F's bit depth, so an
8-bit result is read back as 8-bit and a 16-bit one as 16-bit.
"""

import contextlib
import functools
import time
from collections import namedtuple

import moderngl
import numpy as np

from ...spec.local_plan import FLAT_SPAN, LocalStrength, strength_map
from ...spec.pure_colours import INK_COUNT, PALETTE_SIZE, RIDGE_NOISE_MARGIN
from ...spec.ramp_lookup import table_bends
from ...tiling import DEFAULT_TILES
from ..base import Capabilities, ReadyResult, RecoveryMaps
from .classify import BlockClassifier, BlockLists, block_grid
from .context import REQUIRED_VERSION, GLUnavailable, create_context
from .paths import ComputePath, FragmentPath, available_paths, choose_path, software_renderer

__all__ = ["GLBackend", "GLUnavailable", "EngineTexture"]

#: A texture the engine shares with its caller: `channel` is None for RGBA images or the
#: channel holding a map; `linear` says whether sampled values are linear light.
EngineTexture = namedtuple("EngineTexture", "texture channel linear")

_CONVERT_NONE, _CONVERT_DECODE, _CONVERT_ENCODE = 0, 1, 2
# The local plan that only gives a plan without one its gate of drawn content (towards O): a
# factor of exactly 1 everywhere.
_GATE_ONLY = LocalStrength(1.0, "none", drawn_ink=False)
# Where each map lives: (texture key, channel).
_MAP_CHANNELS = {"alpha": ("model", 0), "beta": ("model", 1), "residual": ("model", 3),
                 "edge_strength": ("edge", 0), "strength": ("strength", 0)}
# The textures made when first needed: (components, dtype); "result" has F's.
_WORK_TEXTURES = {"original_work": (4, "f4"), "filtered_work": (4, "f4"), "model": (4, "f4"), "edge": (1, "f4"),
                  "local_flat": (1, "f4"), "local_rows": (1, "f4"), "strength_factor": (2, "f4"),
                  "kept_factor": (4, "f4"), "strength": (1, "f4"), "jacobi_constant": (4, "f4"),
                  "iterate_a": (4, "f4"), "iterate_b": (4, "f4"), "wakes": (1, "f1")}
_RESULT_BITS = {np.dtype(np.uint8): 8, np.dtype(np.uint16): 16}
# The storage-buffer binding of the fit's live-block flags (live_blocks.glsl).
_LIVE_FLAGS = 6
# The seen-ink test's compiled lengths (INK_SLOTS in pure_colours.glsl): few programs, each
# looping a constant number of times (no 1: moderngl writes an array of one as a plain
# vec3); a slot past O's inks holds _NO_INK, which no encoded colour (0 to 1) comes within
# INK_TOLERANCE of.
_INK_SLOT_COUNTS = (0, 2, 4, 8, INK_COUNT)
_NO_INK = 4.0


def _ink_slots(prior):
    """The fewest of _INK_SLOT_COUNTS that hold the prior's inks."""
    count = 0 if prior.inks is None else len(prior.inks)
    return min(slots for slots in _INK_SLOT_COUNTS if slots >= count)


#: How a texture of 1 to 4 channels reads as straight RGBA: the texture unit expands grey
#: and RGB for free, where a CPU expansion to RGBA cost more than the upload itself.
_SWIZZLES = {1: "RRR1", 2: "RRRG", 3: "RGB1", 4: "RGBA"}


def _texture_dtype(dtype):
    if dtype == np.uint8:
        return "f1"
    if dtype == np.uint16:
        return "nu2"
    return "f4"


def _current(method):
    """Make the engine's own context current around a method.

    Several standalone contexts may live in one process (an engine per thread, a test's
    second engine); creating or releasing one changes which is current. A borrowed context
    belongs to its window, whose owner keeps it current; every call leaves its bound
    framebuffer as it found it. The classification, the copy of F and the readback bind
    the engine's own framebuffers, which a new image size releases: saved only around the
    passes, the next call restored a released one (an AttributeError from moderngl).
    """
    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        if self._owns_context:
            with self.context:
                return method(self, *args, **kwargs)
        previous = self.context.fbo
        try:
            return method(self, *args, **kwargs)
        finally:
            # One its owner released meanwhile is not ours to bind.
            if previous is not None and not isinstance(previous.mglo, moderngl.mgl.InvalidObject):
                previous.use()
    return wrapper


@contextlib.contextmanager
def _driver_memory(what):
    """Out of memory shows in the driver as a texture or framebuffer it cannot make ("the
    framebuffer is not complete" on llvmpipe, measured under prlimit): a MemoryError, which
    the pipeline turns into its one-line figures. Textures and framebuffers are made when a
    pass first needs them, so this guards each making, not only the upload's."""
    try:
        yield
    except moderngl.Error as error:
        raise MemoryError(f"the GL driver could not make {what}: {error}") from None


class _PendingReadback:
    """A result on its way into a pixel buffer; :meth:`wait` copies it out when it is there."""

    def __init__(self, backend, buffer, array):
        self._backend, self._buffer, self._array = backend, buffer, array

    def wait(self):
        return self._backend._finish_readback(self._buffer, self._array)


def _factor_texture(kept_ink):
    """The local plan's output texture: its factor and gate (two channels), and with
    `kept_ink` the kept ink too (four)."""
    return "kept_factor" if kept_ink else "strength_factor"


class GLBackend:
    """The passes as GLSL shaders in one moderngl context (made or borrowed).

    Parameters
    ----------
    context : moderngl.Context, optional
        A context to borrow; by default a standalone one is made.
    gl_path : {"auto", "fragment", "compute"}
        How the passes run (``paths.choose_path``).
    """

    name = "gl"

    def __init__(self, context=None, gl_path="auto"):
        if context is None:
            self.context = create_context()
            self._owns_context = True
        else:
            if context.version_code < REQUIRED_VERSION:
                raise GLUnavailable(f"the context given offers OpenGL {context.version_code}; "
                                    f"aarecovery needs {REQUIRED_VERSION} or later")
            self.context = context
            self._owns_context = False
        try:
            path = choose_path(self.context, gl_path)
        except Exception:
            self.release()
            raise
        max_tile = int(self.context.info["GL_MAX_TEXTURE_SIZE"])
        default_tile = DEFAULT_TILES["gl-software" if software_renderer(self.context) else "gl"]
        self.capabilities = Capabilities(max_tile=max_tile, default_tile=min(default_tile, max_tile),
                                         gl_paths=available_paths(self.context), gl_path=path)
        self._framebuffers = {}
        self._path = (ComputePath if path == "compute" else FragmentPath)(self.context, self._framebuffer)
        #: Whether the compute path's fit keeps its neighbourhoods in shared memory: off, as
        #: no device measured faster with it (``paths.py``); ``aarecovery bench`` times both.
        self.shared_tile = False
        #: None, or a callable that ``aarecovery bench`` gives to time the stages: called with
        #: "upload", "classify" or "passes" once the work of that stage is finished.
        self.stage_clock = None
        #: None, or a callable that ``aarecovery bench --passes`` gives to time each pass on
        #: its own: called with the pass's label and its seconds, the context finished
        #: before and after it (the device's time for that pass, and the wait).
        self.pass_clock = None
        #: Whether the local plan's region sums read two texels at a time (``textureGather``,
        #: GL 4.0; ``local_plan.glsl``); the tests switch it off to check GL 3.3's loop.
        self.gather_region_sums = self.context.version_code >= 400
        self._classifier = BlockClassifier(self.context, compute="compute" in self.capabilities.gl_paths,
                                           runs=path == "fragment")
        self._textures = {}
        self._pixel_buffers = {}
        self._key = None
        self._lists = {}
        self._staging = {}
        self._readbacks = []
        self._next_readback = 0
        # A GPU copies a result into a pixel buffer while it computes the next tile; a
        # software renderer would only add a copy (llvmpipe computes on the CPU anyway).
        self._overlap_readback = not software_renderer(self.context)
        #: Whether 8-bit RGB images are uploaded as they are into a buffer and expanded to
        #: RGBA8 by a compute pass (``unpack_rgb8.comp``) instead of by the driver. On an
        #: NVIDIA H100 the upload of a 4096 x 4096 RGB pair took 14-16 ms against 60-78 ms
        #: as RGB texture writes (the driver expands the rows on the CPU, 3.5 GB/s); on
        #: llvmpipe the pass cost more than the driver's expansion (5.1 against 0.8 ms at
        #: 1024 x 1024), so GPUs on the compute path only. The tests switch it on to check it
        #: everywhere. Packing the result into RGB rows the same way before its readback was
        #: measured too and dropped: 17.5 ms against 3.9 ms for a direct read on the H100.
        self.unpack_rgb8_on_gpu = path == "compute" and self._overlap_readback
        self._ran = None
        self._factor_for = None

    # -- images -----------------------------------------------------------------------------
    @_current
    def load(self, original, o_layout, filtered, f_layout, linear_input, blend_space):
        o_dtype, f_dtype = self._configure(o_layout, f_layout, linear_input, blend_space)
        size = (f_layout.width, f_layout.height)
        key = (size, o_dtype, o_layout.channels, f_dtype, f_layout.channels, self.unpack_rgb8_on_gpu)
        if key != self._key:
            self._allocate(size, o_dtype, o_layout.channels, f_dtype, f_layout.channels)
            self._key = key
        self._upload("original", original, o_layout, o_dtype)
        self._upload("filtered", filtered, f_layout, f_dtype)
        self._factor_for = None
        self._stage("upload")
        self._classified = set()
        self._working_lists = set()
        self._ran = None
        # The blocks are classified when a run first needs them: F's for the paper's model,
        # O's alone with pure colours (classifying F as well cost 25 x 10-17 ms of CPU in the
        # 1024 tiles of a 4096 x 4096 thin-feature pair on llvmpipe).

    def _configure(self, o_layout, f_layout, linear_input, blend_space):
        """The shader defines and formats for a pair; returns the textures' dtypes for O and F."""
        if blend_space == "linear" and not linear_input:
            input_mode, output_mode = _CONVERT_DECODE, _CONVERT_ENCODE
        elif blend_space == "srgb" and linear_input:
            input_mode, output_mode = _CONVERT_ENCODE, _CONVERT_DECODE
        else:
            input_mode = output_mode = _CONVERT_NONE
        # The result texture has F's format where the path can write it (compute shaders store
        # no 3-channel formats, and 16-bit RGB need not be renderable): it then starts as a
        # copy of F, and the readback needs no conversion.
        bits = _RESULT_BITS.get(np.dtype(f_layout.dtype))
        self._result_is_filtered_format = bits is not None and (
            f_layout.channels != 3 or (bits == 8 and self._path.name == "fragment"))
        result_channels = f_layout.channels if self._result_is_filtered_format else 4
        self._defines = {"INPUT_CONVERT": input_mode, "OUTPUT_CONVERT": output_mode,
                         "EXACT_UNTOUCHED": int(f_layout.dtype != np.uint8),
                         "WORK_IS_LINEAR": int(blend_space == "linear"), "RESULT_CHANNELS": result_channels,
                         # The result texture's image format, for the compute path's imageStore.
                         "RESULT_FORMAT": ("r", "rg", "rgb", "rgba")[result_channels - 1] + (str(bits) if bits else "32f")}
        # Straight from the result texture into the caller's layout where it holds F's
        # channels in order (grey+alpha in RGBA does not).
        self._readback_channels = 4 if result_channels == 4 and f_layout.channels == 2 else f_layout.channels
        self._blend_space = blend_space
        self._linear = dict.fromkeys(("original", "filtered", "result"), linear_input)

        def texture_dtype(layout):
            return layout.dtype if layout.dtype in (np.uint8, np.uint16) else np.dtype(np.float32)

        o_dtype, f_dtype = texture_dtype(o_layout), texture_dtype(f_layout)
        # Opaque integer inputs already in the working space's encoding are their own working
        # space: a texel reads as value / (2^n - 1), exactly what to_working_space stores.
        # Float inputs are not: the pass clamps them to [0, 1].
        self._uploads_are_working = (input_mode == _CONVERT_NONE and o_dtype != np.float32 and f_dtype != np.float32
                                     and not o_layout.alpha and not f_layout.alpha)
        return o_dtype, f_dtype

    def _timed(self, label, work):
        """Run `work()`, a pass or a copy on the GPU; with a pass clock, waited for and timed."""
        if self.pass_clock is None:
            return work()
        self.context.finish()
        start = time.perf_counter()
        work()
        self.context.finish()
        self.pass_clock(label, time.perf_counter() - start)

    def _run_pass(self, shader, inputs, outputs, **options):
        """One pass on the chosen path (``paths.py``), labelled for the pass clock."""
        defines = options.get("defines") or {}
        details = [f"pass {defines['LOCAL_PASS']}"] if "LOCAL_PASS" in defines else []
        details += ["final"] if defines.get("FINAL") else []
        label = shader + (f" ({', '.join(details)})" if details else "")
        self._timed(label, lambda: self._path.run_pass(shader, inputs, outputs, **options))

    def _stage(self, name):
        if self.stage_clock is not None:
            self.context.finish()
            self.stage_clock(name)

    def _upload(self, name, image, layout, dtype):
        pixels = image.reshape(layout.height, layout.width, layout.channels)
        if pixels.dtype != dtype or not pixels.flags.c_contiguous:
            # A tile is a strided view of the image: gathered into a buffer kept for the
            # next tile, without a fresh allocation's page faults.
            staging = self._staging.get(name)
            if staging is None or staging.shape != pixels.shape or staging.dtype != dtype:
                staging = self._staging[name] = np.empty(pixels.shape, dtype)
            np.copyto(staging, pixels, casting="same_kind")
            pixels = staging
        packed = self._pixel_buffers.get(f"packed_{name}")
        if packed is None:
            self._textures[name].write(pixels)
            return
        packed.write(pixels)
        packed.bind_to_storage_buffer(0)
        self._run_pass("unpack_rgb8", {}, [self._textures[name]])

    def _unpacks_rgb8(self, dtype, channels):
        """Whether an image of this dtype and channel count goes through ``unpack_rgb8.comp``."""
        return self.unpack_rgb8_on_gpu and self._path.name == "compute" and channels == 3 and dtype == np.uint8

    def _lists_named(self, name):
        """The block lists kept under `name`, made for the loaded size."""
        grid = block_grid(self._key[0])
        lists = self._lists.get(name)
        if lists is None or lists.grid != grid:
            if lists is not None:
                self._path.forget_blocks(lists)
                lists.release()
            lists = self._lists[name] = BlockLists(self.context, grid)
        return lists

    def _block_lists(self, name):
        """The block lists of the uploaded O or F (`name`), classified on the GPU when first asked for."""
        lists = self._lists_named(name)
        if name not in self._classified:
            self._timed("classify", lambda: self._classifier.classify(self._textures[name], lists))
            self._classified.add(name)
        return lists

    def _texture(self, size, components, dtype):
        with _driver_memory(f"a {size[0]}x{size[1]} texture"):
            texture = self.context.texture(size, components, dtype=dtype, alignment=1)
        texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        texture.repeat_x = texture.repeat_y = False
        return texture

    def _allocate(self, size, o_dtype, o_channels, f_dtype, f_channels):
        self._release_images()
        try:
            self._allocate_images(size, o_dtype, o_channels, f_dtype, f_channels)
        except MemoryError:
            self._release_images()
            raise

    def _allocate_images(self, size, o_dtype, o_channels, f_dtype, f_channels):
        t = self._textures
        for name, dtype, channels in (("original", o_dtype, o_channels), ("filtered", f_dtype, f_channels)):
            if self._unpacks_rgb8(dtype, channels):
                # Rows of 3 bytes a pixel, rounded up to whole 4-byte words for the shader.
                with _driver_memory(f"a {size[0]}x{size[1]} buffer"):
                    self._pixel_buffers[f"packed_{name}"] = self.context.buffer(
                        reserve=-(-3 * size[0] * size[1] // 4) * 4)
                channels = 4
            t[name] = self._texture(size, channels, _texture_dtype(dtype))
            t[name].swizzle = _SWIZZLES[channels]
        result_channels = self._defines["RESULT_CHANNELS"]
        t["result"] = self._texture(size, result_channels, _texture_dtype(f_dtype))
        t["result"].swizzle = _SWIZZLES[result_channels]
        # Two, so that a tile's result can be read while the next one's is started; flat, as
        # each tile reads the part it decides.
        self._readbacks = [np.empty(size[0] * size[1] * 4, np.dtype(f_dtype)) for _ in range(2)]

    def _work(self, name):
        """A working texture of the loaded size, made when first needed and kept."""
        if name not in self._textures:
            components, dtype = _WORK_TEXTURES[name]
            self._textures[name] = self._texture(self._key[0], components, dtype)
        return self._textures[name]

    def _working_textures(self):
        if self._uploads_are_working:
            return self._textures["original"], self._textures["filtered"]
        return self._work("original_work"), self._work("filtered_work")

    def _framebuffer(self, textures):
        key = tuple(id(texture) for texture in textures)
        if key not in self._framebuffers:
            with _driver_memory("a framebuffer"):
                self._framebuffers[key] = self.context.framebuffer(list(textures))
        return self._framebuffers[key]

    # -- passes -----------------------------------------------------------------------------
    def _passes(self):
        """Blending and depth tests off for the passes; a borrowed context's enable flags as
        they were afterwards (its framebuffer: ``_current``)."""
        return self.context.scope(self._framebuffer([self._textures["result"]]), enable_only=moderngl.NOTHING)

    def _to_working_space(self, lists=None, list_name=None):
        """O and F into the working textures, over a block list or (`lists` None) everywhere."""
        original_work, filtered_work = self._working_textures()
        if self._uploads_are_working:
            return
        self._run_pass("to_working_space", {"original_image": self._textures["original"],
                                           "filtered_image": self._textures["filtered"]},
                      [original_work, filtered_work], blocks=lists, list_name=list_name,
                      defines=self._defines)

    @_current
    def run(self, plan, maps):
        prior = plan.pure_colours
        # Pure colours restore thin features that the filter erased, where F is flat but O is
        # not: their passes cover O's active blocks, not F's, and where the GPU classifies,
        # only those near a possible ridge or a change of F (_pure_colour_lists). Maps show
        # the fit's model wherever O has edges: there O's.
        if prior is None:
            active = "filtered"
        else:
            listed = plan.pure_colour_blocks and self._classifier.compute and not maps
            active = "pure_colours" if listed else "original"
        lists = self._block_lists("original" if active == "pure_colours" else active)
        self._stage("classify")
        original_work, filtered_work = self._working_textures()
        sources = {"original_work": original_work, "filtered_work": filtered_work,
                   "filtered_image": self._textures["filtered"]}
        uniforms = {"sigma_d": plan.sigma_d, "sigma_e": plan.sigma_e, "strength": plan.strength,
                    "untouched_span": plan.untouched_span}
        # The ramp lookup reads the table the pure colours read, when the plan has both.
        ramp = plan.ramp_table if plan.iterations > 0 else None
        if prior is not None or ramp is not None:
            sources["transfer_table"] = self._transfer_table(prior if prior is not None else ramp)
        if prior is not None:
            uniforms.update(self._pure_colour_uniforms(prior))
        # Towards O reads the local plan's gate (its factor's second channel); a plan
        # without a local plan gets one whose factor is exactly 1.
        local_plan = plan.local if plan.local is not None or not plan.toward_original else _GATE_ONLY
        local = local_plan is not None
        drawn_only = prior is not None and prior.drawn_only
        gated = drawn_only and prior.ink_gate
        # Where the prior's gate leaves the drawn ink out, towards O reads the ink where F kept
        # O's contrast: a third channel (LocalStrength.kept_ink), in a texture of its own.
        kept_ink = plan.toward_original and plan.local is not None and drawn_only and not gated
        if local:
            sources["strength_factor"] = self._work(_factor_texture(kept_ink))
        defines = {**self._defines, "PURE_COLOURS": int(prior is not None), "LOCAL_STRENGTH": int(local),
                   "TOWARD_ORIGINAL": int(plan.toward_original), "BEST_PAIR": int(plan.best_pair),
                   "JACOBI_CONSTANT": int(prior is not None or plan.toward_original)}
        if prior is not None:
            defines.update(self._pure_colour_defines(prior))
            # Pure colours on drawn content only, gated by the local plan's regions' weight.
            defines["PURE_GATE"] = int(local and prior.drawn_only)
            defines["BACKED_OR_SEEN"] = int(local and prior.backed_or_seen)
        if ramp is not None:
            if prior is not None and (ramp.key != prior.key or not np.array_equal(ramp.table, prior.table)):
                raise ValueError(f"the ramp lookup's table (key {ramp.key!r}) is not the pure colours' (key "
                                 f"{prior.key!r}): the passes hold one table (aarecovery.plan.ramp gives them one)")
            defines["TABLE_KEY"] = ramp.key_code
            sources["original_image"] = self._textures["original"]
            sources["transfer_bends"] = self._transfer_bends(ramp)
        pure_gate = bool(defines.get("PURE_GATE"))
        split = None
        with self._passes():
            # Gated pure colours read the gate where they list their blocks: the local plan's
            # factor first, over O's blocks.
            if active == "pure_colours" and not pure_gate:
                lists, split = self._pure_colour_lists(lists, RIDGE_NOISE_MARGIN * prior.ridge_noise, pure_gate)
            if local:
                # Towards O reads the gate too: with the drawn ink where no prior's gate decides.
                self._local_factor(local_plan, None if maps else (lists, "original" if pure_gate else active),
                                   ink_gate=gated or (plan.toward_original and not drawn_only),
                                   ink_span=prior.ink_span if gated else FLAT_SPAN,
                                   for_beta=prior is None and not plan.toward_original, kept_ink=kept_ink)
            if active == "pure_colours" and pure_gate:
                lists, split = self._pure_colour_lists(lists, RIDGE_NOISE_MARGIN * prior.ridge_noise, pure_gate)
            if maps:
                self._strength_map(plan)
            if active not in self._working_lists:
                self._to_working_space(lists, "dilated")
                self._working_lists.add(active)
            # With pure colours the fit covers O's active blocks, and where the classification
            # runs on the GPU it flags those whose steps can change anything (live_blocks.glsl):
            # the steps cover only them. (Over F's blocks nearly all are live: there the flags
            # and their lists cost more than they spare.)
            live = (self._live_blocks() if plan.iterations > 0 and active != "filtered" and self._classifier.compute
                    else None)
            if (plan.iterations > 0 or maps) and split is not None:
                # The extension tests only where a ridge could be extended: the same model.
                for part, no_extension in zip(split, (0, 1)):
                    self._fit_blend_model(sources, uniforms, {**defines, "NO_EXTENSION": no_extension}, part, maps,
                                          live, only_listed=True)
            elif plan.iterations > 0 or maps:
                self._fit_blend_model(sources, uniforms, defines, lists, maps, live)
            if live is not None:
                self._timed("live blocks", lambda: self._classifier.list_flagged(*live))
            result = self._textures["result"]
            keep = {"filtered_image": self._textures["filtered"]}
            if self._result_is_filtered_format:
                # A copy (a memcpy on llvmpipe: 10 ms against 110 ms for keep_filtered over
                # the inactive 85% of a 4096 x 4096 threshold pair, CPU time).
                self._timed("copy of F", lambda: self.context.copy_framebuffer(
                    self._framebuffer([result]), self._framebuffer([self._textures["filtered"]])))
            elif plan.iterations == 0:
                self._run_pass("keep_filtered", keep, [result], defines=defines)
            else:
                # F wherever the steps do not write: outside the live blocks when listed.
                self._run_pass("keep_filtered", keep, [result], blocks=lists if live is None else live[1],
                              list_name="inactive", defines=defines)
            if plan.iterations > 0:
                last_input = self._jacobi_steps(sources, defines, lists if live is None else live[1], plan.iterations,
                                                only_listed=live is not None)
            if ramp is not None:
                self._ramp_lookup(sources, defines, last_input)
        self._stage("passes")
        self._ran = {"maps": maps}

    def _pure_colour_lists(self, original_lists, ridge_floor, gated):
        """The blocks the pure colours' fit covers, listed on the GPU once per pair (GL 4.3),
        and those of them split by whether a ridge could be extended there.

        O's active blocks (`original_lists`) near a pixel where F varies or that could be a
        thin feature's ridge (``pure_colour_blocks.glsl``; twin ``blocks.pure_colour_mask``):
        elsewhere the fit gives F exactly and nothing to gather. Of those, the blocks with no
        possible ridge near, or none beside an open gate of drawn content (`gated`: the local
        plan's factor is made), take the fit without the extension tests, which give nothing
        there and which llvmpipe runs under a mask wherever it draws. The working space is
        made over O's dilated blocks first: the wakes read O there, and those blocks hold every
        block the fit over these lists reads. `ridge_floor`: the ridge's noise margin
        (``possible_ridges``).

        Returns
        -------
        lists : BlockLists
            Every block the fit covers.
        split : tuple of two BlockLists
            Those near a ridge's wake (the whole fit), and the others (no extension).
        """
        key = ("pure_colours", float(ridge_floor), gated)
        parts = ("pure_colours", "pure_colour_ridges", "pure_colour_plain")
        if key not in self._classified:
            self._classified -= {name for name in self._classified if isinstance(name, tuple)}
            if not gated:
                self._factor_for = None  # the local plan's factor covers the lists' blocks
            if "original" not in self._working_lists:
                self._to_working_space(original_lists, "dilated")
                self._working_lists.add("original")
            self._working_lists.add("pure_colours")
            lists, ridges, plain = (self._lists_named(name) for name in parts)
            original_work, _ = self._working_textures()
            inputs = {"original_work": original_work, "filtered_image": self._textures["filtered"]}
            wakes = self._work("wakes")
            self._run_pass("flag_pure_colour_blocks", inputs, [wakes], blocks=original_lists, list_name="active",
                          uniforms={"ridge_floor": key[1]}, defines=self._defines)
            # The local plan's factor was made first (its gate in the second channel).
            gate = self._work(_factor_texture(self._factor_for[5])) if gated else None
            self._timed("pure colour blocks", lambda: self._classifier.list_near_wakes(
                wakes, original_lists, lists, (ridges, plain), gate))
            self._classified.add(key)
        lists, ridges, plain = (self._lists[name] for name in parts)
        return lists, (ridges, plain)

    def _local_factor(self, local, blocks=None, ink_gate=False, ink_span=FLAT_SPAN, for_beta=False, kept_ink=False):
        """The local plan's factor of beta for the loaded O, once per pair and plan (three passes).

        `blocks`: ``(lists, name)``, the block lists of the run, when only the fit reads the
        factor (at its own pixel, in the active blocks): the last pass then covers the active
        blocks and the first two the dilated ones, whose 16-pixel ring holds every value the
        region sums of an active pixel read (REGION_RADIUS = 8). The same factor there, bit
        for bit; the three passes over the whole image took 1.5 s of the 2.2-2.6 s of CPU of
        the tiles of the 4096 x 4096 photo pair (llvmpipe), 0.6 s of 1.25-1.8 s now. None:
        the whole image, as the strength map reads it. `ink_gate`: the second channel (the
        gate of pure colours on drawn content only) counts the drawn ink too, recurring within
        `ink_span` (``PureColourPrior.ink_span``). `for_beta`: with `blocks`, the factor only
        multiplies beta (no pure colours, no move towards O): where F is flat around a pixel,
        whose beta is 0, the last pass counts no drawn ink (``FACTOR_FOR_BETA`` in
        ``local_plan.glsl``), and the factor there is not the specification's. `kept_ink`: a
        third channel holds the drawn ink's weight towards O where F kept O's contrast
        (``LocalStrength.kept_ink``), in a texture of four channels (``kept_factor``) rather
        than ``strength_factor``'s two.
        """
        for_beta = bool(for_beta and blocks is not None)
        kept_ink = bool(kept_ink)
        if self._factor_for in ((local, ink_gate, ink_span, False, None, kept_ink),
                                (local, ink_gate, ink_span, for_beta, blocks and blocks[1], kept_ink)):
            return
        defines = {"LOCAL_ENCODE": int(self._linear["original"]), "INK_BY_LUMA": int(ink_gate and ink_span > FLAT_SPAN),
                   "REGION_GATHER": int(self.gather_region_sums)}
        last_inputs = {"local_input": self._work("local_rows"), "original_image": self._textures["original"]}
        if for_beta or kept_ink:
            last_inputs["filtered_image"] = self._textures["filtered"]
        steps = (({"original_image": self._textures["original"]}, "local_flat", "dilated"),
                 ({"local_input": self._work("local_flat")}, "local_rows", "dilated"),
                 (last_inputs, _factor_texture(kept_ink), "active"))
        for number, (inputs, output, list_name) in enumerate(steps, 1):
            where = {} if blocks is None else {"blocks": blocks[0], "list_name": list_name}
            uniforms = {"textured": local.textured, "ink_shares": tuple(map(float, local.ink_shares)),
                        "ink_gate_span": float(ink_span)}
            beta_only = ({"FACTOR_FOR_BETA": int(for_beta), "DRAWN_INK": int(local.drawn_ink), "INK_GATE": int(ink_gate),
                          "KEPT_INK": int(kept_ink)} if number == 3 else {})
            self._run_pass("local_plan", inputs, [self._work(output)], uniforms=uniforms,
                          defines={**defines, **beta_only, "LOCAL_PASS": number}, **where)
        self._factor_for = (local, ink_gate, ink_span, for_beta, blocks and blocks[1], kept_ink)
        # Gated pure colours listed their blocks by this factor's gate.
        self._classified -= {name for name in self._classified if isinstance(name, tuple) and name[2]}

    def _strength_map(self, plan):
        """The strength map of the maps: the plan's strength times the local factor (read back)."""
        factor = None
        if plan.local is not None:
            texture = self._work(_factor_texture(self._factor_for[5]))
            channels = np.empty(self._key[0][::-1] + (texture.components,), np.float32)
            texture.read_into(channels)
            factor = channels[..., 0]
        self._work("strength").write(strength_map(plan, factor, self._key[0][::-1]))

    def _transfer_table(self, prior):
        """The filter's table (3 KB; a colour map's 3-D table 384 KB): per run, as it belongs
        to the plan, not to the loaded pair."""
        table = np.ascontiguousarray(prior.table, np.float32)
        if table.ndim == 4:
            # (R, G, B, 3) in C order: the texture's x runs along B (transfer_table.glsl).
            texture = self._textures.get("transfer_map")
            if texture is None or texture.size != table.shape[2::-1]:
                if texture is not None:
                    texture.release()
                texture = self._textures["transfer_map"] = self.context.texture3d(table.shape[2::-1], 3, dtype="f4")
                texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
                texture.repeat_x = texture.repeat_y = texture.repeat_z = False
            texture.write(table)
            return texture
        if "transfer_table" not in self._textures:
            self._textures["transfer_table"] = self._texture((256, 1), 3, "f4")
        self._textures["transfer_table"].write(table)
        return self._textures["transfer_table"]

    def _transfer_bends(self, ramp):
        """The ramp lookup's table bends (``spec.ramp_lookup.table_bends``), per run as the table."""
        if "transfer_bends" not in self._textures:
            self._textures["transfer_bends"] = self._texture((256, 1), 3, "f4")
        self._textures["transfer_bends"].write(np.ascontiguousarray(table_bends(ramp.table), np.float32))
        return self._textures["transfer_bends"]

    @staticmethod
    def _pure_colour_defines(prior):
        """The prior's switches, compiled in (pure_colours.glsl says why)."""
        return dict(TABLE_KEY=prior.key_code, CLAMP_ENDS=int(prior.key_low is not None), TO_CUBE=int(prior.to_cube),
                    EXPLAIN_FILTERED=int(prior.explain_filtered), INK_SLOTS=_ink_slots(prior))

    def _pure_colour_uniforms(self, prior):
        """The palette and the table's key range as uniforms."""
        palette = np.zeros((PALETTE_SIZE, 3), np.float32)
        colours = prior.palette_in(self._blend_space)
        palette[:len(colours)] = colours
        inks = np.full((_ink_slots(prior), 3), _NO_INK, np.float32)
        if len(inks):
            inks[:len(prior.inks)] = prior.inks
        low, high = prior.key_range()
        return dict(palette_size=len(colours), palette=[tuple(map(float, colour)) for colour in palette],
                    inks=[tuple(map(float, colour)) for colour in inks],
                    key_low=tuple(map(float, low)), key_high=tuple(map(float, high)),
                    noise_contrast=float(prior.noise_contrast), ridge_noise=float(prior.ridge_noise),
                    luma_purity=float(prior.luma_purity))

    def _live_blocks(self):
        """The flags the fit sets and the lists made of them (``live_blocks.glsl``), flags cleared."""
        grid = block_grid(self._key[0])
        lists = self._lists.get("live")
        if lists is None or lists.grid != grid:
            if lists is not None:
                self._path.forget_blocks(lists)
                lists.release()
            lists = self._lists["live"] = BlockLists(self.context, grid)
        flags = self._pixel_buffers.get("live_flags")
        if flags is None:
            # Made with the images (released with them when the tile size changes).
            flags = self._pixel_buffers["live_flags"] = self.context.buffer(reserve=4 * grid[0] * grid[1])
        flags.clear()
        return flags, lists

    def _fit_blend_model(self, sources, uniforms, defines, lists, maps, live=None, only_listed=False):
        """The model and the first Jacobi iterate (and the edge map, the Jacobi steps' constant with pure colours);
        with `live` (flags, lists), the blocks whose Jacobi steps can change anything flagged."""
        pure = defines["JACOBI_CONSTANT"]
        outputs = [self._work("model"), self._work("iterate_a")]
        if maps:
            # Maps are read everywhere; outside the active blocks they show the unfitted model.
            outputs.append(self._work("edge"))
            self._framebuffer([outputs[0]]).clear(0.5, 0.0, 0.0, 0.0)
            self._framebuffer([outputs[2]]).clear(0.0, 0.0, 0.0, 0.0)
        locations = {}
        if pure:
            outputs.append(self._work("jacobi_constant"))
            locations = dict(CONSTANT_LOCATION=2 + int(maps))
        if live is not None:
            live[0].bind_to_storage_buffer(_LIVE_FLAGS)
            uniforms = {**uniforms, "live_columns": live[1].grid[0]}
        self._run_pass("fit_blend_model", sources, outputs, blocks=lists, list_name="active", uniforms=uniforms,
                      defines={**defines, "MAPS": int(maps), "SHARED_TILE": int(self.shared_tile),
                               "LIVE_BLOCKS": int(live is not None), **locations},
                      only_listed=only_listed)

    def _jacobi_steps(self, sources, defines, lists, iterations, only_listed=False):
        """Iterations 2..n ping-pong between two textures; the last writes the result.

        R1 from R0 = F is the fit's first iterate; with one iteration the last pass forms it
        again, reading F itself. Every value a step gathers lies in a listed block, where the
        step before wrote it: in an active block (the margin of ``blocks.active_mask``), and
        with the fit's live blocks in one of those (``live_blocks.glsl`` flags the blocks of
        both gathers). Returns the texture the last step read. `only_listed`: the live blocks
        even where they are nearly all (one triangle over every pixel would read the model
        where no fit wrote it this tile).
        """
        inputs = {**sources, "model_map": self._work("model")}
        if defines["JACOBI_CONSTANT"]:
            inputs["jacobi_constant_map"] = self._work("jacobi_constant")
        previous = self._work("iterate_a") if iterations > 1 else sources["filtered_work"]
        for step in range(2 if iterations > 1 else 1, iterations + 1):
            final = step == iterations
            step_input = previous
            if final:
                target = self._textures["result"]
            else:
                target = self._work("iterate_b" if previous is self._textures.get("iterate_a") else "iterate_a")
            self._run_pass("jacobi_step", {**inputs, "previous_iterate": previous}, [target], blocks=lists,
                          list_name="active", defines={**defines, "FINAL": int(final)}, only_listed=only_listed)
            previous = target
        return step_input

    def _ramp_lookup(self, sources, defines, last_input):
        """The ramp lookup over F's active blocks, where it acts (F is not flat): the last step
        again where a pixel takes it, from `last_input` (what that step read), and the lookup
        added (``ramp_lookup.frag``)."""
        inputs = {**sources, "model_map": self._work("model"), "previous_iterate": last_input,
                  "filtered_image": self._textures["filtered"]}
        if defines["JACOBI_CONSTANT"]:
            inputs["jacobi_constant_map"] = self._work("jacobi_constant")
        self._run_pass("ramp_lookup", inputs, [self._textures["result"]], blocks=self._block_lists("filtered"),
                      list_name="active", defines={**defines, "FINAL": 1})

    @_current
    def finish(self):
        self.context.finish()

    # -- results ----------------------------------------------------------------------------
    @_current
    def start_readback(self, window=None):
        rows, columns = window or (slice(0, self._key[0][1]), slice(0, self._key[0][0]))
        height, width = rows.stop - rows.start, columns.stop - columns.start
        slot = self._next_readback
        self._next_readback = 1 - slot
        array = self._readbacks[slot][:height * width * self._readback_channels].reshape(
            height, width, self._readback_channels)
        source = self._framebuffer([self._textures["result"]])
        read = dict(viewport=(columns.start, rows.start, width, height), components=self._readback_channels,
                    dtype=_texture_dtype(array.dtype))
        # The whole result (Engine.result) is read at once: on an NVIDIA H100 a 4096 x 4096
        # RGBA8 result read as RGB took 3.9 ms straight into memory, 1.2 + 7.3 ms through a
        # pixel buffer. Tiles go through a pixel buffer, so that the read overlaps the next
        # tile's passes.
        if not self._overlap_readback or window is None:
            source.read_into(array, **read)
            return ReadyResult(array)
        name = f"readback_{slot}"
        if name not in self._pixel_buffers or self._pixel_buffers[name].size < array.nbytes:
            if name in self._pixel_buffers:
                self._pixel_buffers[name].release()
            self._pixel_buffers[name] = self.context.buffer(reserve=self._readbacks[slot].nbytes, dynamic=True)
        source.read_into(self._pixel_buffers[name], **read)
        return _PendingReadback(self, self._pixel_buffers[name], array)

    @_current
    def _finish_readback(self, buffer, array):
        buffer.read_into(array, size=array.nbytes)
        return array

    @_current
    def read_maps(self):
        if not (self._ran and self._ran["maps"]):
            raise RuntimeError("no maps were computed: call compute(..., maps=True) first")
        width, height = self._key[0]
        model = np.empty((height, width, 4), np.float32)
        self._textures["model"].read_into(model)
        edge = np.empty((height, width), np.float32)
        self._textures["edge"].read_into(edge)
        strength = np.empty((height, width), np.float32)
        self._textures["strength"].read_into(strength)
        return RecoveryMaps(np.ascontiguousarray(model[..., 0]), np.ascontiguousarray(model[..., 1]), edge,
                            np.ascontiguousarray(model[..., 3]), strength)

    def texture(self, name):
        if name in ("result", "original", "filtered"):
            return EngineTexture(self._textures[name], None, self._linear[name])
        if name in _MAP_CHANNELS:
            if not (self._ran and self._ran["maps"]):
                raise RuntimeError(f"the {name} map was not computed: call compute(..., maps=True) first")
            key, channel = _MAP_CHANNELS[name]
            return EngineTexture(self._textures[key], channel, False)
        raise KeyError(f"no texture {name!r}; choose from result, original, filtered, "
                       + ", ".join(_MAP_CHANNELS))

    # -- cleanup ----------------------------------------------------------------------------
    def _release_images(self):
        for framebuffer in self._framebuffers.values():
            framebuffer.release()
        for texture in self._textures.values():
            texture.release()
        for buffer in self._pixel_buffers.values():
            buffer.release()
        self._framebuffers, self._textures, self._pixel_buffers = {}, {}, {}
        self._staging = {}
        self._key = None

    def release(self):
        if hasattr(self, "_path"):
            self._release_objects()
        if self._owns_context:
            self.context.release()
            self._owns_context = False

    @_current
    def _release_objects(self):
        self._path.release()
        for lists in self._lists.values():
            lists.release()
        self._lists = {}
        self._classifier.release()
        self._release_images()
