"""Drawing the image area: an image, a map, a difference heat-map, or two of them split.

The view reads the engine's textures directly in the shared GL context; nothing is read back
to the CPU to show a result.
"""

from dataclasses import dataclass
from typing import NamedTuple, Optional

import moderngl

from .glsl import program as build_program

__all__ = ["ImageSource", "Layer", "ImageView", "KIND_COLOUR", "KIND_MAP", "KIND_DIFFERENCE"]

KIND_COLOUR, KIND_MAP, KIND_DIFFERENCE = 0, 1, 2
BACKGROUND = (0.11, 0.11, 0.12)


class ImageSource(NamedTuple):
    """A texture to show, described the way ``Engine.texture()`` describes its own.

    Attributes
    ----------
    texture : moderngl.Texture
        In the context the view draws in.
    channel : int or None
        None for an RGBA image; else the channel holding a single-valued map.
    linear : bool
        True when the values are linear light (the view sRGB-encodes them).
    """

    texture: moderngl.Texture
    channel: Optional[int]
    linear: bool


@dataclass(frozen=True)
class Layer:
    """What one side of the view shows.

    Attributes
    ----------
    kind : int
        :data:`KIND_COLOUR`, :data:`KIND_MAP` or :data:`KIND_DIFFERENCE`.
    first : ImageSource
        The image, the map, or the minuend of the difference.
    second : ImageSource, optional
        The subtrahend of a difference.
    gain : float
        Scale applied to a map value or a difference before display.
    """

    kind: int
    first: object
    second: object = None
    gain: float = 1.0

    @classmethod
    def colour(cls, source):
        """Show an RGBA image (or a map's channel as grey, if `source` names one)."""
        if source.channel is not None:
            return cls(KIND_MAP, source)
        return cls(KIND_COLOUR, source)

    @classmethod
    def map(cls, source, gain=1.0):
        """Show one channel, times `gain`, as grey."""
        return cls(KIND_MAP, source, gain=gain)

    @classmethod
    def difference(cls, first, second, gain=1.0):
        """Show ``max |first - second|`` over channels, times `gain`, as a heat-map."""
        return cls(KIND_DIFFERENCE, first, second, gain=gain)


class ImageView:
    """Draws layers into a rectangle of the current framebuffer.

    One program is compiled per layer configuration (kinds, channels, colour encodings, split
    or not) the first time it is drawn, and kept: llvmpipe pays for both sides of a branch on
    a uniform, so the configuration is baked in as constants instead.

    Parameters
    ----------
    context : moderngl.Context
        The context shared with the engine.
    """

    def __init__(self, context):
        self.context = context
        self._programs = {}

    def _program(self, layers, split):
        def described(layer):
            return (layer.kind, 0 if layer.first.channel is None else int(layer.first.channel),
                    int(bool(layer.first.linear)), int(bool(layer.second is not None and layer.second.linear)))
        key = (split,) + described(layers[0]) + described(layers[1])
        if key not in self._programs:
            defines = {"SPLIT": int(split)}
            for index, layer in enumerate(layers):
                kind, channel, linear_a, linear_b = described(layer)
                defines.update({f"KIND{index}": kind, f"CHANNEL{index}": channel,
                                f"LINEAR{index}_A": linear_a, f"LINEAR{index}_B": linear_b})
            program = build_program(self.context, "fullscreen.vert.glsl", "image_view.frag.glsl", defines)
            for unit, name in enumerate(("u_layer0_a", "u_layer0_b", "u_layer1_a", "u_layer1_b")):
                if name in program:
                    program[name].value = unit
            program["u_background"].value = BACKGROUND
            self._programs[key] = (program, self.context.vertex_array(program, []))
        return self._programs[key]

    def draw(self, area, view, left, right=None):
        """Draw into `area` of the currently bound framebuffer.

        Parameters
        ----------
        area : tuple of int
            ``(x, y, width, height)`` in framebuffer pixels, y counted from the bottom (GL).
        view : ViewState
            Zoom, pan and divider; its view size should equal the area's size.
        left : Layer
            Shown left of the divider, or everywhere when `right` is None.
        right : Layer, optional
            Shown right of the divider.
        """
        split = right is not None
        layers = (left, right if split else left)
        program, vertex_array = self._program(layers, split)
        uniforms = {"u_area": tuple(float(v) for v in area), "u_offset": (view.offset_x, view.offset_y),
                    "u_zoom": view.zoom, "u_split_x": view.split_x if split else float(area[2]) + 1.0,
                    "u_gain": (float(layers[0].gain), float(layers[1].gain))}
        for name, value in uniforms.items():
            if name in program:  # the compiler drops uniforms a configuration never reads
                program[name].value = value
        for unit, layer_index, which in ((0, 0, "first"), (1, 0, "second"), (2, 1, "first"), (3, 1, "second")):
            source = getattr(layers[layer_index], which) or layers[layer_index].first
            source.texture.use(unit)
        previous_viewport = self.context.viewport
        self.context.viewport = tuple(int(v) for v in area)
        self.context.disable(moderngl.BLEND)
        vertex_array.render(moderngl.TRIANGLES, vertices=3)
        self.context.viewport = previous_viewport

    def release(self):
        """Free the programs."""
        for program, vertex_array in self._programs.values():
            vertex_array.release()
            program.release()
        self._programs.clear()
