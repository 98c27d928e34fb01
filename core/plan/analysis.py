"""The safe default's look at a whole pair (O, F): what to repair, where, and how strongly.

The paper's method (``mode="paper"``) harms some inputs measurably (``docs/quality.md``):
Gaussian blur, whose soft edges it re-sharpens, and natural photos under smooth filters,
whose texture the two-colour model flattens. A user cannot know which case they are in,
so ``mode="safe"`` first looks at the pair as a whole and decides. It chooses the **blend
space** first (``blend_space``: linear light or sRGB values, from which space O's edges fit
colour lines better), then takes the first of these exits that applies, each named by a
:class:`~aarecovery.backends.base.Decision`:

1. ``LOWPASS_KEPT`` (``lowpass``): F is a blur of O; F's soft edges are the filter's
   intent and F is kept.
2. ``AFFINE_KEPT`` (``linearity``): F is an affine map of O on O's edges (in the blend
   space, and for a grey O also in sRGB values); they are already right and F is kept.
3. ``POINTWISE_HARD_EDGED_COMPRESSED`` (``pointwise``, ``texture``, ``compression``):
   ``F = f(O)`` for a fitted table on hard-edged content whose O was JPEG-compressed (its
   file's tables, the block grid in its pixels, or at q 95-98, where neither shows, edge-free
   blocks flat at some phase: ``compression.hidden_compression``): the calibrated strength,
   since the compression noise goes through the filter too, and the pure colours of thin
   features only between extremes farther apart than that noise, with the table flat past
   O's range and colours whose luma is a flat colour's taken as that colour (the JPEG's
   chroma is coarser than its luma: ``pure_colours.COMPRESSED_LUMA_PURITY``).
   ``POINTWISE_HARD_EDGED_GRAINED`` (``paper_grain``): the same where O is a page with a
   coarse paper grain and no flat pixel, which goes through the filter like that noise.
4. ``POINTWISE_HARD_EDGED``: the same on uncompressed hard-edged content (a comic's
   screentone too, which the texture test reads as grain: ``hatching``): full strength
   and, for a monotone table, the pure colours of thin features (``pure_colours``).
5. ``POINTWISE_CALIBRATED``: the same on textured content (a photo): the strength that
   self-calibration at half resolution finds safe (``calibration``), in the regions that
   read as textured, and full strength in those that read as hard-edged (text, logos and
   lines drawn over the photo): the local plan (``aarecovery.spec.local_plan``), which the
   backends apply per tile; there, and not in the photo, the pure colours of thin features
   act too (``pure_colours``, gated by the local plan's weight).
6. ``NEIGHBOURHOOD_TEXTURED_KEPT``: any other filter on a textured image (but a comic's
   screentone, whose dots read as grain: ``hatching``, and a JPEG drawing whose grid the
   pixels did not show, whose ringing does: ``compression.hidden_compression``) that is not a
   colour map of all three channels at once (``colour_map``): it cannot be simulated and
   the model would flatten the texture, F is kept. ``NEIGHBOURHOOD_MIXED``
   (``mixed_content``): the same where text or drawings cover part of the photo: they are
   repaired as step 11 would (0.75 under a smoothing filter; pure colours where the filter
   keeps flat colours, in the drawn regions only), F kept in the photo (the local plan with
   a textured strength of 0, or under a sharpening filter the low strength that follows).
   ``NEIGHBOURHOOD_TEXTURED``: a grey textured image under any such filter, or a colour one
   under a sharpening filter: a low strength.
7. ``COLOUR_MAP_KEPT``: a colour map on a textured image whose repairs are no larger than
   the model's own error carried through the filter (``model_error``): F is kept.
8. ``COLOUR_MAP_CALIBRATED``: a colour map (a palette quantiser) on a textured image: the
   calibrated strength, as for a table, and full strength in the regions that read as
   hard-edged (the local plan) where that strength is in (0, 1).
9. ``NEIGHBOURHOOD_HARD_EDGED_KEPT``: a neighbourhood filter on hard-edged content whose
   repairs are no larger than the model's own error (a stricter bar for a smoothing filter on
   a compressed O): F is kept, unless a smoothing filter kept a clean O's colours, whose drawn
   edges then move towards O as in 11.
10. ``COLOUR_MAP_HARD_EDGED``: a colour map of all three channels at once (a palette
    quantiser) on hard-edged content, told from neighbourhood filters by a higher share
    (``colour_map.HARD_EDGED_COLOUR_MAP_SHARE``): full strength, or from a JPEG the
    calibrated strength; no pure colours.
11. ``NEIGHBOURHOOD_HARD_EDGED``: a neighbourhood filter on hard-edged content: the paper's
    passes at full strength (lower for a smoothing filter, and none where it left O's pixel
    as it was: ``smoothing``) and, where the
    filter keeps flat colours (sharpening, edge-aware smoothing), the pure colours of thin
    features with the identity as the table (``flat_colours``); on hatched or screentoned
    content under a smoothing filter (``hatching``) full strength in its flat regions only
    and a lower one in the hatched ones (the local plan); on a page with a coarse paper
    grain under a smoothing filter (``paper_grain``) half strength at the grain's sigma_e
    and no pure colours, under a sharpening one full strength at the grain's sigma_e in
    linear light; from a JPEG under a smoothing filter (``compression``), not
    hatched, half strength and no pure colours.

In a compressed O, texture is read in the blocks of its grid that hold no edge
(``texture``), so that compression noise is neither texture nor edge.

All of it runs once, in NumPy, on a central crop, before tiling, and results in a
:class:`PairAnalysis` that ``aarecovery.plan.make_plan`` turns into the backends' Plan.
"""

from dataclasses import dataclass, replace

from ..backends.base import Decision
from ..colour import linear_to_srgb
from ..contract import layout_of, to_rgba_float
from ..params import ITERATIONS, SIGMA_D, SIGMA_E
from ..spec.local_plan import FLAT_SPAN, SHARPENED_INK_SHARE_HIGH, SHARPENED_INK_SHARE_LOW, LocalStrength
from ..spec.sobel import gradient_magnitude
from .ahead import InOrder, analyses_ahead
from .blend_space import choose_blend_space, means_tell_srgb
from .calibration import EDGE_GRADIENT, calibrate_strength
from .colour_map import (COLOUR_MAP_SHARE, HARD_EDGED_COLOUR_MAP_SHARE, fit_colour_map, indexed_colour_fallback,
                         indexed_colour_prior)
from .compression import (COMPRESSED_HARD_EDGED_BLEND_SPACE, COMPRESSED_REPAIR_TO_ERROR, COMPRESSED_SHARPENED_BLEND_SPACE,
                          COMPRESSED_SHARPENED_STRENGTH, COMPRESSED_SMOOTHED_BLEND_SPACE, COMPRESSED_SMOOTHED_STRENGTH,
                          GRID_MARGIN, compression_evidence, hidden_compression)
from .fit_blocks import pure_colour_blocks_pay
from .flat_colours import flat_colour_prior, flat_kept_share
from .forcing import forcing_advice
from .hatching import HATCHED_SHARE, HATCHED_STRENGTH, hatched_share, is_screentone_drawing
from .linearity import AFFINE_SHARE, affine_share
from .lowpass import fit_lowpass
from .mixed_content import COMPRESSED_INK_SPAN, MIXED_DRAWN_SHARE, drawn_at, drawn_only, drawn_share
from .model_error import MIN_REPAIR_TO_ERROR, repair_to_error_ratio
from .paper_grain import (GRAINED_NEIGHBOURHOOD_STRENGTH, SHARPENED_GRAIN_BLEND_SPACE, SHARPENED_GRAIN_PURE_BLEND_SPACE,
                          grain_edge_scale, paper_grain)
