"""The GL backend behind :class:`aarecovery.Engine`: GLSL 3.30 fragment passes on moderngl.

Passes (each has a NumPy twin of the same name in ``aarecovery.spec.passes``):

0. ``to_working_space``, once per image pair: O and F decoded and premultiplied into float
   textures, so that parameter changes never decode again.
1. ``fit_blend_model``: O and F neighbourhoods -> model (alpha, beta, extremes, residual)
   and the first Jacobi iterate, which needs no pass of its own because the F texels it
   gathers were already fetched for Sobel.
2. ``jacobi_step`` (iterations 2..n), the last one fused with ``from_working_space``.
3. ``from_working_space`` alone only for 0 or 1 iterations.

Only the blocks of 16 x 16 pixels where the edge strength can be non-zero are drawn by the
fit and the inner Jacobi passes (``blocks.vert``): where F is not flat for the paper's
model, where O is not flat with pure colours (whose edge strength does not need F's
gradient). Elsewhere beta is 0 and R = F, which the textures hold from the moment the pair
is loaded. On llvmpipe, which shades every
covered fragment, this is what makes mostly flat results (threshold, posterize) fast; a GPU
skips those pixels in the shader's early exit anyway.

Colour conversion happens on fetch, in the shader (colour.glsl), for every bit depth.
sRGB textures would decode 8-bit inputs for free, but llvmpipe's decode is off by up to
1.2e-3 from the exact curve, and the fit's argmax and 3 sigma_d decisions turn such errors
into visible differences from the NumPy specification (up to 140/255 on noisy edges,
measured); the exact shader decode matched NumPy on every test image.
"""

import contextlib
import functools
from collections import namedtuple

import moderngl
import numpy as np

from ...spec.pure_colours import PALETTE_SIZE
from ...tiling import DEFAULT_TILES
from ..base import Capabilities, RecoveryMaps
from .blocks import BLOCK_SIDE, active_blocks
from .context import REQUIRED_VERSION, GLUnavailable, create_context
from .glsl import load_source

__all__ = ["GLBackend", "GLUnavailable", "EngineTexture"]

#: A texture the engine shares with its caller: `channel` is None for RGBA images or the
#: channel holding a map; `linear` says whether sampled values are linear light.
EngineTexture = namedtuple("EngineTexture", "texture channel linear")

_CONVERT_NONE, _CONVERT_DECODE, _CONVERT_ENCODE = 0, 1, 2
_UNITS = {"original_image": 0, "filtered_image": 1, "model_map": 2, "previous_iterate": 3, "recovered_work": 3,
          "original_work": 4, "filtered_work": 5, "transfer_table": 6, "fixed_a_map": 7, "fixed_b_map": 8}
# Where each map lives: (texture key, channel).
_MAP_CHANNELS = {"alpha": ("model", 0), "beta": ("model", 1), "residual": ("model", 3),
                 "edge_strength": ("edge", 0)}


def _texture_dtype(dtype):
    if dtype == np.uint8:
        return "f1"
    if dtype == np.uint16:
        return "nu2"
    return "f4"


#: How a texture of 1 to 4 channels reads as straight RGBA: the texture unit expands grey
#: and RGB for free, where a CPU expansion to RGBA cost more than the upload itself.
_SWIZZLES = {1: "RRR1", 2: "RRRG", 3: "RGB1", 4: "RGBA"}
# Above this share of active blocks one full-screen triangle is cheaper than the blocks.
_FULL_SCREEN_SHARE = 0.9

def _pixels(image, layout, dtype):
    """The image's pixels as a contiguous array of the texture's dtype (floats as float32)."""
    return np.ascontiguousarray(image.reshape(layout.height, layout.width, layout.channels), dtype=dtype)


def _current(method):
    """Make the engine's own context current around a method.

    Several standalone contexts may live in one process (an engine per thread, a test's
    second engine); creating or releasing one changes which is current. A borrowed context
    belongs to its window, whose owner keeps it current.
    """
    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        if not self._owns_context:
            return method(self, *args, **kwargs)
        with self.context:
            return method(self, *args, **kwargs)
    return wrapper


