"""What every built-in filter shares: the contract check and putting alpha back."""

import numpy as np

from ..errors import InputError

__all__ = ["check_contract", "with_colour", "check_positive"]


def check_contract(image, name="image"):
    if not isinstance(image, np.ndarray) or image.ndim != 3 or image.shape[2] not in (3, 4):
        shape = getattr(image, "shape", type(image).__name__)
        raise InputError(f"{name} has shape {shape}; filters take the core contract, float32 (H, W, 3) "
                         "or (H, W, 4) in [0, 1]: use aarecovery.filters.apply(name, image) for other layouts")
    if image.dtype != np.float32:
        raise InputError(f"{name} has dtype {image.dtype}; filters take float32 in [0, 1]: use "
                         "aarecovery.filters.apply(name, image), which converts uint8/uint16/grey images")
    return image[..., :3]


def with_colour(image, colour):
    colour = np.clip(colour, 0, 1).astype(np.float32, copy=False)
    if image.shape[2] == 4:
        return np.concatenate([colour, image[..., 3:4]], axis=-1)
    return np.ascontiguousarray(colour)


def check_positive(name, value):
    if not np.isfinite(value) or value <= 0:
        raise InputError(f"{name} must be a number above 0, got {value!r}")