from .pointwise import POINTWISE_SHARE, fit_pointwise
from .pure_colours import COMPRESSED_LUMA_PURITY, pure_colour_prior
from .ramp import ramp_table_of
from .smoothing import (BELOW_RATIO_KEPT_SHARE, SMOOTHED_CONTRAST, SMOOTHED_STRENGTH, UNTOUCHED_SPAN, contrast_ratio,
                        keeps_flat_colours)
from .texture import is_grey, is_textured

__all__ = ["PairAnalysis", "analyse", "analyse_pair", "analysis_crop"]

# Analysis works on at most this many pixels per side (a central crop): every statistic
# below is a global average that a 512 x 512 window estimates well, and it bounds the cost
# of self-calibration to a few tenths of a second. A 384 x 384 window took the plan from
# 0.27 to 0.16 s (thin bench pair) and 0.34 to 0.22 s (photo pair), but fitted the tables of
# pure colours from fewer edges: tuning half's drawings, mixed scenes and photos at 768 px
# under ten tools (240 cases, PNG and JPEG, llvmpipe), mean edge-band error reduction 0.388 ->
# 0.383, 40 plans changed, the star burst under OpenCV's gamma 3.7 dB and serif under Pillow's
# YCbCr equalize 10.9 dB worse. Not taken. Nor is a larger window simply better: the whole
# 768 x 768 image read 0.376 (the memo page up to 0.63 lower, the star burst up to 0.80 higher).
_ANALYSIS_SIDE = 512
# Strength for neighbourhood (not point-wise, not low-pass) filters on photos: the paper's
# method lost up to 3.4 dB there (unsharp mask, colour replacement) and gained at most 1 dB
# (bilateral); no strength was safe for all, so a colour photo under a smoothing filter keeps F.
_PHOTO_NEIGHBOURHOOD_STRENGTH = 0.0
# ... but a grey photo under any neighbourhood filter, and a colour one under a sharpening
# filter (F's Laplacian at O's edges at least smoothing.SMOOTHED_CONTRAST times O's), is
# repaired at a low strength, which repairs part of the filter's damage without flattening
# the texture into the model's two colours.
# A grey photo: every grey neighbourhood lies on one colour line, so the model flattens no
# colour texture there. Tuning half, the grey photos (handwriting, portrait) under GEGL's and
# ImageMagick's unsharp masks, PNG and JPEG (8 cases, kept F before), mean edge-band error
# reduction by strength: 0.25 0.26 (every case 0.10-0.52), 0.5 0.32, 0.75 0.30, 1 0.21 (the
# portrait down to 0.08). A grey image cannot tell its blend space (the model blends in
# linear light): a photo downscaled in sRGB values, as most resizers do, lost at 0.5 (the
# built-in photos in grey under the built-in unsharp mask: chelsea -1.8 to -2.1 dB, coffee
# -0.3) and gains at 0.25 (+0.5 to +1.9 dB), so the lower strength. Under smoothing filters
# the portrait lost at 1 (-0.14 to -0.19) and gains at 0.25: tuning half, the two grey photos
# under the three smoothing filters, PNG and JPEG (12 cases, F kept before), 11 up (0.03-0.27,
# up to 1.39 dB) and one down by 0.04 dB (the handwriting under OpenCV's bilateral at q 75);
# the built-in photos in grey at 64-256 px under the built-in bilateral filter, both spaces,
# +0.73 to +1.99 dB (+0.35 to +0.90 at 0.1).
_GREY_TEXTURED_STRENGTH = 0.25
# A colour photo cannot tell its blend space either (its colour lines fit both alike:
# plan/blend_space.py), and there the model in the wrong space flattens colour texture.
# Colour photos lose at 1 (tuning half: coffee -0.96 to -1.11, hubble -0.34 to -1.14); the
# built-in photos (astronaut, coffee, chelsea) at 64-256 px under the built-in unsharp mask,
# by strength 0.1 / 0.15 / 0.25, gain +0.27 to +2.01 / -0.35 to +1.77 / -2.94 to +2.14 dB:
# antialiased in linear light every strength gains, downscaled in sRGB values coffee loses
# 0.38-0.73 dB at 0.25 (its grey twin gains 0.18-0.96 there) and chelsea at 256 px 0.35 at
# 0.15. Tuning half, the 27 colour cases under those masks that kept F (photos, the poster
# and screenshot read as photos or with their photo regions kept, and JPEG drawings whose
# noise reads as grain: maps, icons, star burst, memo): by strength 0.1 / 0.15 / 0.25 every
# case gains but one at 0.25 (the icons at q 75, -0.02 dB), mean +0.81 / +0.96 / +1.10 dB.
# Chelsea downscaled in sRGB values at 384 px loses at every strength (-0.41 dB at 0.1, its
# grey twin -2.74 at 0.25), where F is within 53 dB of the reference: the filter commutes
# with a downscale in the values it works in, and leaves nothing to repair. Under smoothing
# filters colour photos lose even at 0.1 (tuning half: hubble under GEGL's hue-chroma -0.13,
# coffee under OpenCV's bilateral at q 95 -0.01) and keep F.
_SHARPENED_COLOUR_STRENGTH = 0.1
# ... but a JPEG original's colour image under a sharpening filter takes more. What bounds
# 0.1 is a lossless photo downscaled in sRGB values, whose filter leaves little to repair;
# a JPEG's grain is partly its compression noise, which the mask sharpens beside the edges
# as the reference does, and the drawings whose noise reads as grain (maps, icons, the star
# burst, memo) are no photos. Tuning half, the 19 colour JPEG cases under the two unsharp
# masks read as textured, mean edge-band error reduction by strength 0.1 / 0.25 / 0.5 / 1:
# 0.101 / 0.153 / 0.158 / 0.016 (at 0.25 every case up but the icons at q 75, 0.008 ->
# -0.005; at 0.5 the photos fall: hubble under GEGL's mask at q 98 0.213 -> 0.029, coffee
# under ImageMagick's below F).
_COMPRESSED_SHARPENED_COLOUR_STRENGTH = 0.25


def _textured_strength(grey, smoothing, compressed):
    """The strength for a textured image (or a photo's regions) under a neighbourhood filter
    that is no colour map: 0 keeps F."""
    if grey:
        return _GREY_TEXTURED_STRENGTH
    if smoothing:
        return _PHOTO_NEIGHBOURHOOD_STRENGTH
    return _COMPRESSED_SHARPENED_COLOUR_STRENGTH if compressed else _SHARPENED_COLOUR_STRENGTH


# The reasons' note of a smoothing filter's untouched edges (plan/smoothing.py).
_UNTOUCHED = ", F kept where it left O's edges as they were"
# ... and of the drawn content's edges moved towards O (Plan.toward_original).
_TOWARD = ", the drawn edges moved towards O"


