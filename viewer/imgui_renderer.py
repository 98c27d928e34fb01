"""A small moderngl renderer for Dear ImGui (imgui-bundle), in a context passed to it.

It implements ImGui 1.92's texture protocol (``ImGuiBackendFlags_RendererHasTextures``):
ImGui creates and grows its font atlas on demand and the renderer uploads what changed.
"""

import ctypes

import moderngl
import numpy as np
from imgui_bundle import imgui

from .glsl import program

__all__ = ["ImGuiRenderer"]

# Vertex and index buffers start at this many bytes and double when a frame needs more.
_INITIAL_BUFFER_BYTES = 1 << 18


def _memory(address, size):
    """A read-only view of `size` bytes that ImGui owns at `address` (no copy)."""
    return memoryview((ctypes.c_ubyte * size).from_address(address)).cast("B")


class ImGuiRenderer:
    """Draws ImGui's draw data with moderngl.

    Parameters
    ----------
    context : moderngl.Context
        Where to draw; the ImGui context must be current (``imgui.create_context()``).
    """

    def __init__(self, context):
        if imgui.get_current_context() is None:
            raise RuntimeError("create an ImGui context (imgui.create_context()) before the renderer")
        self.context = context
        self.program = program(context, "imgui.vert.glsl", "imgui.frag.glsl")
        self.program["u_texture"].value = 0
        self.vertex_buffer = context.buffer(reserve=_INITIAL_BUFFER_BYTES, dynamic=True)
        self.index_buffer = context.buffer(reserve=_INITIAL_BUFFER_BYTES, dynamic=True)
        self.vertex_array = self._make_vertex_array()
        self._textures = {}  # GL name -> moderngl.Texture, for ImGui's texture ids
        io = imgui.get_io()
        io.backend_flags |= imgui.BackendFlags_.renderer_has_textures
        platform_io = imgui.get_platform_io()
        largest = context.info["GL_MAX_TEXTURE_SIZE"]
        platform_io.renderer_texture_max_width = largest
        platform_io.renderer_texture_max_height = largest

    def _make_vertex_array(self):
        # ImDrawVert: float2 pos, float2 uv, uint32 colour (RGBA bytes, normalised).
        assert imgui.VERTEX_SIZE == 20 and imgui.INDEX_SIZE == 4, "unexpected ImGui vertex layout"
        return self.context.vertex_array(
            self.program, [(self.vertex_buffer, "2f 2f 4f1", "in_position", "in_uv", "in_colour")],
            index_buffer=self.index_buffer, index_element_size=imgui.INDEX_SIZE)

    # ------------------------------------------------------------------ textures
    def register_texture(self, texture):
        """Make a moderngl texture usable in ``imgui.image``; returns its ``ImTextureRef``."""
        self._textures[texture.glo] = texture
        return imgui.ImTextureRef(texture.glo)

    def _update_texture(self, data):
        status = data.status
        if status == imgui.ImTextureStatus.want_create:
            texture = self.context.texture((data.width, data.height), 4, dtype="f1")
            texture.filter = (moderngl.LINEAR, moderngl.LINEAR)  # ImGui's baked lines need bilinear
            texture.repeat_x = texture.repeat_y = False
            texture.write(data.get_pixels_array())
            self._textures[texture.glo] = texture
            data.set_tex_id(texture.glo)
            data.status = imgui.ImTextureStatus.ok
        elif status == imgui.ImTextureStatus.want_updates:
            texture = self._textures[data.tex_id]
            pixels = data.get_pixels_array().reshape(data.height, data.width, 4)
            for rect in data.updates:
                block = np.ascontiguousarray(pixels[rect.y:rect.y + rect.h, rect.x:rect.x + rect.w])
                texture.write(block, viewport=(rect.x, rect.y, rect.w, rect.h))
            data.status = imgui.ImTextureStatus.ok
        elif status == imgui.ImTextureStatus.want_destroy and data.unused_frames > 0:
            texture = self._textures.pop(data.tex_id, None)
            if texture is not None:
                texture.release()
            data.set_tex_id(0)
            data.status = imgui.ImTextureStatus.destroyed

    def _update_textures(self, draw_data):
        for data in draw_data.textures:
            if data.status != imgui.ImTextureStatus.ok:
                self._update_texture(data)

    # ------------------------------------------------------------------ drawing
    def _reserve(self, buffer, size):
        if buffer.size < size:
            buffer.orphan(max(size, buffer.size * 2))

    def render(self, draw_data, framebuffer):
        """Draw one frame's ImGui draw data into `framebuffer`.

        Parameters
        ----------
        draw_data : imgui.ImDrawData
            From ``imgui.get_draw_data()`` after ``imgui.render()``.
        framebuffer : moderngl.Framebuffer
            The window's (``context.screen``) or an offscreen one of the display's size.
        """
        self._update_textures(draw_data)
        scale_x, scale_y = draw_data.framebuffer_scale
        display_x, display_y = draw_data.display_pos
        display_width, display_height = draw_data.display_size
        fb_width, fb_height = int(display_width * scale_x), int(display_height * scale_y)
        if fb_width <= 0 or fb_height <= 0 or draw_data.cmd_lists_count == 0:
            return
        context = self.context
        framebuffer.use()
        context.viewport = (0, 0, fb_width, fb_height)
        context.enable_only(moderngl.BLEND)
        context.blend_equation = moderngl.FUNC_ADD
        context.blend_func = (moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA,
                              moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA)
        # Display coordinates (y down) to clip space (y up).
        self.program["u_scale"].value = (2.0 / display_width, -2.0 / display_height)
        self.program["u_translate"].value = (-1.0 - 2.0 * display_x / display_width,
                                             1.0 + 2.0 * display_y / display_height)
        bound = None
        try:
            for draw_list in draw_data.cmd_lists:
                vertex_bytes = draw_list.vtx_buffer.size() * imgui.VERTEX_SIZE
                index_bytes = draw_list.idx_buffer.size() * imgui.INDEX_SIZE
                self._reserve(self.vertex_buffer, vertex_bytes)
                self._reserve(self.index_buffer, index_bytes)
                self.vertex_buffer.write(_memory(draw_list.vtx_buffer.data_address(), vertex_bytes))
                self.index_buffer.write(_memory(draw_list.idx_buffer.data_address(), index_bytes))
                for command in draw_list.cmd_buffer:
                    left, top, right, bottom = command.clip_rect
                    left, right = (left - display_x) * scale_x, (right - display_x) * scale_x
                    top, bottom = (top - display_y) * scale_y, (bottom - display_y) * scale_y
                    if right <= left or bottom <= top:
                        continue
                    texture_id = command.get_tex_id()
                    if texture_id != bound:
                        self._textures[texture_id].use(0)
                        bound = texture_id
                    context.scissor = (int(left), int(fb_height - bottom), int(right - left), int(bottom - top))
                    # moderngl counts `first` in indices; 32-bit indices keep vtx_offset at 0.
                    self.vertex_array.render(moderngl.TRIANGLES, vertices=command.elem_count,
                                             first=command.idx_offset)
        finally:
            context.scissor = None
            context.disable(moderngl.BLEND)

    def release(self):
        """Free the GL objects and tell ImGui its textures are gone."""
        for data in imgui.get_platform_io().textures:
            if data.status != imgui.ImTextureStatus.destroyed and data.tex_id in self._textures:
                data.set_tex_id(0)
                data.status = imgui.ImTextureStatus.destroyed
        for texture in self._textures.values():
            texture.release()
        self._textures.clear()
        io = imgui.get_io()
        io.backend_flags &= ~imgui.BackendFlags_.renderer_has_textures
        self.vertex_array.release()
        self.vertex_buffer.release()
        self.index_buffer.release()
        self.program.release()