class GLBackend:
    """The passes as GLSL 3.30 fragment shaders in one moderngl context (made or borrowed)."""

    name = "gl"

    def __init__(self, context=None):
        if context is None:
            self.context = create_context()
            self._owns_context = True
        else:
            if context.version_code < REQUIRED_VERSION:
                raise GLUnavailable(f"the context given offers OpenGL {context.version_code}; "
                                    f"aarecovery needs {REQUIRED_VERSION} or later")
            self.context = context
            self._owns_context = False
        max_tile = int(self.context.info["GL_MAX_TEXTURE_SIZE"])
        self.capabilities = Capabilities(max_tile=max_tile, default_tile=min(DEFAULT_TILES["gl"], max_tile))
        self._programs = {}
        self._textures = {}
        self._framebuffers = {}
        self._key = None
        self._readback = None
        self._ran = None
        self._blocks = {}
        self._block_arrays = {}

    # -- programs ---------------------------------------------------------------------------
    def _program(self, fragment, vertex="fullscreen.vert", **defines):
        defines = {**self._defines, **defines}
        key = (fragment, vertex, tuple(sorted(defines.items())))
        if key not in self._programs:
            program = self.context.program(vertex_shader=load_source(vertex),
                                           fragment_shader=load_source(fragment, defines))
            for uniform, unit in _UNITS.items():
                if uniform in program:
                    program[uniform] = unit
            vertex_array = self.context.vertex_array(program, []) if vertex == "fullscreen.vert" else None
            self._programs[key] = (program, vertex_array)
        return self._programs[key]

    # -- images -----------------------------------------------------------------------------
    @_current
    def load(self, original, o_layout, filtered, f_layout, linear_input, blend_space):
        if blend_space == "linear" and not linear_input:
            input_mode, output_mode = _CONVERT_DECODE, _CONVERT_ENCODE
        elif blend_space == "srgb" and linear_input:
            input_mode, output_mode = _CONVERT_ENCODE, _CONVERT_DECODE
        else:
            input_mode = output_mode = _CONVERT_NONE
        self._defines = {"INPUT_CONVERT": input_mode, "OUTPUT_CONVERT": output_mode,
                         "EXACT_UNTOUCHED": int(f_layout.dtype != np.uint8),
                         "WORK_IS_LINEAR": int(blend_space == "linear")}
        self._blend_space = blend_space
        self._linear = dict.fromkeys(("original", "filtered", "result"), linear_input)

        def texture_dtype(layout):
            return layout.dtype if layout.dtype in (np.uint8, np.uint16) else np.dtype(np.float32)

        o_dtype, f_dtype = texture_dtype(o_layout), texture_dtype(f_layout)
        size = (f_layout.width, f_layout.height)
        key = (size, o_dtype, o_layout.channels, f_dtype, f_layout.channels)
        if key != self._key:
            self._allocate(size, o_dtype, o_layout.channels, f_dtype, f_layout.channels)
            self._key = key
        t = self._textures
        original_pixels = _pixels(original, o_layout, o_dtype)
        filtered_pixels = _pixels(filtered, f_layout, f_dtype)
        t["original"].write(original_pixels)
        t["filtered"].write(filtered_pixels)
        # O's blocks are needed only with pure colours: found when first asked for.
        self._original_pixels = original_pixels
        self._set_blocks({"filtered": active_blocks(filtered_pixels)}, size)
        self._model_blocks = "stale"
        with self._passes():
            self._draw(self._framebuffers["working"], "to_working_space.frag",
                       {"original_image": t["original"], "filtered_image": t["filtered"]})
        self._ran = None

    def _prepare_blocks(self, name):
        """Make sure block set `name` exists, and that outside it the model reads as unfitted.

        The block passes write the model, the iterates and the edge map only inside their
        blocks; the final full-image pass reads the model everywhere (beta 0 must mean R = F
        there), and the edge map is read back everywhere. Iterates outside the blocks are
        never read (see :func:`active_blocks`).
        """
        if name not in self._blocks:
            self._set_blocks({name: active_blocks(self._original_pixels)}, self._key[0], keep=True)
        count = self._blocks[name][0]
        if count is not None and self._model_blocks != name:
            self._framebuffers["model"].clear(0.5, 0.0, 0.0, 0.0)
            self._framebuffers["edge"].clear(0.0, 0.0, 0.0, 0.0)
        self._model_blocks = name if count is not None else None

    def _set_blocks(self, block_sets, size, keep=False):
        """Keep instance buffers of active blocks: ``{name: (count, buffer)}``, where a count of
        None means "draw the whole image" (almost every block is active). With `keep`, add
        to the sets already made for this pair instead of replacing them."""
        if not keep:
            for vertex_array in self._block_arrays.values():
                vertex_array.release()
            self._block_arrays = {}
            for _, buffer in self._blocks.values():
                if buffer is not None:
                    buffer.release()
            self._blocks = {}
        total = -(-size[0] // BLOCK_SIDE) * -(-size[1] // BLOCK_SIDE)
        for name, blocks in block_sets.items():
            if name in self._blocks:
                continue
            if len(blocks) > _FULL_SCREEN_SHARE * total:
                self._blocks[name] = (None, None)
            else:
                self._blocks[name] = (len(blocks), self.context.buffer(blocks.tobytes()) if len(blocks) else None)

    def _texture(self, size, components, dtype):
        texture = self.context.texture(size, components, dtype=dtype, alignment=1)
        texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        texture.repeat_x = texture.repeat_y = False
        return texture

    def _allocate(self, size, o_dtype, o_channels, f_dtype, f_channels):
        self._release_images()
        try:
            self._allocate_images(size, o_dtype, o_channels, f_dtype, f_channels)
        except moderngl.Error as error:
            # Out of memory shows in the driver as a texture or framebuffer it cannot make
            # ("the framebuffer is not complete" on llvmpipe, measured under prlimit).
            self._release_images()
            raise MemoryError(f"the GL driver could not make the {size[0]}x{size[1]} textures: {error}") from None

    def _allocate_images(self, size, o_dtype, o_channels, f_dtype, f_channels):
        t = self._textures
        t["original"] = self._texture(size, o_channels, _texture_dtype(o_dtype))
        t["original"].swizzle = _SWIZZLES[o_channels]
        t["filtered"] = self._texture(size, f_channels, _texture_dtype(f_dtype))
        t["filtered"].swizzle = _SWIZZLES[f_channels]
        t["original_work"] = self._texture(size, 4, "f4")
        t["filtered_work"] = self._texture(size, 4, "f4")
        t["model"] = self._texture(size, 4, "f4")
        t["edge"] = self._texture(size, 1, "f4")
        t["fixed_a"] = self._texture(size, 4, "f4")
        t["fixed_b"] = self._texture(size, 4, "f4")
        t["transfer_table"] = self._texture((256, 1), 3, "f4")
        t["iterate_a"] = self._texture(size, 4, "f4")
        t["iterate_b"] = self._texture(size, 4, "f4")
        t["result"] = self._texture(size, 4, _texture_dtype(f_dtype))
        fb = self._framebuffers
        fb["working"] = self.context.framebuffer([t["original_work"], t["filtered_work"]])
        fb["filtered_work"] = self.context.framebuffer([t["filtered_work"]])
        fb["model"] = self.context.framebuffer([t["model"]])
        fb["edge"] = self.context.framebuffer([t["edge"]])
        fb["fit"] = self.context.framebuffer([t["model"], t["iterate_a"]])
        fb["fit_maps"] = self.context.framebuffer([t["model"], t["iterate_a"], t["edge"]])
        fb["fit_pure"] = self.context.framebuffer([t["model"], t["iterate_a"], t["fixed_a"], t["fixed_b"]])
        fb["fit_pure_maps"] = self.context.framebuffer([t["model"], t["iterate_a"], t["edge"], t["fixed_a"],
                                                        t["fixed_b"]])
        fb["iterate_a"] = self.context.framebuffer([t["iterate_a"]])
        fb["iterate_b"] = self.context.framebuffer([t["iterate_b"]])
        fb["result"] = self.context.framebuffer([t["result"]])
        self._readback = np.empty((size[1], size[0], 4), np.dtype(f_dtype))

    # -- passes -----------------------------------------------------------------------------
    @contextlib.contextmanager
    def _passes(self):
        """Blending and depth tests off for the passes; a borrowed context's framebuffer and
        enable flags as they were afterwards."""
        previous = None if self._owns_context else self.context.fbo
        try:
            with self.context.scope(self._framebuffers["working"], enable_only=moderngl.NOTHING):
                yield
        finally:
            if previous is not None:
                previous.use()

    def _draw(self, framebuffer, fragment, inputs, uniforms=None, blocks=None, **defines):
        """One pass: over the whole image, or over the active blocks of the set `blocks` names."""
        count, buffer = self._blocks.get(blocks, (None, None))
        program, vertex_array = self._program(fragment, "fullscreen.vert" if count is None else "blocks.vert",
                                              **defines)
        for name, value in (uniforms or {}).items():
            if name in program:
                program[name] = value
        for uniform, texture in inputs.items():
            texture.use(_UNITS[uniform])
        framebuffer.use()
        if count is None:
            vertex_array.render(moderngl.TRIANGLES, vertices=3)
            return
        if count == 0:
            return
        program["image_size"] = self._key[0]
        program["block_side"] = BLOCK_SIDE
        key = (id(program), blocks)
        if key not in self._block_arrays:
            self._block_arrays[key] = self.context.vertex_array(program, [(buffer, "2i/i", "block")])
        self._block_arrays[key].render(moderngl.TRIANGLES, vertices=6, instances=count)

    @_current
    def run(self, plan, maps):
        prior = plan.pure_colours
        # Pure colours restore thin features that the filter erased, where F is flat but O is
        # not: their passes cover O's active blocks, not F's.
        active = "filtered" if prior is None else "original"
        self._prepare_blocks(active)
        sources = {"original_work": self._textures["original_work"],
                   "filtered_work": self._textures["filtered_work"], "filtered_image": self._textures["filtered"]}
        uniforms = {"sigma_d": plan.sigma_d, "sigma_e": plan.sigma_e, "strength": plan.strength}
        if prior is not None:
            sources["transfer_table"] = self._textures["transfer_table"]
            uniforms.update(self._pure_colour_uniforms(prior))
        defines = {"PURE_COLOURS": int(prior is not None)}
        with self._passes():
            if plan.iterations > 0 or maps:
                self._fit_blend_model(sources, uniforms, defines, active, maps)
            if plan.iterations == 0:
                self._draw(self._framebuffers["result"], "from_working_space.frag", sources, FROM_FILTERED=1)
            else:
                self._jacobi_steps(sources, defines, active, plan.iterations)
        self._ran = {"maps": maps}

    def _pure_colour_uniforms(self, prior):
        """The filter's table (3 KB, into its texture) and the palette as uniforms: per run,
        as they belong to the plan, not to the loaded pair."""
        self._textures["transfer_table"].write(np.ascontiguousarray(prior.table, np.float32))
        palette = np.zeros((PALETTE_SIZE, 3), np.float32)
        colours = prior.palette_in(self._blend_space)
        palette[:len(colours)] = colours
        low, high = prior.key_range()
        return dict(table_key=prior.key_code, palette_size=len(colours),
                    palette=[tuple(map(float, colour)) for colour in palette],
                    key_low=tuple(map(float, low)), key_high=tuple(map(float, high)),
                    clamp_ends=int(prior.key_low is not None), to_cube=int(prior.to_cube))

    def _fit_blend_model(self, sources, uniforms, defines, active, maps):
        """The model and the first Jacobi iterate (and the edge map, the fixed pure colours)."""
        pure = defines["PURE_COLOURS"]
        framebuffer = ("fit_pure" if pure else "fit") + ("_maps" if maps else "")
        outputs = dict(FIXED_LOCATION=2 + int(maps), FIXED_LOCATION_B=3 + int(maps)) if pure else {}
        self._draw(self._framebuffers[framebuffer], "fit_blend_model.frag", sources, uniforms, blocks=active,
                   MAPS=int(maps), **outputs, **defines)

    def _jacobi_steps(self, sources, defines, active, iterations):
        """Iterations 2..n ping-pong between two textures; the last writes the result.

        R1 from R0 = F is the fit's first iterate; with one iteration the last pass forms it
        again, reading F itself, since outside the blocks no iterate is written.
        """
        t = self._textures
        inputs = {**sources, "model_map": t["model"]}
        if defines["PURE_COLOURS"]:
            inputs.update(fixed_a_map=t["fixed_a"], fixed_b_map=t["fixed_b"])
        previous = "iterate_a" if iterations > 1 else "filtered_work"
        for step in range(2 if iterations > 1 else 1, iterations + 1):
            final = step == iterations
            target = "result" if final else ("iterate_b" if previous == "iterate_a" else "iterate_a")
            self._draw(self._framebuffers[target], "jacobi_step.frag", {**inputs, "previous_iterate": t[previous]},
                       blocks=None if final else active, FINAL=int(final), **defines)
            previous = target

    @_current
    def finish(self):
        self.context.finish()

    # -- results ----------------------------------------------------------------------------
    @_current
    def read_result(self):
        self._textures["result"].read_into(self._readback)
        return self._readback

    @_current
    def read_maps(self):
        if not (self._ran and self._ran["maps"]):
            raise RuntimeError("no maps were computed: call compute(..., maps=True) first")
        width, height = self._key[0]
        model = np.empty((height, width, 4), np.float32)
        self._textures["model"].read_into(model)
        edge = np.empty((height, width), np.float32)
        self._textures["edge"].read_into(edge)
        return RecoveryMaps(np.ascontiguousarray(model[..., 0]), np.ascontiguousarray(model[..., 1]), edge,
                            np.ascontiguousarray(model[..., 3]))

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
        self._framebuffers, self._textures = {}, {}
        self._key = None

    def release(self):
        self._release_objects()
        if self._owns_context:
            self.context.release()
            self._owns_context = False

    @_current
    def _release_objects(self):
        self._set_blocks({}, (1, 1))
        self._release_images()
        for program, vertex_array in self._programs.values():
            if vertex_array is not None:
                vertex_array.release()
            program.release()
        self._programs = {}