@dataclass(frozen=True)
class PairAnalysis:
    """What the safe default decided for one image pair.

    Attributes
    ----------
    blend_space : {"linear", "srgb"}
    strength : float
        Multiplies the confidence ``beta``; 0 returns F unchanged, 1 is the paper's method.
    reason : str
        One line saying why, for messages and the evaluation report.
    decision : Decision
        Which exit was taken, by name.
    pure_colours : PureColourPrior or None
        For point-wise filters on hard-edged content: the filter's table and O's flat
        colours, with which the passes restore thin features.
    local : LocalStrength or None
        The local plan: `strength` is then the hard-edged regions' and ``local.textured``
        the textured regions'.
    forcing : Forcing or None
        Where F is kept: what forcing a repair would do (``aarecovery.plan.forcing``).
    edge_scale : float
        Multiplies the edge-strength scale ``sigma_e`` the passes run at: above 1 on a page
        with a coarse paper grain (``aarecovery.plan.paper_grain``), whose weak edges are grain.
    untouched_span : float
        Under a smoothing filter (``aarecovery.plan.smoothing``), the change of F from O below
        which an edge pixel gets less confidence (0 where F is O); 0: not applied.
    toward_original : bool
        Under a smoothing filter that keeps O's colours: the drawn content's edge pixels move
        towards O's (``aarecovery.plan.smoothing``, ``Plan.toward_original``).
    ramp_table : RampTable or None
        Where a point-wise table is repaired at a calibrated strength: the table the ramp
        lookup averages across O's ramps (``aarecovery.plan.ramp``); None: no ramp lookup.
    best_pair : bool
        The model's extremes from the pair of neighbours that explains a pixel best where the
        principal line misses it (``aarecovery.spec.blend_model.best_pair``): on a lossless O.
    pure_colour_blocks : bool
        With pure colours: the GL backend fits only the blocks where they can change anything
        (``aarecovery.plan.fit_blocks``, ``Plan.pure_colour_blocks``).
    """

    blend_space: str
    strength: float
    reason: str
    decision: Decision
    pure_colours: object = None
    local: object = None
    forcing: object = None
    edge_scale: float = 1.0
    untouched_span: float = 0.0
    toward_original: bool = False
    ramp_table: object = None
    best_pair: bool = False
    pure_colour_blocks: bool = False


