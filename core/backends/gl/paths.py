"""How a pass runs: as a fragment pass (GL 3.3) or as a compute pass (GL 4.3).

Both paths run the same passes, built from the same GLSL function libraries (``blend_model.glsl``,
``jacobi.glsl``, ``working.glsl``, ...): ``NAME.frag`` draws a full-screen triangle or a quad
per listed run of blocks, ``NAME.comp`` runs a 16 x 16 work group per listed block and stores
its outputs with ``imageStore``. A pass names its inputs (sampler uniforms, :data:`SAMPLER_UNITS`) and its
outputs in order (fragment output locations, image bindings).

Which path ``"auto"`` runs (:func:`choose_path`), measured:

* Mesa llvmpipe (2 cores, GL 4.5): the fragment path. CPU time of the classification and
  passes of ``mode="paper"`` on a 2048 x 2048 pair, fragment against compute: 169 ms against
  377 ms thresholded, 540 ms against 1413 ms under gamma (every pixel fitted). llvmpipe
  shades fragments in 2x2 quads on its rasterizer threads; a compute work group is a loop
  over its invocations.
* NVIDIA H100 (GL 4.3 through EGL, this product's passes, ``aarecovery bench``, classify and
  passes of the safe default at 3840 x 2160): the compute path, 837 MP/s against 151 MP/s
  for the fragment passes under gamma (every pixel fitted), 3.1 GP/s against 0.20 GP/s
  thresholded; data-centre GPUs give fragment shading only a few of their units.

Other GPUs were not measured; compute is the rule wherever GL 4.3 is offered by a GPU.
A shared-memory tile for the fit's neighbourhoods (``SHARED_TILE`` in
``fit_blend_model.comp``) made the fit 1.6x slower on llvmpipe (0.92 s against 0.56 s of CPU,
2048 x 2048 under gamma: barriers are expensive there). On the H100 it changed nothing at
3840 x 2160 (810 against 837 MP/s under gamma, the fit pass alone 1.25 against 0.71 ms) and
helped only at 4096 x 4096 under gamma (743 against 458 MP/s), where every pass then ran
several times slower per pixel than at 3840 x 2160 (half of its work groups were past the
end of the block list, since fixed in ``finish_block_lists.comp``); it stays off
(``GLBackend.shared_tile``; ``aarecovery bench`` times both).
"""

import moderngl

from ...errors import InputError
from ...params import GL_PATHS
from .blocks import BLOCK_SIDE
from .context import COMPUTE_VERSION
from .glsl import load_source

__all__ = ["COMPUTE_VERSION", "SAMPLER_UNITS", "FragmentPath", "ComputePath", "choose_path",
           "available_paths", "software_renderer"]

#: The texture unit of every sampler uniform the passes declare.
SAMPLER_UNITS = {"original_image": 0, "filtered_image": 1, "model_map": 2, "previous_iterate": 3,
                 "original_work": 4, "filtered_work": 5, "transfer_table": 6, "jacobi_constant_map": 7,
                 "strength_factor": 8, "local_input": 9, "transfer_bends": 10}


def available_paths(context):
    """The GL paths `context` can run (``aarecovery.params.GL_PATHS`` less ``"auto"``), fragment first."""
    paths = tuple(path for path in GL_PATHS if path != "auto")
    return paths if context.version_code >= COMPUTE_VERSION else paths[:1]


def software_renderer(context):
    """Whether `context` renders on the CPU (Mesa llvmpipe, softpipe, SwiftShader)."""
    renderer = context.info["GL_RENDERER"].lower()
    return any(name in renderer for name in ("llvmpipe", "softpipe", "swiftshader", "software"))


def _auto_rule(paths, software):
    return "compute" if "compute" in paths and not software else "fragment"


def choose_path(context, requested="auto"):
    """The GL path to run in `context`: `requested`, or by the measured rule for ``"auto"``.

    Raises
    ------
    InputError
        For ``"compute"`` on a context older than GL 4.3.
    """
    paths = available_paths(context)
    if requested == "auto":
        return _auto_rule(paths, software_renderer(context))
    if requested not in paths:
        raise InputError(f"gl_path {requested!r} needs OpenGL 4.3 compute shaders, and this context offers "
                         f"{context.version_code // 100}.{context.version_code // 10 % 10}; use "
                         "gl_path='fragment' or 'auto'")
    return requested


def _set(program, name, value):
    member = program.get(name, None)
    if member is not None:
        member.value = value


