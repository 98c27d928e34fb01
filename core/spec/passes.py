"""The recovery passes in pipeline order: the NumPy specification the GL backend follows.

Each function is one pass, and the GL backend has a shader pass of the same name
(``backends/gl/shaders/<name>.frag``) that ``tests/test_gl_parity.py`` compares with it:

1. :func:`to_working_space`: O and F into premultiplied RGBA in the blend space.
2. :func:`fit_blend_model`: the two-colour model of O and its confidence at every pixel
   (the paper's, or with the safe default's pure colours of thin features).
3. :func:`jacobi_step`, ``iterations`` times, starting from R = F.
4. :func:`from_working_space`: back to straight RGBA in the input's encoding.

:func:`recover_working` runs steps 2 and 3; it is the one place the Jacobi loop is written.
"""

import numpy as np

from .blend_model import fit_paper_model, toward_original, untouched_factor
from .jacobi import jacobi_step
from .pure_colours import fit_pure_colour_model
from .working_space import from_working_space, to_working_space

__all__ = ["to_working_space", "fit_blend_model", "jacobi_step", "from_working_space", "recover_working"]


def fit_blend_model(original, filtered, sigma_d, sigma_e, strength=1.0, prior=None, blend_space="linear",
                    factor=None, untouched_span=0.0, gate=None, toward=None, best_pair=False):
    """Fit the two-colour blend model at every pixel of O (section 3.1) and its confidence.

    The GL pass of this name also writes the first Jacobi iterate, which it can form from
    the F texels it already fetched for Sobel; its twin here is ``jacobi_step(F, F, model)``.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 4)
        O and F in the working space.
    sigma_d, sigma_e : float
        The model's colour-line and edge scales (``aarecovery.params``).
    strength : float
        Multiplies the confidence ``beta``: the safe default's per-image repair strength;
        1 is the paper's method and leaves ``beta`` bit-identical.
    prior : PureColourPrior, optional
        The safe default's pure colours of thin features, for point-wise filters on
        hard-edged content (``aarecovery.spec.pure_colours``); None is the paper's method.
    blend_space : {"linear", "srgb"}
        The working space's colour space, needed only with `prior` (its table is on
        sRGB-encoded values).
    factor : ndarray of float32, shape (H, W), optional
        The local plan's per-pixel factor of ``beta`` (``aarecovery.spec.local_plan``),
        applied after `strength`; None leaves ``beta`` as it is.
    untouched_span : float
        Above 0, ``beta`` is multiplied last by
        :func:`~aarecovery.spec.blend_model.untouched_factor` (a smoothing filter's untouched
        edges, ``aarecovery.plan.smoothing``); 0 leaves it as it is.
    gate : ndarray of float32, shape (H, W), optional
        Where a `prior` that acts on drawn content only acts, from 0 to 1: the local plan's
        weight of the drawn regions (``LocalStrength.region_weight``).
    toward : ndarray of float32, shape (H, W), optional
        A smoothing filter's weight of O's own colour in the Jacobi steps, applied last
        (:func:`~aarecovery.spec.blend_model.toward_original`; the local plan's regions'
        weight); None: none.
    best_pair : bool
        Where the principal line misses the centre, the pair of neighbours that explains it
        best (:func:`~aarecovery.spec.blend_model.best_pair`; ``Plan.best_pair``); False is the
        paper's model.

    Returns
    -------
    BlendModel
    """
    if prior is None:
        model = fit_paper_model(original, filtered, sigma_d, sigma_e, strength, best=best_pair)
    else:
        model = fit_pure_colour_model(original, filtered, sigma_d, sigma_e, strength, prior, blend_space, gate,
                                      best=best_pair)
    if factor is not None:
        model.beta = (model.beta * factor).astype(np.float32)
    if untouched_span > 0:
        model.beta = (model.beta * untouched_factor(original, filtered, model.index_a, model.index_b,
                                                    untouched_span)).astype(np.float32)
    if toward is not None:
        toward_original(model, original, filtered, toward)
    return model


def recover_working(original, filtered, sigma_d, sigma_e, iterations, strength=1.0, prior=None,
                    blend_space="linear", factor=None, untouched_span=0.0, gate=None, model=None, toward=None,
                    best_pair=False):
    """Fit the model and run the Jacobi iterations on working-space images.

    Parameters are those of :func:`fit_blend_model`, `iterations` (0 returns F) and `model`,
    the model :func:`fit_blend_model` gives for them when the caller already has it (then
    not fitted again).

    Returns
    -------
    recovered : ndarray of float32, shape (H, W, 4)
    model : BlendModel
    """
    if model is None:
        model = fit_blend_model(original, filtered, sigma_d, sigma_e, strength, prior, blend_space, factor,
                                untouched_span, gate, toward, best_pair)
    recovered = filtered
    for _ in range(iterations):
        recovered = jacobi_step(recovered, filtered, model)
    return recovered, model