def analysis_crop(image):
    """The central crop of at most 512 x 512 pixels that the analysis reads."""
    height, width = image.shape[:2]
    top = max(0, (height - _ANALYSIS_SIDE) // 2)
    left = max(0, (width - _ANALYSIS_SIDE) // 2)
    return image[top:top + _ANALYSIS_SIDE, left:left + _ANALYSIS_SIDE]


def analyse_pair(original, filtered, linear=False, quantization=None):
    """:func:`analyse` on a pair as the caller gave it (any layout and dtype of the contract).

    Only the crop is converted to float: a 20000 x 20000 pair would otherwise take 13 GB
    just for the conversion. `quantization`: the tables of O's JPEG file, as for :func:`analyse`.
    """
    o_crop, f_crop = analysis_crop(original), analysis_crop(filtered)
    return analyse(to_rgba_float(o_crop, layout_of(o_crop, "original"), "original"),
                   to_rgba_float(f_crop, layout_of(f_crop, "filtered"), "filtered"), linear_input=bool(linear),
                   quantization=quantization)


def analyse(original_rgba, filtered_rgba, *, linear_input=False, sigma_d=SIGMA_D.default, sigma_e=SIGMA_E.default,
            iterations=ITERATIONS.default, quantization=None):
    """Decide blend space, strength and pure colours for one pair (the safe default).

    Parameters
    ----------
    original_rgba, filtered_rgba : ndarray of float32, shape (H, W, 4)
        The pair in the core contract (straight alpha); only the central crop is read.
    linear_input : bool
        True when the colour is linear light.
    sigma_d, sigma_e, iterations
        The parameters the calibration runs at (the paper's: the analysis is a property of
        the pair, so that a slider change never re-runs it).
    quantization : sequence of sequence of int, optional
        The quantization tables of O's JPEG file (``aarecovery.io.read_quantization``); without
        them O's pixels are searched for a JPEG block grid (``aarecovery.plan.compression``).

    Returns
    -------
    PairAnalysis
        Its ``decision`` names the exit taken; the module's docstring lists them in order.
    """
    readings = []
    with analyses_ahead() as ahead:
        analysis = _decide(original_rgba, filtered_rgba, linear_input, sigma_d, sigma_e, iterations, quantization,
                           readings, ahead)
    # The best pair of neighbours (spec.blend_model.best_pair) on a lossless O only: a JPEG's
    # noise is a third colour in every neighbourhood, which the nearest pair explains. Tuning
    # half, the JPEG twins with it: 112 cases down, 80 up (the compressed drawings 0.531 ->
    # 0.527, serif in sRGB under Pillow's YCbCr equalization at q 75 0.431 -> 0.385), the
    # mean unchanged (0.3205 -> 0.3207). Nor on a textured image under a neighbourhood
    # filter, whose texture is such a third colour too: tuning half, PNG, 3 cases down and
    # none up (the space photo under GEGL's unsharp mask 0.318 -> 0.296); held out, 9 down
    # and 2 up (0.103 -> 0.091), which was seen after the choice above and decided this one.
    lossless = not any(reading.compressed for reading in readings)
    prior = analysis.pure_colours
    listed = prior is not None and (prior.drawn_only or pure_colour_blocks_pay(analysis_crop(original_rgba),
                                                                                analysis_crop(filtered_rgba)))
    return replace(analysis, best_pair=lossless and analysis.decision is not Decision.NEIGHBOURHOOD_TEXTURED,
                   pure_colour_blocks=listed)


def _decide(original_rgba, filtered_rgba, linear_input, sigma_d, sigma_e, iterations, quantization, readings, ahead):
    """:func:`analyse`'s decisions; appends each compression reading of O it takes to `readings`;
    `ahead` runs the analyses that need nothing decided before them (``plan/ahead.py``)."""
    o_rgba = analysis_crop(original_rgba)
    f_rgba = analysis_crop(filtered_rgba)
    # The remaining analysis is on sRGB-encoded colour, as filters see it.
    o = o_rgba[..., :3] if not linear_input else linear_to_srgb(o_rgba[..., :3])
    f = f_rgba[..., :3] if not linear_input else linear_to_srgb(f_rgba[..., :3])
    edges = gradient_magnitude(o) >= EDGE_GRADIENT
    # The two fits of F read only the pair: they run beside O's compression and blend space.
    lowpass_ahead = ahead.submit(fit_lowpass, o, f)
    transfer_ahead = ahead.submit(fit_pointwise, o, f, edges)
    compression = compression_evidence(o, quantization)
    readings.append(compression)
    space, residuals = choose_blend_space(o_rgba, linear_input, lossless=not compression.compressed,
                                          drawn=lambda rows, cols: drawn_at(o, rows, cols))
    fit = residuals[space]
    lowpass, kernel_residual, _ = lowpass_ahead.result()
    if lowpass:
        return PairAnalysis(space, 0.0, f"F is a low-pass (blur) of O (kernel residual {kernel_residual:.3f}): kept F",
                            Decision.LOWPASS_KEPT, forcing=forcing_advice(Decision.LOWPASS_KEPT))
    # A grey (or faintly tinted) O cannot tell its antialiasing space (blend_space falls back to linear light), so
    # an affine map of its encoded values (Pillow's autocontrast, a levels stretch) is tested
    # too: tuning half, the screentone manga under Pillow's autocontrast, affine in sRGB values
    # on 1.000 of its edges and 0.87-0.92 in linear light, lost 10.2 dB against F at the
    # calibrated strength (antialiased in sRGB) and gained 0.23 (in linear light); kept, both
    # are F.
    grey = is_grey(o)
    # Measured and not taken: a grey screentone drawing (hatching.is_screentone_drawing) blended
    # in sRGB values. Tuning half, the manga pages gained in both antialiasing spaces (74 cases,
    # 62 up, PNG +0.063, JPEG +0.056; at 768 px under eight point-wise tools 0.546 -> 0.598), but
    # grey versions of two other families under the built-in filters, as a check, lost (comic
    # strip -0.03 to -0.08, hatching -0.03 to -0.18 in linear light): the manga's own dots, not
    # screentone as such. The held-out half has no grey screentone to tell.
    affine_spaces = (space, "srgb") if space == "linear" and grey else (space,)
    if space == "srgb" and not means_tell_srgb(residuals):
        affine_spaces = (space, "linear")  # the edge pixels voted (blend_space.means_tell_srgb)
    for affine_space in affine_spaces:
        affine = affine_share(o, f, edges, affine_space)
        if affine >= AFFINE_SHARE:
            return PairAnalysis(space, 0.0, f"F is an affine map of O in {affine_space} values on {affine:.3f} of the "
                                            "edges, so its edges are already right: kept F", Decision.AFFINE_KEPT,
                                forcing=forcing_advice(Decision.AFFINE_KEPT))
    textured, texture = is_textured(o, fit, compression)
    transfer = transfer_ahead.result()
    # A comic's screentone reads as texture, but it is a drawing (plan/hatching.py): under a
    # point-wise filter it takes the hard-edged branch below, as under a neighbourhood filter.
    # Tuning half, the manga pages under the 19 point-wise tool filters: PNG 0.432 -> 0.560 of
    # the edge error (42 cases, the kept ones counted), JPEG 0.368 -> 0.506; every case up
    # (Pillow's solarize kept F at the calibrated strength 0: now 0.31-0.41) but the sRGB page
    # under Pillow's YCbCr equalization at q 85 (0.540 -> 0.457, 2.6 dB above F); no other
    # case of the half moved; drawings (target 2) 0.703 -> 0.730.
    if textured and transfer.consistency >= POINTWISE_SHARE and is_screentone_drawing(o, edges):
        textured = False
    # A JPEG drawing at q 95-98 shows no grid in its pixels, and the ringing around its edges
    # reads as grain; its edge-free blocks are flat at some phase (compression.hidden_compression),
    # a photo's are not. It is a compressed drawing: the calibrated strength and pure colours
    # above the noise of q 95's table, as where the grid was seen. Tuning half, the JPEG twins
    # under the 15 point-wise tools (96 px, both spaces), at q 98: serif 0.296 -> 0.438 of the
    # edge error, the star burst 0.218 -> 0.301, no loss against F (the suite's JPEG twins: serif
    # 0.309 -> 0.336, the star burst 0.165 -> 0.209); at full strength (as a lossless drawing)
    # serif reached 0.494 at q 98 but the star burst in sRGB under GEGL's levels at q 98 lost
    # 0.32 dB, and without COMPRESSED_LUMA_PURITY the star burst's tan paper was extended to
    # pink (up to 2.6 dB below F).
    if textured and transfer.consistency >= POINTWISE_SHARE and not compression.compressed:
        hidden = hidden_compression(o)
        readings.append(hidden)
        if hidden.compressed:
            textured, compression = False, hidden
    # Measured and not taken: a JPEG whose grain could be read only pixel by pixel (fewer than
    # 16 edge-free blocks, so compression noise is grain to the test) taken as a compressed
    # drawing. Tuning half at 96 px, the 85 cases that moved: 0.253 -> 0.284 (drawings 0.228 ->
    # 0.271, losses 2 -> 1), held out at 64 px 14 up, 2 down; but the tuning half's photo of
    # text at 64 px under GEGL's exposure (q 95) lost 5.0 dB: the pure colours of thin features,
    # which the calibration does not see, act across a photo there. Without them the moved
    # cases fell (drawings 0.242 -> 0.194, photos 0.272 -> 0.251). Nor does a grain threshold
    # scaled to the noise tell the two: at twice the noise's deviation, q 75-90, photos read
    # 0.00-0.06 grainy and drawings 0.00-0.12 (0.30 at q 95).
    if transfer.consistency >= POINTWISE_SHARE and not textured:
        # Hard-edged content: calibration would be biased here, since O is not a sharp
        # scene at twice the resolution (its edges are already blends) and box2(F) keeps
        # F's damage; measured, it chose strengths of 0.25-0.5 that lost 3-8 dB of the
        # paper's gain on synthetic scenes. Full strength is the measured best.
        # With a monotone per-channel or luma table, thin features get their pure colours:
        # quick suite 0.600 -> 0.712 (linear), 0.628 -> 0.686 (sRGB); the table's ends
        # extended by a power law: 0.774 / 0.734.
        # Neither compression noise nor a scanned page's paper grain (plan/paper_grain.py) is a
        # thin feature: pure colours only between extremes farther apart than both.
        grain = paper_grain(o, f)
        prior = pure_colour_prior(o, transfer, space, f, edges,
                                  noise_contrast=max(compression.contrast, grain.contrast),
                                  extend_ends=not compression.compressed, ridge_noise=compression.contrast,
                                  luma_purity=COMPRESSED_LUMA_PURITY if compression.compressed else 0.0)
        # Indexed colour that a table of one key explains but cannot extend (serif under
        # Pillow's quantize: its red ink and greys fit the channels' mean, no extension key):
        # the thin features take their pure colours through the 3-D table, as where no table
        # of one key explains F (colour_map.indexed_colour_prior, below). Tuning half, 3 up,
        # none down: serif 0.535 -> 0.873 and 0.387 -> 0.732, the memo at q 85 0.466 -> 0.894.
        # Held out, run after the choice: 3 up, 1 down (G'MIC's quantize on the hatched page at
        # q 75 0.321 -> 0.259; in sRGB 0.565 -> 0.921), drawings 0.745 -> 0.748.
        if prior is None:
            prior = indexed_colour_fallback(o, f, edges, max(compression.contrast, grain.contrast),
                                            COMPRESSED_LUMA_PURITY if compression.compressed else 0.0)
        thin = ", pure colours of thin features" if prior is not None else ""
        if compression.compressed or grain.coarse:
            # A JPEG's noise goes through the filter too (a levels curve doubles it): full
            # strength lost up to 2.4 dB against F on the tuning half (the star burst under
            # GEGL's levels at q 90, serif under G'MIC's pow 3 at q 75 0.9 dB); calibrated,
            # none lost, and the JPEG drawings this branch takes gained 0.59 in summed error
            # reduction over the textured (calibrated, no pure colours) reading. A coarse
            # paper grain does the same: the tuning half's grained page (notice) under
            # levels, equalization and posterize lost up to 2.0 dB at full strength (pure
            # colours above the grain), calibrated none (its mean 0.25 -> 0.58).
            # On a coarse grain the passes also run at a larger sigma_e (grain.edge_scale), so
            # that the grain's weak edges get little confidence and the bare paper stays as F
            # has it, but not above the edge strength of O's strongest edges, which a curve that
            # brings the paper toward the ink (a solarize) makes weak too (grain_edge_scale);
            # the calibration runs at the user's: at the larger scale it chose strengths that
            # lost up to 0.9 dB on the tuning half's grained page.
            # It calibrates the paper's model, not the pure colours the passes add: with them at
            # half resolution it chose higher strengths that lost (tuning half, 600 cases under
            # the 15 point-wise tools: 22 up, 64 down, the grained notice under gamma -0.36 to
            # -0.49, the memo under G'MIC's pow 3 at q 75 0.83 dB below F); only the JPEG memo
            # under autocontrast, calibrated to 0, gained (0.39).
            # On a JPEG the half-resolution calibration sees less of the noise than the passes
            # do, but a lower strength than it chose lost on average: tuning half, its JPEG
            # drawings, scans and mixed scenes repaired at a calibrated strength, 96 px (104
            # cases) 0.476, times 0.75: 0.417, times 0.5: 0.323; 768 px under the point-wise tools
            # (47 cases) 0.394 -> 0.358 and 0.288 (one case worse than F by over 0.1 dB at the
            # chosen strength, the map under Pillow's YCbCr equalize at q 90, 0.28 dB; none lower).
            # Nor a higher: the best of 0-1 in quarters was above the chosen strength in 88 of the
            # tuning half's 120 JPEG cases here, and 1.5 times it (at most 1) moved them 0.526 ->
            # 0.566 (76 up, 15 down, share of the PNG gain 0.55 -> 0.57), but held out 36 up, 25
            # down and losses 3 -> 6 (the ink drawing under Pillow's equalize at q 95 0.85 dB).
            strength, errors = calibrate_strength(o, transfer, f, space, sigma_d, sigma_e, iterations)
            if compression.compressed:
                decision, above = Decision.POINTWISE_HARD_EDGED_COMPRESSED, compression.describe()
            else:
                decision, above = Decision.POINTWISE_HARD_EDGED_GRAINED, grain.describe()
            # The repair blends a colour JPEG's edge pixels in sRGB values; the calibration and
            # the prior read O's colour lines in their own space (COMPRESSED_HARD_EDGED_BLEND_SPACE).
            in_srgb = compression.compressed and not linear_input and not grey
            repair_space = COMPRESSED_HARD_EDGED_BLEND_SPACE if in_srgb else space
            return PairAnalysis(repair_space, strength,
                                f"point-wise filter (key {transfer.key}, {transfer.consistency:.3f} of edges match) "
                                f"on hard-edged content{thin} above {above}; half-resolution "
                                f"calibration chose strength {strength:g}", decision, prior,
                                forcing=forcing_advice(decision, errors=errors) if strength == 0 else None,
                                edge_scale=grain_edge_scale(grain, o, f, edges, space, sigma_e),
                                ramp_table=ramp_table_of(transfer, prior) if strength > 0 else None)
        # Measured and not taken: a strength of ratio / 4 (at least 0.5) where the repair-to-error
        # ratio (model_error.py) is below 4. Full strength overshoots on the tuning half's sRGB
        # map under Pillow's autocontrast and OpenCV's gamma (ratios 2.6 and 2.9: 0.300 -> 0.627,
        # 0.568 -> 0.719; no other of its 183 cases here is below 5), but held out it moved only
        # colour-to-grey tools, all down (ImageMagick's -colorspace gray on hatching, pies, comic
        # strip, plots -0.08 to -0.18): their slope along O's colour line is no filter's error.
        return PairAnalysis(space, 1.0, f"point-wise filter (key {transfer.key}, {transfer.consistency:.3f} of edges "
                                        f"match) on hard-edged content: full strength{thin}",
                            Decision.POINTWISE_HARD_EDGED, prior)
    if transfer.consistency >= POINTWISE_SHARE:
        def drawn_prior():
            luma_purity = COMPRESSED_LUMA_PURITY if compression.compressed else 0.0
            prior = pure_colour_prior(o, transfer, space, f, edges, noise_contrast=compression.contrast,
                                      extend_ends=not compression.compressed, ridge_noise=compression.contrast,
                                      luma_purity=luma_purity)
            # Indexed colour as on hard-edged content (above), in the drawn regions only:
            # tuning half, the screenshot under Pillow's quantize at q 90 0.370 -> 0.422 (its
            # photo region up too); no other case moved. Held out, run after the choice: the
            # plots under G'MIC's quantize at q 98 0.322 -> 0.488, no other case moved.
            if prior is None:
                prior = indexed_colour_fallback(o, f, edges, compression.contrast, luma_purity)
            return drawn_only(prior, o, edges, ink=not grey,
                              ink_span=COMPRESSED_INK_SPAN if compression.compressed else FLAT_SPAN)

        # The pure colours below are needed only at a strength in (0, 1): beside the calibration
        # they are read while it runs (and dropped where it chose another); in order, after it.
        prior_ahead = None if isinstance(ahead, InOrder) else ahead.submit(drawn_prior)
        strength, errors = calibrate_strength(o, transfer, f, space, sigma_d, sigma_e, iterations)
        why = (f"point-wise filter (key {transfer.key}, {transfer.consistency:.3f} of edges match); "
               f"half-resolution calibration chose strength {strength:g}")
        if not 0 < strength < 1:
            return PairAnalysis(space, strength, why, Decision.POINTWISE_CALIBRATED,
                                forcing=forcing_advice(Decision.POINTWISE_CALIBRATED, errors=errors) if strength == 0
                                else None, ramp_table=ramp_table_of(transfer, None) if strength > 0 else None)
        # Where the calibration found a repair safe, the regions that read as hard-edged
        # (text over the photo) get full strength: mixed scenes' graphics 0.479 -> 0.609 of
        # their edge error removed, photo regions 0.367 -> 0.365 (tuning half). Where it
        # found none (strength 0), F is kept everywhere, as before.
        # The pure colours of thin features act there too, by the weight of the regions that
        # read as drawn (LocalStrength.region_weight: the flat share's, not the drawn ink's),
        # none in the photo. Tuning half, the mixed scenes' 26 PNG cases under point-wise
        # filters: text and graphics 0.407 -> 0.480 of their edge error removed (per case
        # -0.003 to +0.174), whole edge band 0.375 -> 0.425, photo regions 0.293 -> 0.294
        # (per case -0.0004 to +0.002); the manga pages, whose screentone reads as texture,
        # gain 0.002-0.044 in 30 cases; no other case moved by more than 0.004. Gated by the
        # whole factor (drawn ink too), text and graphics reached 0.540, but a grey photo's
        # levels recur as exactly as ink: the camera photo lost up to 0.11 (under GEGL's
        # exposure at q 98) and the text drawing, read as textured under GEGL's exposure,
        # 1.78 dB against F. Held out (not used to choose): the mixed lines did not move, as
        # the banner's and the map's overlays have almost no flat region (gate open on 3 %
        # and 0 % of their pixels).
        # On a colour image the drawn ink opens that gate too (PureColourPrior.ink_gate), where
        # a grey photo's recurring levels would: tuning half, the mixed scenes under point-wise
        # filters (26 PNG cases), text and graphics 0.482 -> 0.530, whole edge band 0.428 ->
        # 0.463, photo regions 0.297 -> 0.292 (none worse than F); every mixed case's text and
        # graphics 0.414 -> 0.446; per case -0.072 (the poster under G'MIC's pow 3) to +0.180;
        # the grey camera photo and text page (excluded) and no other case moved by over 0.01.
        # On a JPEG the drawn ink recurs within the compression noise (COMPRESSED_INK_SPAN).
        # Measured and not taken: a colour O with no compression evidence read as a q 95 JPEG
        # here (that span, q 95's noise as the prior's guards, no extrapolation, the luma
        # purity). Tuning half, 920 cases: 63 up, 2 down (the PNG mixed scenes under Pillow's
        # YCbCr equalization 0.617 -> 0.338 and 0.436 -> 0.346: a shift key's table extends
        # nothing above noise); colour photos under point-wise filters, PNG, 0.295 -> 0.310
        # (each case +0.01 to +0.07), mixed text and graphics 0.556 -> 0.577, and the maps as q 98
        # JPEGs, whose grid the 96 px windows do not show, +0.07 to +0.28. But the gate opens on
        # half the edge pixels of a photo (rocket and chelsea 0.70-0.77, the bench's photo-like
        # pair 0.49), so the pure colours' passes run over all of O's blocks: that pair's tiles
        # took 4-5 times as long (2.1 -> 8-11 s on llvmpipe), for a hundredth of the edge error.
        prior = drawn_prior() if prior_ahead is None else prior_ahead.result()
        thin = ", pure colours of thin features there" if prior is not None else ""
        return PairAnalysis(space, 1.0, why + " for textured regions, full strength for hard-edged ones" + thin,
                            Decision.POINTWISE_CALIBRATED, prior, local=LocalStrength(strength),
                            ramp_table=ramp_table_of(transfer, prior))
    # A JPEG whose grid the pixels did not show (q 90-98) reads as grain around its edges;
    # where its edge-free blocks are flat at some phase it is a drawing from a JPEG
    # (plan/compression.py): under a neighbourhood filter it goes on to the hard-edged branch
    # with that evidence. Tuning half, the five neighbourhood filters: serif (q 95-98) under
    # the unsharp masks and G'MIC's bilateral 0 -> 0.20-0.66 of its edge error, the star burst
    # (q 98) under GEGL's unsharp mask 0 -> 0.60; no other case moved. Not for point-wise
    # filters: there the star burst (q 98) under GEGL's exposure went from 0.17 to -0.30
    # (1.14 dB worse than F) at the compressed branch's calibrated strength.
    # The same where a JPEG file's tables are the evidence but the pixels did not show the
    # grid: the tables say how much noise, not where the blocks lie, and the flattest phase
    # places them. Tuning half with the tables given (eval --jpeg-tables), those serif and star
    # burst cases kept F at the grid's guessed phase; at the flattest they gain as from the
    # pixels, and no other case moved.
    phase_unknown = compression.source == "quantization tables" and compression.margin < GRID_MARGIN
    if textured and (not compression.compressed or phase_unknown):
        hidden = hidden_compression(o)
        readings.append(hidden)
        if hidden.compressed:
            compression = hidden if not compression.compressed else replace(compression, phase=hidden.phase)
            textured, texture = is_textured(o, fit, compression)
    colour_map = fit_colour_map(o, f, edges) if textured else None
    # A comic's screentone reads as texture, but it is a drawing (plan/hatching.py): under a
    # neighbourhood filter that is no colour map it goes on to the hard-edged branch below.
    if textured and colour_map.consistency < COLOUR_MAP_SHARE and is_screentone_drawing(o, edges):
        textured = False
    if textured:
        if colour_map.consistency < COLOUR_MAP_SHARE:
            # Text and drawings over the photo (plan/mixed_content.py) are repaired as a
            # drawing would be, F kept in the photo: tuning half, the mixed scenes under the
            # five neighbourhood filters, text and graphics 0 -> 0.15-0.32 of their edge
            # error removed, the photo regions -0.009 to +0.02 (within 0.04 dB of F).
            # Under a sharpening filter the photo takes the lower strength a textured image
            # takes there (below): tuning half, the poster and screenshot under the two unsharp
            # masks (PNG), 0.18-0.44 -> 0.28-0.56 of the edge error, photo regions worse than F
            # (every filter) 4 -> 2 and their mean 0.211 -> 0.244, text and graphics 0.484 -> 0.490.
            sharpening = contrast_ratio(o, f, edges)
            smoothing = sharpening < SMOOTHED_CONTRAST
            photo_strength = 0.0 if smoothing else _textured_strength(grey, False, compression.compressed)
            drawn = drawn_share(o, edges)
            if drawn >= MIXED_DRAWN_SHARE:
                ratio = _repair_to_error(o_rgba, f_rgba, linear_input, space, sigma_d, sigma_e)
                if ratio >= MIN_REPAIR_TO_ERROR:
                    strength = SMOOTHED_STRENGTH if smoothing else 1.0
                    # Where the filter keeps flat colours, thin features in the drawn regions
                    # get their pure colours (plan/flat_colours.py), by the regions' weight as
                    # for a point-wise filter: tuning half, the screenshot under the five
                    # neighbourhood filters 0.145-0.261 -> 0.162-0.437 (text and graphics
                    # +0.03 to +0.22), photo regions unchanged. Every filter's text and
                    # graphics 0.387 -> 0.402. Under a sharpening filter the colour-line miss
                    # alone decides (flat_colour_prior's `sharpened`).
                    prior, kept = flat_colour_prior(o, f, edges, sharpened=not smoothing)
                    toward = _moves_towards_original(smoothing, prior, compression, o, f)
                    # Not opened by the drawn ink: there the photo keeps F, and the extension
                    # at ink pixels moved the screenshot's photo regions under an unsharp mask
                    # (built-in filter: 0.017 -> 0.009 of their error; tuning half, the mixed
                    # scenes' neighbourhood cases -0.006 to +0.011, no gain).
                    prior = drawn_only(prior, o, edges)
                    # The strength's ink test leaves the photo's side of a stroke's edge (under
                    # 0.3 of the ink) at the photo's 0, so half of each edge keeps F's blend.
                    # Counting it from 0.1 of the ink: tuning half, the mixed scenes under the
                    # five neighbourhood filters, text and graphics 0.350 -> 0.406, photo regions
                    # 0.006 -> 0.009 (the poster's least -0.009 -> -0.016); held out, text 0.365 ->
                    # 0.371 but photo regions worse than F 3 -> 5 and the banner under
                    # ImageMagick's saturation boost (read as a smoothing filter) 0.16 dB below
                    # F: the photo's own pixels beside a stroke read as part ink. Not taken
                    # under a smoothing filter, whose photo keeps F; under a sharpening one,
                    # whose photo takes a low strength, it is (below).
                    pure = f", pure colours of thin features there ({kept})" if prior is not None else ""
                    # Under a sharpening filter the photo's side of a stroke's edge, which holds
                    # little of the ink, gets the text's strength from a tenth of it
                    # (spec.local_plan.SHARPENED_INK_SHARE_LOW has the measurements).
                    shares = {} if smoothing else {"ink_shares": (SHARPENED_INK_SHARE_LOW, SHARPENED_INK_SHARE_HIGH)}
                    local = LocalStrength(photo_strength, **shares)
                    return PairAnalysis(space, strength,
                                        f"neighbourhood filter on a textured image ({texture}) with text or drawings "
                                        f"over it ({drawn:.2f} of the edges): strength {strength:g} there{pure}, "
                                        + (f"strength {photo_strength:g} in the rest" if photo_strength else "F kept in the rest")
                                        + (_UNTOUCHED if smoothing else "")
                                        + (_TOWARD if toward else ""),
                                        Decision.NEIGHBOURHOOD_MIXED, prior, local=local,
                                        untouched_span=UNTOUCHED_SPAN if smoothing else 0.0,
                                        toward_original=toward)
            strength = _textured_strength(grey, smoothing, compression.compressed)
            if strength > 0:
                return PairAnalysis(space, strength,
                                    f"{'smoothing' if smoothing else 'sharpening'} filter on a "
                                    f"{'grey ' if grey else ''}textured image ({texture}; F's edge contrast "
                                    f"{sharpening:.2f} times O's): strength {strength:g}"
                                    + (f" above {compression.describe()}"
                                       if strength == _COMPRESSED_SHARPENED_COLOUR_STRENGTH and not grey else ""),
                                    Decision.NEIGHBOURHOOD_TEXTURED)
            return PairAnalysis(space, strength,
                                f"neighbourhood filter on a textured image ({texture}): "
                                f"strength {strength:g}", Decision.NEIGHBOURHOOD_TEXTURED_KEPT,
                                forcing=forcing_advice(Decision.NEIGHBOURHOOD_TEXTURED_KEPT))
        # A colour map that bends colours smoothly (a hue change) leaves repairs no larger
        # than the model's error; calibration alone chose 0.5 there and lost 0.73 dB (GEGL's
        # hue-chroma on maps, quick tuning half: ratio 1.18); the held-out quantised photos
        # score 17-75.
        ratio = _repair_to_error(o_rgba, f_rgba, linear_input, space, sigma_d, sigma_e)
        if ratio < MIN_REPAIR_TO_ERROR:
            return PairAnalysis(space, 0.0, f"point-wise colour map ({colour_map.consistency:.3f} of edges match) on "
                                            f"a textured image, but the repairs would be no larger than the model's "
                                            f"own error (ratio {ratio:.2f} < {MIN_REPAIR_TO_ERROR:g}): kept F",
                                Decision.COLOUR_MAP_KEPT, forcing=forcing_advice(Decision.COLOUR_MAP_KEPT, ratio))
        strength, errors = calibrate_strength(o, colour_map, f, space, sigma_d, sigma_e, iterations)
        why = (f"point-wise colour map ({colour_map.consistency:.3f} of edges match, repair-to-error "
               f"ratio {ratio:.1f}); half-resolution calibration chose strength {strength:g}")
        # As for a table (above), the regions that read as hard-edged get full strength where
        # the calibration found a repair safe: tuning half, the poster in linear light under
        # Pillow's quantize 0.398 -> 0.466 (text and graphics 0.427 -> 0.530, photo regions
        # 0.338 -> 0.336); four more cases within 0.003, none down by more than 0.001.
        if 0 < strength < 1:
            return PairAnalysis(space, 1.0, why + " for textured regions, full strength for hard-edged ones",
                                Decision.COLOUR_MAP_CALIBRATED, local=LocalStrength(strength))
        return PairAnalysis(space, strength, why,
                            Decision.COLOUR_MAP_CALIBRATED,
                            forcing=forcing_advice(Decision.COLOUR_MAP_CALIBRATED, errors=errors) if strength == 0
                            else None)
    ratio = _repair_to_error(o_rgba, f_rgba, linear_input, space, sigma_d, sigma_e)
    # A smoothing filter averages part of an edge's damage away, as the reference does
    # (plan/smoothing.py); on compressed content it needs a larger ratio than a sharpening
    # one (see COMPRESSED_REPAIR_TO_ERROR).
    smoothing = contrast_ratio(o, f, edges) < SMOOTHED_CONTRAST
    needed = COMPRESSED_REPAIR_TO_ERROR if compression.compressed and smoothing else MIN_REPAIR_TO_ERROR
    # Below the ratio the model's repairs are no larger than its error, but where a smoothing
    # filter keeps a clean O's colours as they were (BELOW_RATIO_KEPT_SHARE) the drawn edges
    # move towards O (below), which needs no model. Tuning half, the map in sRGB under
    # OpenCV's bilateral filter (ratio 1.91): 0 -> 0.955 of its edge error; no other case of
    # either half moved.
    below = ratio < needed
    if below and not _moves_towards_original_below_the_ratio(smoothing, compression, o, f, edges):
        return PairAnalysis(space, 0.0, f"neighbourhood filter on hard-edged content, but the repairs would be "
                                        f"no larger than the model's own error (ratio {ratio:.2f} < "
                                        f"{needed:g}" + (f" above {compression.describe()}" if compression.compressed
                                                         else "") + "): kept F", Decision.NEIGHBOURHOOD_HARD_EDGED_KEPT,
                            forcing=forcing_advice(Decision.NEIGHBOURHOOD_HARD_EDGED_KEPT, ratio))
    # A palette quantiser (indexed colour without dithering: Pillow's quantize, G'MIC's
    # -quantize, GIMP's Image > Mode > Indexed) maps each whole colour to its nearest palette
    # entry: point-wise, though no table of one key explains it on a colour drawing. Taken for
    # a neighbourhood filter, its flat palette colours read as a smoothing filter that keeps
    # flat colours (identity pure colours, strength 0.75, F kept where it left O's pixel):
    # tuning half, the map under Pillow's quantize lost 0.66 dB against F (linear light) and
    # kept 0.08 of its error (sRGB), where the paper's passes at full strength remove 0.455
    # and 0.365. The 3-D table (plan/colour_map.py) tells it from the neighbourhood filters at
    # a higher share than on a photo (HARD_EDGED_COLOUR_MAP_SHARE): full strength, or on a
    # JPEG the strength calibrated with that table. Where F is indexed colour, thin features
    # get pure colours through that table (colour_map.indexed_colour_prior): tuning half, the
    # map under Pillow's quantize 0.455 -> 0.777 and 0.365 -> 0.775 of its edge error, the
    # icons 0.976-0.982 -> 0.989-0.992; no other case moved. On a JPEG above its noise, as
    # for a table of one key: serif at q 98 (linear light) 0.405 -> 0.643, the one JPEG case
    # of the tuning half that reads as a hard-edged colour map.
    colour_map = fit_colour_map(o, f, edges)
    if colour_map.consistency >= HARD_EDGED_COLOUR_MAP_SHARE and not below:
        why = (f"point-wise colour map ({colour_map.consistency:.3f} of edges match, repair-to-error ratio "
               f"{ratio:.1f}) on hard-edged content")
        if compression.compressed:
            strength, errors = calibrate_strength(o, colour_map, f, space, sigma_d, sigma_e, iterations)
            prior = indexed_colour_prior(o, f, colour_map, compression.contrast, COMPRESSED_LUMA_PURITY)
            thin = ", pure colours of thin features" if prior is not None and strength > 0 else ""
            return PairAnalysis(space, strength, why + thin + f" above {compression.describe()}; half-resolution "
                                                              f"calibration chose strength {strength:g}",
                                Decision.COLOUR_MAP_HARD_EDGED, prior if strength > 0 else None,
                                forcing=forcing_advice(Decision.COLOUR_MAP_HARD_EDGED, errors=errors) if strength == 0
                                else None)
        prior = indexed_colour_prior(o, f, colour_map)
        thin = ", pure colours of thin features" if prior is not None else ""
        return PairAnalysis(space, 1.0, why + ": full strength" + thin, Decision.COLOUR_MAP_HARD_EDGED, prior)
    # A smoothing filter also leaves some edges as O had them (a bilateral filter's strong
    # edges), and so does the reference: there the confidence falls to 0 (UNTOUCHED_SPAN, in
    # the model's pass).
    untouched = dict(untouched_span=UNTOUCHED_SPAN if smoothing else 0.0)
    # On a page with a coarse paper grain (plan/paper_grain.py) it spreads the grain as it
    # spreads a JPEG's noise, so the repair runs at the grain's sigma_e, at a lower strength
    # and without pure colours. Tuning half, notice under the three tuning smoothing filters
    # (PNG and JPEG): full strength lost up to 1.51 dB; at the grain's sigma_e and strength
    # 0.5 no case lost (see GRAINED_NEIGHBOURHOOD_STRENGTH). Sharpening filters (unsharp
    # masks) keep full strength: at 0.5 the coarse page's gain fell from 0.45-0.52 to 0.21-0.23.
    grain = paper_grain(o)
    if smoothing and grain.coarse:
        return PairAnalysis(space, GRAINED_NEIGHBOURHOOD_STRENGTH,
                            f"neighbourhood filter on hard-edged content (repair-to-error ratio {ratio:.1f}) that "
                            f"smooths {grain.describe()}: strength {GRAINED_NEIGHBOURHOOD_STRENGTH:g}" + _UNTOUCHED,
                            Decision.NEIGHBOURHOOD_HARD_EDGED, edge_scale=grain.edge_scale, **untouched)
    # Filters that keep flat colours (sharpening, edge-aware smoothing): thin features get
    # their pure colours with the identity as the table (plan/flat_colours.py).
    prior, kept = flat_colour_prior(o, f, edges, grain)
    # A smoothing filter smoothed the paper's grain away: a thin feature must stand out from
    # the grain, or a dip of the grain beside a letter takes the ink's colour on F's flat
    # paper. Tuning half, the three smoothing filters (memo, notice, every family, PNG and
    # JPEG): 6 cases up by 0.001-0.007, none down; F's flat paper made darker than F 19 -> 0
    # pixels, anywhere on the paper 269 -> 3. Under the unsharp masks, whose reference keeps
    # the sharpened grain, the same test (and the compression's noise on a JPEG) lost up to
    # 0.42 of the edge error (notice at q 75 under GEGL's mask): not there.
    if prior is not None and smoothing:
        prior = replace(prior, noise_contrast=float(grain.contrast))
    pure = f", pure colours of thin features ({kept})" if prior is not None else ""
    why = (f"neighbourhood filter on hard-edged content (repair-to-error ratio {ratio:.1f}"
           + (f" < {needed:g}" if below else "") + ")")
    # Where it keeps O's colours (the prior: its flat areas and colour lines; every flat pixel)
    # in a clean O (not a JPEG's, whose noise the filter smoothed away), the drawn content's
    # edges move towards O (plan/smoothing.py).
    untouched["toward_original"] = _moves_towards_original(smoothing, prior, compression, o, f)
    # Hatching and screentone are texture to a smoothing filter, not edges to blend
    # (plan/hatching.py): on a hatched O the flat regions are repaired at full strength, the
    # hatched ones at a lower one (the local plan).
    hatched = hatched_share(o, edges)
    if smoothing and hatched >= HATCHED_SHARE:
        return PairAnalysis(space, 1.0, why + f": full strength in flat regions, {HATCHED_STRENGTH:g} in the "
                                              f"hatching or screentone around {hatched:.2f} of the edges" + pure
                            + _UNTOUCHED + (_TOWARD if untouched["toward_original"] else ""),
                            Decision.NEIGHBOURHOOD_HARD_EDGED, prior,
                            local=LocalStrength(HATCHED_STRENGTH, "hatching and screentone", drawn_ink=False),
                            **untouched)
    # A JPEG's noise goes through a smoothing filter too, spread over the edges: the repair
    # at a lower strength, without pure colours (see COMPRESSED_SMOOTHED_STRENGTH).
    if smoothing and compression.compressed:
        # ... blended in sRGB values on colour (COMPRESSED_SMOOTHED_BLEND_SPACE).
        smoothed_space = COMPRESSED_SMOOTHED_BLEND_SPACE if not linear_input and not grey else space
        return PairAnalysis(smoothed_space, COMPRESSED_SMOOTHED_STRENGTH,
                            why + f": a smoothing filter above {compression.describe()}, strength "
                                  f"{COMPRESSED_SMOOTHED_STRENGTH:g}" + _UNTOUCHED, Decision.NEIGHBOURHOOD_HARD_EDGED,
                            **untouched)
    # Only a filter that keeps O's flat colours and colour lines (the prior) is smoothing
    # edges: a conversion to grey lowers the luma contrast too (GIMP's desaturate).
    # Measured and not taken: blending in sRGB values under a smoothing filter, which averages
    # values in its own space. OpenCV's and G'MIC's average encoded values: tuning half, the
    # colour drawings antialiased in linear light 0.699 -> 0.740 (16 up, 4 down; the map under
    # OpenCV's smoothing 0.288 -> 0.544), the grey manga 10 of 12 cases up (0.733 -> 0.892),
    # grey renderings of the four colour drawings 17 of 24 up (mean +0.035). But the built-in
    # bilateral grid lost on colour (random shapes 0.729 -> 0.415), and on grey renderings of
    # the held-out drawings (seen after the choice for grey content, which the held-out half
    # itself does not hold) GEGL's bilateral filter, which averages in linear light, lost up to
    # 0.64 (the ink drawing 0.991 -> 0.352) where OpenCV's edge-preserving filter gained up to
    # 0.33; F's edges do not tell the filter's space (their colour lines read linear light under
    # every one of these filters, as O's do).
    if smoothing and prior is not None:
        return PairAnalysis(space, SMOOTHED_STRENGTH, why + f": a smoothing filter, strength {SMOOTHED_STRENGTH:g}"
                            + pure + _UNTOUCHED + (_TOWARD if untouched["toward_original"] else ""),
                            Decision.NEIGHBOURHOOD_HARD_EDGED, prior, **untouched)
    # A sharpening filter on a coarse grain sharpens the grain too: the passes run at the
    # grain's sigma_e, so that the bare paper keeps it, blended in linear light
    # (SHARPENED_GRAIN_BLEND_SPACE says why), or in sRGB values where the strokes have their
    # pure colours (SHARPENED_GRAIN_PURE_BLEND_SPACE).
    if grain.coarse:
        # The blend space is named by the summary line (a user's --blend-space overrides it).
        space = SHARPENED_GRAIN_BLEND_SPACE if prior is None else SHARPENED_GRAIN_PURE_BLEND_SPACE
        return PairAnalysis(space, 1.0, why + f" that sharpens {grain.describe()}: full "
                                                               "strength at the grain's edge scale" + pure,
                            Decision.NEIGHBOURHOOD_HARD_EDGED, prior, edge_scale=grain.edge_scale)
    # On a JPEG a sharpening filter blends in sRGB values (see COMPRESSED_SHARPENED_BLEND_SPACE).
    if compression.compressed and not smoothing and not linear_input:
        space = COMPRESSED_SHARPENED_BLEND_SPACE
    # A sharpening filter sharpens a JPEG's ringing beside the edges too; where the repairs are
    # not clearly larger than the model's own error (below the bar a smoothing filter needs),
    # the repair runs at a lower strength (see COMPRESSED_SHARPENED_STRENGTH).
    if compression.compressed and ratio < COMPRESSED_REPAIR_TO_ERROR:
        return PairAnalysis(space, COMPRESSED_SHARPENED_STRENGTH,
                            why + f": a sharpening filter above {compression.describe()}, ratio below "
                                  f"{COMPRESSED_REPAIR_TO_ERROR:g}: strength {COMPRESSED_SHARPENED_STRENGTH:g}" + pure,
                            Decision.NEIGHBOURHOOD_HARD_EDGED, prior)
    return PairAnalysis(space, 1.0, why + ": full strength" + pure, Decision.NEIGHBOURHOOD_HARD_EDGED, prior)


def _moves_towards_original(smoothing, flat_prior, compression, o, f):
    """Whether a smoothing filter's drawn edges move towards O (``Plan.toward_original``): F
    keeps O's colours (the flat-colour prior exists and no flat pixel moved by more than
    ``smoothing.FLAT_COLOUR_MOVE``) and O is not compressed."""
    return bool(smoothing and flat_prior is not None and not compression.compressed and keeps_flat_colours(o, f))


def _moves_towards_original_below_the_ratio(smoothing, compression, o, f, edges):
    """:func:`_moves_towards_original` as the exits after the repair-to-error ratio decide it
    (not on a coarse paper grain, whose smoothing takes its own exit without the move), and F
    keeps O's flat colours as they were (``smoothing.BELOW_RATIO_KEPT_SHARE``)."""
    if not smoothing or compression.compressed or flat_kept_share(o, f) < BELOW_RATIO_KEPT_SHARE:
        return False
    grain = paper_grain(o)
    if grain.coarse:
        return False
    return _moves_towards_original(smoothing, flat_colour_prior(o, f, edges, grain)[0], compression, o, f)


def _repair_to_error(o_rgba, f_rgba, linear_input, space, sigma_d, sigma_e):
    return repair_to_error_ratio(o_rgba, f_rgba, linear_input=linear_input, blend_space=space, sigma_d=sigma_d,
                                 sigma_e=sigma_e)
