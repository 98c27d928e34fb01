"""A Krita layer's pixels as float32 bytes in R, G, B, A order (or grey, alpha), and back.

Krita hands out a layer's pixels in its own channel order (8- and 16-bit RGBA are stored
B, G, R, A; float RGBA as R, G, B, A; ``Node.channels()`` lists the order), as unsigned
integers or floats. The core wants float32 in [0, 1] with straight alpha. Krita's Python may
have no NumPy, so the conversion falls back to the standard library (slower: about a second
per megapixel).
"""

import array
import struct
from dataclasses import dataclass

from aarecovery_bridge import PluginError

# Krita's colour depth -> (struct code, the integer white or None for floats).
DEPTHS = {"U8": ("B", 255), "U16": ("H", 65535), "F16": ("e", None), "F32": ("f", None)}
# Krita's colour model -> channel names in the core's order.
MODELS = {"RGBA": ("Red", "Green", "Blue", "Alpha"), "GRAYA": ("Gray", "Alpha")}
CONVERT_HINT = "convert it with Image > Convert Image Color Space to RGB/Alpha (8-bit, 16-bit or float)"


@dataclass(frozen=True)
class Layout:
    """How a layer stores its pixels.

    Attributes
    ----------
    depth : str
        Krita's colour depth ("U8", "U16", "F16", "F32").
    order : tuple of int
        For each channel in the core's order, its index among the stored channels.
    linear : bool
        The layer's profile has a linear tone curve (Krita's "...-g10.icc" profiles, the
        default of its 16-bit and float documents).
    """

    depth: str
    order: tuple
    linear: bool

    @property
    def channels(self):
        return len(self.order)


def layout_of(node):
    """The :class:`Layout` of paint layer `node`, or PluginError for a colour space it lacks."""
    model, depth = node.colorModel(), node.colorDepth()
    if model not in MODELS or depth not in DEPTHS:
        raise PluginError(f"layer '{node.name()}' is {model} {depth}, which the plug-in does not read; "
                          f"{CONVERT_HINT}")
    stored = [channel.name() for channel in node.channels()]
    try:
        order = tuple(stored.index(name) for name in MODELS[model])
    except ValueError:
        raise PluginError(f"layer '{node.name()}' has the channels {', '.join(stored)}; {CONVERT_HINT}") from None
    profile = node.colorProfile().lower()
    return Layout(depth, order, "g10" in profile or "linear" in profile)


def _numpy():
    try:
        import numpy
    except ImportError:
        return None
    return numpy


def to_float(raw, layout):
    """Stored bytes -> float32 bytes in the core's channel order, integers scaled to [0, 1]."""
    code, white = DEPTHS[layout.depth]
    n = layout.channels
    np = _numpy()
    if np is not None:
        values = np.frombuffer(raw, dtype="<" + {"B": "u1", "H": "u2", "e": "f2", "f": "f4"}[code])
        values = values.reshape(-1, n)[:, list(layout.order)].astype(np.float32)
        return (values / white if white else values).astype("<f4").tobytes()
    values = struct.unpack(f"<{len(raw) // struct.calcsize(code)}{code}", raw)
    out = array.array("f", bytes(4 * len(values)))
    for core_index, stored_index in enumerate(layout.order):
        column = values[stored_index::n]
        out[core_index::n] = array.array("f", [v / white for v in column] if white else column)
    return out.tobytes()


def from_float(data, layout):
    """Float32 bytes in the core's order -> the layer's stored bytes (integers rounded)."""
    code, white = DEPTHS[layout.depth]
    n = layout.channels
    np = _numpy()
    if np is not None:
        values = np.frombuffer(data, dtype="<f4").reshape(-1, n)
        if white:
            values = np.floor(np.clip(values, 0.0, 1.0) * white + 0.5)
        stored = np.empty_like(values)
        stored[:, list(layout.order)] = values
        return stored.astype("<" + {"B": "u1", "H": "u2", "e": "f2", "f": "f4"}[code]).tobytes()
    values = array.array("f", data)
    stored = [0] * len(values)
    for core_index, stored_index in enumerate(layout.order):
        column = values[core_index::n]
        stored[stored_index::n] = [int(min(max(v, 0.0), 1.0) * white + 0.5) for v in column] if white else column
    return struct.pack(f"<{len(stored)}{code}", *stored)


def blend(before, after, mask, channels):
    """`after` where the selection `mask` (one byte a pixel) is full, `before` where it is
    empty, in between where it is partial (float32 bytes in the core's order)."""
    np = _numpy()
    if np is not None:
        b = np.frombuffer(before, dtype="<f4").reshape(-1, channels)
        a = np.frombuffer(after, dtype="<f4").reshape(-1, channels)
        m = np.frombuffer(mask, dtype=np.uint8).astype(np.float32)[:, None] / 255
        return (b + m * (a - b)).astype("<f4").tobytes()
    b, a = array.array("f", before), array.array("f", after)
    out = array.array("f", b)
    for i, weight in enumerate(mask):
        if weight:
            w = weight / 255
            for c in range(i * channels, (i + 1) * channels):
                out[c] = b[c] + w * (a[c] - b[c])
    return out.tobytes()
