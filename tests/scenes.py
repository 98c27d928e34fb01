"""Small supersampled test scenes, made in the tests (no files)."""

import numpy as np

from aarecovery.colour import linear_to_srgb, srgb_to_linear


def box_downsample(image, factor):
    height, width = image.shape[0] // factor, image.shape[1] // factor
    return image.reshape(height, factor, width, factor, -1).mean(axis=(1, 3))


def half_plane_coverage(size, angle_degrees, factor=16, offset=0.37):
    """Sub-sample mask of a straight edge through the image centre, shape (size*f, size*f)."""
    n = size * factor
    y, x = (np.mgrid[0:n, 0:n] + 0.5) / factor - size / 2
    angle = np.radians(angle_degrees)
    return (x * np.cos(angle) + y * np.sin(angle)) > offset


def two_colour_edge(size, angle_degrees, colour_a, colour_b, factor=16):
    """A straight antialiased edge between two colours, box-filtered in linear light.

    Returns
    -------
    original : ndarray of uint8, shape (size, size, 3)
        sRGB-encoded.
    mask : ndarray of bool, shape (size*factor, size*factor)
        The supersampled scene: True where colour_a is.
    """
    mask = half_plane_coverage(size, angle_degrees, factor)
    a = srgb_to_linear(np.asarray(colour_a, np.float32))
    b = srgb_to_linear(np.asarray(colour_b, np.float32))
    scene = np.where(mask[..., None], a, b)
    original = linear_to_srgb(box_downsample(scene, factor))
    return to_uint8(original), mask


def to_uint8(image):
    return np.rint(np.clip(image, 0, 1) * 255).astype(np.uint8)


def luminance(encoded):
    linear = srgb_to_linear(np.asarray(encoded, np.float32))
    return linear @ np.array([0.2126, 0.7152, 0.0722], np.float32)


def shapes(size=96, seed=0, factor=4, noise=0.0):
    """Random antialiased discs and wedges in random colours, 8-bit sRGB."""
    rng = np.random.default_rng(seed)
    n = size * factor
    y, x = (np.mgrid[0:n, 0:n] + 0.5) / factor
    scene = np.empty((n, n, 3), np.float32)
    scene[:] = rng.random(3)
    for _ in range(10):
        cx, cy, radius = rng.random() * size, rng.random() * size, rng.random() * size / 4 + 3
        inside = (x - cx) ** 2 + (y - cy) ** 2 < radius ** 2
        if rng.random() < 0.5:
            angle = rng.random() * np.pi
            inside = ((x - cx) * np.cos(angle) + (y - cy) * np.sin(angle) > 0) & \
                ((x - cx) ** 2 + (y - cy) ** 2 < (2 * radius) ** 2)
        scene[inside] = srgb_to_linear(rng.random(3).astype(np.float32))
    image = linear_to_srgb(box_downsample(scene, factor))
    image = image + rng.normal(0, noise, image.shape).astype(np.float32)
    return to_uint8(image)


def disc_and_bar(height=40, width=56, supersample=6):
    """An antialiased RGBA test image: a coloured disc and a slanted bar on a soft gradient."""
    s = supersample
    y, x = np.mgrid[0:height * s, 0:width * s] / s
    disc = (x - 20.3) ** 2 + (y - 18.7) ** 2 < 11.2 ** 2
    bar = np.abs((x - 36) * 0.8 - (y - 20) * 0.6) < 3.1
    rgb = np.empty(x.shape + (3,))
    rgb[...] = np.stack([0.15 + 0.2 * x / width, 0.2 + 0.1 * y / height, 0.3 + 0 * x], -1)
    rgb[disc] = (0.9, 0.75, 0.2)
    rgb[bar] = (0.1, 0.55, 0.85)
    alpha = np.where((x > 44) & (y > 26), 0.45, 1.0)
    rgba = np.concatenate([rgb, alpha[..., None]], -1)
    return rgba.reshape(height, s, width, s, 4).mean(axis=(1, 3))