class _Path:
    def __init__(self, context, framebuffer):
        self.context = context
        self._framebuffer = framebuffer
        self._programs = {}

    def _prepare(self, program, inputs, uniforms):
        for name, value in uniforms.items():
            _set(program, name, value)
        for name, texture in inputs.items():
            texture.use(SAMPLER_UNITS[name])
            _set(program, name, SAMPLER_UNITS[name])

    def release(self):
        for program in self._programs.values():
            for item in (program if isinstance(program, tuple) else (program,)):
                if item is not None:
                    item.release()
        self._programs = {}


class FragmentPath(_Path):
    """Passes as fragment shaders: a full-screen triangle, or a quad per listed block."""

    name = "fragment"

    def __init__(self, context, framebuffer):
        super().__init__(context, framebuffer)
        self._block_arrays = {}
        # A CPU renderer draws a list that covers nearly everything as one triangle
        # (classify.FULL_SCREEN_SHARE); asking costs a GPU a wait, so it never asks.
        self._full_screen_when_nearly_everything = software_renderer(context)

    def _program(self, shader, vertex, defines):
        key = (shader, vertex, tuple(sorted(defines.items())))
        if key not in self._programs:
            program = self.context.program(vertex_shader=load_source(vertex),
                                           fragment_shader=load_source(f"{shader}.frag", defines))
            full_screen = self.context.vertex_array(program, []) if vertex == "fullscreen.vert" else None
            self._programs[key] = (program, full_screen)
        return self._programs[key]

    def run_pass(self, shader, inputs, outputs, *, blocks=None, list_name=None, uniforms=None, defines=None,
                 only_listed=False):
        """Run pass `shader` over the whole image, or over the blocks of list `list_name`.

        Parameters
        ----------
        shader : str
            The pass's name: ``shader.frag`` (or ``.comp``) in the shader folder.
        inputs : dict of str to moderngl.Texture
            Sampler uniform -> texture.
        outputs : list of moderngl.Texture
            In output-location order, all the size of the image.
        blocks : BlockLists, optional
        list_name : str, optional
            One of ``blocks.LISTS``, with `blocks`.
        uniforms, defines : dict, optional
        only_listed : bool
            Draw the list's blocks even where they are nearly all of them: the pass must not
            write the others (a list that another pass with other defines covers the rest of).
        """
        if (blocks is not None and not only_listed and self._full_screen_when_nearly_everything
                and blocks.nearly_everything(list_name)):
            blocks = None
        program, full_screen = self._program(shader, "fullscreen.vert" if blocks is None else "blocks.vert",
                                             defines or {})
        self._prepare(program, inputs, uniforms or {})
        self._framebuffer(outputs).use()
        if blocks is None:
            full_screen.render(moderngl.TRIANGLES, vertices=3)
            return
        _set(program, "image_size", outputs[0].size)
        _set(program, "block_side", BLOCK_SIDE)
        key = (id(program), id(blocks), list_name)
        if key not in self._block_arrays:
            self._block_arrays[key] = self.context.vertex_array(program, [(blocks.buffers[list_name], "2i/i", "block")])
        blocks.draw(self._block_arrays[key], list_name)

    def forget_blocks(self, blocks):
        """Release the vertex arrays made for `blocks` (before its buffers go)."""
        for key in [key for key in self._block_arrays if key[1] == id(blocks)]:
            self._block_arrays.pop(key).release()

    def release(self):
        for vertex_array in self._block_arrays.values():
            vertex_array.release()
        self._block_arrays = {}
        super().release()


class ComputePath(_Path):
    """Passes as compute shaders: a 16 x 16 work group per listed block, or a grid of them."""

    name = "compute"

    def _program(self, shader, defines):
        key = (shader, tuple(sorted(defines.items())))
        if key not in self._programs:
            self._programs[key] = self.context.compute_shader(load_source(f"{shader}.comp", defines))
        return self._programs[key]

    def run_pass(self, shader, inputs, outputs, *, blocks=None, list_name=None, uniforms=None, defines=None,
                 only_listed=False):
        """As :meth:`FragmentPath.run_pass`; outputs are bound as images 0, 1, ... (a list is
        always dispatched block by block)."""
        program = self._program(shader, {**(defines or {}), "BLOCK_LIST": int(blocks is not None)})
        self._prepare(program, inputs, uniforms or {})
        for binding, texture in enumerate(outputs):
            texture.bind_to_image(binding, read=False, write=True)
        width, height = outputs[0].size
        program["image_size"] = (width, height)
        if blocks is None:
            program.run(-(-width // BLOCK_SIDE), -(-height // BLOCK_SIDE))
        else:
            blocks.dispatch(program, list_name)
        # Later passes fetch what this one stored, and readbacks and other contexts' draws read it.
        self.context.memory_barrier(moderngl.ALL_BARRIER_BITS)

    def forget_blocks(self, blocks):
        pass

