"""The GL/NumPy parity tolerances, in one table (as kornia's ``_DTYPE_PRECISIONS``).

Every test that compares the GL backend with the NumPy specification takes its tolerance
from here. The decisions the passes take (the EM's start, the extremes, the pure-colour
tests) are made off exact ties on both backends (``SPREAD_TIE`` in
``aarecovery.spec.blend_model``, ``RIDGE_MARGIN`` in ``aarecovery.spec.pure_colours``), so
what is left is float rounding of the same formulas: fused multiply-adds and reciprocal
divisions on the GPU. README's "Design" section states the result tolerances.
"""

import numpy as np

#: The recovered image R, by its dtype: one 8-bit level, two 16-bit levels, 1e-5 on float.
RESULT = {np.dtype(np.uint8): 1, np.dtype(np.uint16): 2, np.dtype(np.float32): 1e-5}

#: The maps (``aarecovery.RecoveryMaps``), absolute; the edge strength relative. Beta goes
#: through exp(), which GLSL computes within 3 + 2|x| ULP: 1.25e-5 apart measured (a noisy
#: 33 x 16 pair under equalize, test_gl_fuzz seed 1014).
MAPS = {"alpha": 1e-4, "beta": 1e-4, "residual": 1e-5, "edge_strength": 1e-5}

#: The strength map (the local plan's factor), apart from MAPS as only the local plan's tests
#: make it vary: counts are exact on both backends, the share, smoothstep and factor are float32 arithmetic in a different order, and the drawn ink's share
#: is a ratio of colour distances that GLSL's pow() encodes from linear input within a few ULPs,
#: under a smoothstep 3.75 steep: 1.76e-5 apart measured (posterized bars over a photo, linear)
#: on llvmpipe, 6.6e-5 at one pixel of 55,552 on an NVIDIA H100.
STRENGTH = 1e-4

#: The working-space textures (the same sRGB formula in float32), relative and absolute.
WORKING_SPACE = (1e-6, 1e-7)


def result_difference(actual, expected):
    """The largest difference between two results, as float64."""
    return np.abs(np.asarray(actual, np.float64) - expected).max(initial=0)


def assert_results_agree(actual, expected, message=""):
    """`actual` (GL) equals `expected` (NumPy) in dtype and shape and within :data:`RESULT`."""
    assert actual.dtype == expected.dtype and actual.shape == expected.shape, message
    difference = result_difference(actual, expected)
    assert difference <= RESULT[actual.dtype], f"{message} R differs by {difference}"


def assert_maps_agree(actual, expected, names=tuple(MAPS), message=""):
    """Each of the maps `names` of `actual` (GL) within :data:`MAPS` of `expected` (NumPy)."""
    for name in names:
        got, want = getattr(actual, name), getattr(expected, name)
        if name == "edge_strength":
            np.testing.assert_allclose(got, want, rtol=MAPS[name], atol=1e-7, err_msg=f"{message} {name}")
        else:
            np.testing.assert_allclose(got, want, rtol=0, atol=MAPS[name], err_msg=f"{message} {name}")
