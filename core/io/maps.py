"""The recovery maps as files: 16-bit grey PNGs, scaled so that what matters is visible."""

import os

import numpy as np

from .write import write_image

__all__ = ["MAP_SCALES", "map_paths", "maps_as_images", "write_maps"]

#: Factor each map is multiplied by before it is clipped to [0, 1] and stored as 16-bit
#: grey; ``"sqrt"`` stores the square root, the geometric mean of O's and F's Sobel
#: magnitudes, which makes the weak edges that sigma_e decides about visible.
MAP_SCALES = {"alpha": 1.0, "beta": 1.0, "edge_strength": "sqrt", "residual": 10.0, "strength": 1.0}


def map_paths(folder):
    """The file each map is written to in `folder`, by map name."""
    return {name: os.path.join(folder, f"{name}.png") for name in MAP_SCALES}


def _visible_map(values, scale):
    scaled = np.sqrt(np.maximum(values, 0)) if scale == "sqrt" else values * np.float32(scale)
    return np.rint(np.clip(scaled, 0, 1) * 65535).astype(np.uint16)


def maps_as_images(folder, maps):
    """The :class:`~aarecovery.RecoveryMaps` `maps` as 16-bit images, by the path each goes to in `folder`."""
    return {path: _visible_map(getattr(maps, name), MAP_SCALES[name]) for name, path in map_paths(folder).items()}


def write_maps(folder, maps):
    """Write the :class:`~aarecovery.RecoveryMaps` `maps` into `folder` (which must exist), each atomically."""
    for path, image in maps_as_images(folder, maps).items():
        write_image(path, image)
