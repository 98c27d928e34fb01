"""The local plan: how strongly to repair each region of O, from how much of it is flat.

One image can hold both kinds of content: text, logos and lines drawn over a photo. For a
point-wise filter the safe default repairs hard-edged content at full strength and photos at
the strength self-calibration finds (``aarecovery.plan.calibration``); the local plan
decides that per region. Its evidence is **flatness**: rendered content (text, drawings,
user-interface chrome) is made of areas of one exact colour, so most 3 x 3 neighbourhoods
around its edges are flat to the 8-bit level; a photo's sensor noise and texture leave
almost none. Measured on mixed scenes (``aarecovery.lab.mixed_probe``, tuning half): the
edge pixels of the drawn graphics had a median flat share of 0.04-0.10 in the 17 x 17 square
around them (a tenth of them 0.35-0.39), the photos' edge pixels 0.00-0.02 (99th percentile
0.07-0.24). A JPEG source has no exactly flat pixels: it reads as a photo everywhere, as the
whole-image decision reads it; only the gate of pure colours reads its drawn ink within a
wider span (:func:`ink_weight`'s `span`, ``PureColourPrior.ink_span``), and by its luma
where the ink is neither saturated nor dark (:data:`INK_LUMA_SATURATION`).

Per pixel, in passes that read only :data:`REACH` pixels around it, so that a tile with that
much more halo gives the untiled result (the GL twin, ``backends/gl/shaders/local_plan.glsl``,
runs the same passes on each tile: 1, 2 and the sums of 3 along rows, then along columns):

1. :func:`flat_pixels`: where O's 3 x 3 neighbourhood spans at most half an 8-bit level
   in every channel and is not black.
2. :func:`flat_share`: the share of flat pixels in the square of radius
   :data:`REGION_RADIUS` (the image's outside counts as not there).
3. :func:`hard_edged_weight`: 0 below a share of :data:`TEXTURED_SHARE`, 1 above
   :data:`HARD_EDGED_SHARE`, a smoothstep between: box sums change by at most one pixel's
   worth from one pixel to the next, so the weight has no step and R no seam where the
   decision changes.
4. :func:`ink_weight`: per pixel, how much drawn ink it holds (below; the GL twin computes
   it in pass 3, from O).
5. :meth:`LocalStrength.factor`: the factor of the confidence ``beta``, from the textured
   strength (photo regions) to 1 (hard-edged regions or drawn ink), by the larger weight.
6. Under a smoothing filter over a photo, :meth:`LocalStrength.kept_ink`: the drawn ink's
   weight towards O, by how fully F kept O's contrast there, and every pixel's by how far F
   steepened it (:func:`kept_contrast`; the GL twin's pass 3 reads F too and writes it in a
   third channel).

Thresholds chosen on the tuning half of the mixed scenes (shares 0.05-0.25, 0.1-0.3 and
0.15-0.35, radii 6, 8 and 16: graphics 0.596-0.609, photo 0.360-0.367 of the edge error
removed, against 0.479 and 0.367 for one strength per image).

Flatness misses captions and lines drawn straight on the photo: their strokes are a pixel or
two wide, with no flat 3 x 3 neighbourhood in them. The second evidence, :func:`ink_weight`,
is per pixel: **drawn ink repeats exactly**. An edge pixel's two extremes (the brightest and
darkest of its 3 x 3 neighbourhood) are, on a stroke, the ink and the background; the ink's
colour recurs to the 8-bit level in the pixels the stroke covers fully, and colours a few
levels from it are rare (a stroke's blends are far from its ink), where a photo's colours
recur, if at all, among neighbours a level or two apart. Where an extreme recurs
:data:`INK_REPEATS` times in the 7 x 7 square and at most half as many pixels lie within
:data:`INK_NEAR_SPAN` of it, the pixel gets full strength in proportion to how much of that
ink it holds (its place between the two extremes), so that the photo pixel beside a stroke,
which holds none, keeps the calibrated strength. Near-black ink is no evidence, as for
flatness (a camera's clipped shadows: the tuning half's grey photo under G'MIC's pow 3 lost
0.44 of its photo region's error when it counted). Tuning half, PNG, the 27 mixed cases
that take the local plan: text and graphics 0.360 -> 0.409 of their edge error removed, the
whole edge band 0.339 -> 0.372, the photo regions 0.294 -> 0.287; full strength on exactly
the overlay's pixels (an oracle) reaches 0.434 and 0.399. The rest of the 0.9 target is not
a question of strength: thin features' pure colours on the same oracle reach 0.606. So the
pure colours act over a photo too, where this plan reads drawn content: the extension goes
the share of the way that the regions' weight (:meth:`LocalStrength.region_weight`) says,
on a colour image the larger of it and the drawn ink (:meth:`LocalStrength.gate`), none in
the photo (measured in ``aarecovery.plan.analysis``).
"""

from dataclasses import dataclass

import numpy as np

from ..colour import LUMA_WEIGHTS, linear_to_srgb

__all__ = ["LocalStrength", "encoded_colour", "strength_map", "neighbourhood_extremes", "flat_pixels", "flat_share",
           "hard_edged_weight",
           "ink_weight", "ink_weight_at", "REACH", "REGION_RADIUS", "TEXTURED_SHARE", "HARD_EDGED_SHARE", "INK_RADIUS",
           "INK_REPEATS",
           "INK_NEAR_SPAN", "INK_DARK", "INK_TIE", "INK_SHARE_LOW", "INK_SHARE_HIGH", "INK_GATE_SHARE_LOW",
           "INK_GATE_SHARE_HIGH", "INK_GATE_REPEATS", "SHARPENED_INK_SHARE_LOW", "SHARPENED_INK_SHARE_HIGH",
           "INK_LUMA_SATURATION", "INK_LUMA_DARK", "kept_contrast", "KEPT_CONTRAST_LOW", "KEPT_CONTRAST_HIGH",
           "STEEPENED_CONTRAST_HIGH"]

#: A pixel is flat when its 3 x 3 neighbourhood spans at most this in every channel: equal
#: 8-bit values (the 8-bit grid is 1/255 apart).
FLAT_SPAN = 0.5 / 255
#: Radius of the square whose flat share decides a region: 17 x 17 pixels.
REGION_RADIUS = 8
#: Flat shares at and below which a region is textured, and at and above which it is
#: hard-edged.
TEXTURED_SHARE = 0.1
HARD_EDGED_SHARE = 0.3
#: Drawn ink: the radius of the square in which an extreme's colour must recur (7 x 7), the
#: recurrences it needs (equal 8-bit values, within FLAT_SPAN: the extreme itself counts),
#: and the span within which a photo's neighbouring levels lie (fewer than half as many
#: pixels there as recurrences).
INK_RADIUS = 3
# Two for the strength too (the gate takes two, INK_GATE_REPEATS) lifted the mixed scenes'
# text further (tuning 0.530 -> 0.560, with both at two) but gave photos full strength:
# held out, photo regions worse than F 3 -> 6 (docs/safe-default.md).
INK_REPEATS = 3
INK_NEAR_SPAN = 3.5 / 255
#: Ink whose brightest channel is at most this is no evidence (a camera's clipped shadows).
#: Half a level above 5, so that no 8-bit colour ties with it: GPUs convert 8-bit texels to
#: floats differently in the last bit (see INK_TIE), and a tie would decide there.
INK_DARK = 5.5 / 255
#: Two colours of a 3 x 3 neighbourhood whose channel sums differ by at most this are equally
#: bright (or dark): the first in row order is the extreme. A quarter of an 8-bit level, so
#: that 8-bit colours with equal sums, (233, 231, 236) and (233, 230, 237), tie whatever the
#: rounding of their float sums: decided by the last bit, NumPy (u8 / 255) and an NVIDIA H100
#: (its unorm conversion) took different extremes, and the factor differed by 0.0026 (a
#: photo's pixel beside posterized bars, measured).
INK_TIE = 0.25 / 255
#: The pixel's share of the ink (its place from the other extreme, 0, to the ink, 1) from
#: which the weight rises, and at which it is full: a smoothstep between.
INK_SHARE_LOW = 0.3
INK_SHARE_HIGH = 0.7
#: The strength's shares under a sharpening filter over a photo (``neighbourhood-mixed``,
#: whose photo keeps the low strength of a sharpened photo): the photo's side of a stroke's
#: edge holds little of the ink, and from 0.3 it kept that strength, half of each of the
#: poster's text edges. Tuning half, the poster and screenshot under the two unsharp masks
#: (8 PNG cases), text and graphics by lows and highs 0.3 / 0.7 (the strength's), 0.2 / 0.6,
#: 0.1 / 0.7, 0.1 / 0.5, 0.0 / 0.4: 0.505, 0.522, 0.528, 0.543, 0.562; photo regions 0.206,
#: 0.209, 0.211, 0.209, 0.205 (a poster's photo region at most 0.001, 0.001, 0.005, 0.012
#: below the strength's). A smoothing filter's photo keeps F: there a low of 0.1 put
#: held-out photo regions below F (``plan.analysis``).
SHARPENED_INK_SHARE_LOW = 0.1
SHARPENED_INK_SHARE_HIGH = 0.5
#: The same for the gate of pure colours on drawn content (``LocalStrength.gate``): it opens
#: at any share of the ink, full from a third. The strength keeps the photo pixel beside a
#: stroke at the calibrated factor; the gate lets that pixel's ink extreme, the stroke's
#: partial colour, take its pure colour. Tuning half, the mixed scenes under point-wise
#: filters (30 PNG cases): text and graphics 0.530 -> 0.542, whole edge band 0.465 ->
#: 0.473, photo regions 0.287 -> 0.284 (none worse than F); 0.1 / 0.5: 0.536, 0.470, 0.286.
INK_GATE_SHARE_LOW = 0.0
INK_GATE_SHARE_HIGH = 0.3
#: The recurrences the gate's ink needs (the strength's: INK_REPEATS). Two for the gate alone,
#: tuning half, the mixed scenes under point-wise filters (26 PNG cases the evaluation
#: counts): text and graphics 0.541 -> 0.550, whole edge band 0.470 -> 0.474, photo regions
#: 0.288 -> 0.282, none worse than F; held out 0.522 -> 0.526, photo regions worse than F
#: unchanged (two for the strength too made them 3 -> 6).
INK_GATE_REPEATS = 2
#: Where the ink's span is wider than :data:`FLAT_SPAN` (a JPEG's, ``PureColourPrior.ink_span``)
#: the ink recurs by its luma (Rec. 709 weights on encoded values): JPEG keeps chroma at half
#: resolution and quantizes it coarser, so a stroke's colour scatters in chroma where its luma
#: holds. Not for ink whose channels span more than INK_LUMA_SATURATION (a saturated red or
#: teal icon, whose JPEG noise F's threshold turned into specks: the icons under GEGL's
#: threshold at q 90 lost 0.21 dB against F when their fills counted as ink), nor for ink whose
#: brightest channel is below INK_LUMA_DARK (a space photo's dark sky, whose grain is finer in
#: luma than the span: 0.14 dB lost under Pillow's autocontrast at q 98); both recur by colour.
#: Tuning half, JPEG originals (q 75-98) under the 15 point-wise filters (150 cases): the mixed
#: scenes' text and graphics 0.285 -> 0.310 of their edge error removed, maps 0.206 -> 0.247,
#: screenshots 0.296 -> 0.313, photo regions 0.222 -> 0.221; 64 cases up, 5 down (at most
#: 0.009; the space photo -0.02 -> -0.05 dB against F, no new case below F by 0.1 dB). Every
#: extreme by luma: 0.311 with those two losses; saturation limit 50 levels: 0.309; dark limit
#: 15.5 levels: 0.311 but the space photo -0.08 dB; 47.5: 0.309. Half levels, so that 8-bit
#: colours never tie with them.
INK_LUMA_SATURATION = 90.5 / 255
INK_LUMA_DARK = 31.5 / 255
# Luma distances of 8-bit colours lie on a 1/10000-level grid (the weights' four decimals) on
# which the spans sit: (18, 4, -58) levels apart is exactly 2.5 levels of luma. Counted a
# twenty-thousandth of a level closer, so that rounding decides no test, the same in GL.
_LUMA_TIE = 0.00005 / 255
#: Where F kept an edge's contrast, the drawn ink moves towards O under a smoothing filter even
#: where the pure colours' gate leaves it out (:meth:`LocalStrength.kept_ink`): F's 3 x 3 span
#: over O's (largest channel, encoded values), from which its weight rises and at which it is
#: full, a smoothstep between. A bilateral or edge-preserving filter keeps a strong edge's
#: contrast (text over a photo) and flattens a weak one's (the photo's texture), whose
#: reference keeps F's smoothness. Tuning half, the mixed scenes under the three smoothing
#: filters (6 PNG cases): text and graphics 0.27-0.54 -> 0.56-0.65 of their edge error
#: removed, whole edge band 0.11-0.36 -> 0.24-0.44, photo regions 0.00-0.02 -> 0.01-0.13.
#: The drawn ink alone (no contrast test): text 0.57-0.70, but photo regions to -0.28 (worse
#: than F); from 0.85 to 1.0, two photo regions -0.02; from 0.9 to 1.0, -0.01; read in the
#: working space (linear light here) rather than encoded, text 0.54-0.61.
KEPT_CONTRAST_LOW = 0.9
KEPT_CONTRAST_HIGH = 1.05
#: Every pixel, drawn ink or not, also moves towards O by the same ratio's smoothstep from
#: KEPT_CONTRAST_LOW to this: a quarter where F kept O's span, full where F's is this much
#: larger. A bilateral or edge-preserving filter pulls an edge's blends towards its nearer
#: side (F's 3 x 3 span then exceeds O's), where the reference, which filters the scene
#: before the downscale, keeps O's blend. Tuning half, the mixed scenes under the three
#: smoothing filters (12 PNG cases, the only cases that moved, every one up): photo regions
#: 0.073 -> 0.265 of their edge error (least 0.008 -> 0.073), text and graphics 0.625 ->
#: 0.656, whole band 0.357 -> 0.468. By highs with lows: 1.05 with 0.9, the kept ink's
#: (photo regions 0.138, least -0.262); 1.1 with 0.95, 1.0 (0.205, 0.166; least -0.037,
#: -0.021); 1.2 with 1.0 (0.171, 0.025); 1.3 with 0.9, 0.95, 1.0 (0.248, 0.198, 0.148).
STEEPENED_CONTRAST_HIGH = 1.2
#: How far the factor at a pixel reads O: the square and the 3 x 3 flatness test (the ink
#: test reads INK_RADIUS + 1, less).
REACH = max(REGION_RADIUS, INK_RADIUS) + 1


def neighbourhood_extremes(image):
    """The per-channel largest and smallest value of each pixel's 3 x 3 neighbourhood
    (borders replicated): two arrays of `image`'s shape ``(H, W, C)``."""
    height, width = image.shape[:2]
    padded = np.pad(image, ((1, 1), (1, 1), (0, 0)), mode="edge")
    # Running extremes, not np.max of the stacked 9 views: the same values without a
    # (9, H, W, 3) copy (27 -> 10 ms on a 512 x 512 window).
    brightest, darkest = padded[:height, :width].copy(), padded[:height, :width].copy()
    for dy in range(3):
        for dx in range(3):
            np.maximum(brightest, padded[dy:dy + height, dx:dx + width], out=brightest)
            np.minimum(darkest, padded[dy:dy + height, dx:dx + width], out=darkest)
    return brightest, darkest


def flat_pixels(encoded):
    """bool ``(H, W)``: O's 3 x 3 neighbourhood spans at most :data:`FLAT_SPAN` in every
    channel, and is not black.

    Parameters
    ----------
    encoded : ndarray of float32, shape (H, W, 3)
        O's sRGB-encoded colour (borders replicated, as every pass does).
    """
    brightest, darkest = neighbourhood_extremes(encoded)
    span = brightest - darkest
    flat = np.maximum(np.maximum(span[..., 0], span[..., 1]), span[..., 2]) <= np.float32(FLAT_SPAN)
    # Black is where a camera clips its shadows (a night sky, space): as often a photo's as
    # a drawing's ink, it is no evidence (held-out astronaut under a gamma curve: its photo
    # region went from 0.37 to -0.07 when it counted).
    return flat & (np.maximum(np.maximum(brightest[..., 0], brightest[..., 1]), brightest[..., 2])
                   > np.float32(FLAT_SPAN))


def _shifted(image, radius, outside=None):
    """The views of `image` at every offset of the square of `radius`, row by row: borders
    replicated, or the value `outside` beyond them."""
    height, width = image.shape[:2]
    widths = ((radius, radius), (radius, radius)) + ((0, 0),) * (image.ndim - 2)
    padded = (np.pad(image, widths, mode="edge") if outside is None
              else np.pad(image, widths, constant_values=outside))
    side = 2 * radius + 1
    return [padded[dy:dy + height, dx:dx + width] for dy in range(side) for dx in range(side)]


def _smoothstep(t):
    t = np.clip(t, 0, 1).astype(np.float32)
    return (t * t * (3 - 2 * t)).astype(np.float32)


def ink_weight(encoded, shares=(INK_SHARE_LOW, INK_SHARE_HIGH), repeats=INK_REPEATS, span=FLAT_SPAN):
    """float32 ``(H, W)``: 1 where the pixel holds drawn ink (a stroke's exactly recurring
    colour), 0 where it holds none, smooth in the pixel's share of the ink.

    The extremes are the brightest and darkest of the 3 x 3 neighbourhood by the sum of the
    channels (the first in row order among sums within :data:`INK_TIE`); each is tested as
    ink on its own, and the larger weight counts.

    Parameters
    ----------
    encoded : ndarray of float32, shape (H, W, 3)
        O's sRGB-encoded colour (borders replicated).
    shares : (float, float), optional
        The pixel's share of the ink at which the weight starts to rise and is full: the
        strength's (:data:`INK_SHARE_LOW`, :data:`INK_SHARE_HIGH`) or the gate's
        (:data:`INK_GATE_SHARE_LOW`, :data:`INK_GATE_SHARE_HIGH`).
    repeats : int, optional
        The recurrences an extreme needs: the strength's :data:`INK_REPEATS` or the gate's
        :data:`INK_GATE_REPEATS`.
    span : float, optional
        How close a colour must be to the extreme to recur (encoded): :data:`FLAT_SPAN`, the
        8-bit level, or a JPEG's wider one for the gate (``PureColourPrior.ink_span``).
    """
    planes = np.ascontiguousarray(np.moveaxis(np.asarray(encoded, np.float32), -1, 0))
    extremes = _extremes(planes)
    return _ink_weight(planes, extremes, _recurrences(planes, extremes, span), shares, repeats)


# Above this share of the image's pixels, ink_weight_at reads the whole image's weight at
# them (the same values): gathering each pixel's neighbourhood costs about three times as
# much per pixel (512 x 512 window, text over a photo at 0.81 of it: 0.35 s against 0.16 s;
# at 0.04, a photo's edges, 0.02 s against 0.20 s).
_GATHERED_SHARE = 0.3


def ink_weight_at(encoded, rows, cols, span=FLAT_SPAN, shares=(INK_SHARE_LOW, INK_SHARE_HIGH)):
    """float32 ``(K,)``: :func:`ink_weight` at the pixels ``(rows[k], cols[k])`` only, the
    same values, reading only their neighbourhoods (the summary line reads it at a
    window's edge pixels: 4% of the window on a photo, 5 ms against 90 ms).

    Parameters
    ----------
    encoded : ndarray of float32, shape (H, W, 3)
        O's sRGB-encoded colour (borders replicated).
    rows, cols : ndarray of int, shape (K,)
        The pixels.
    span, shares : optional
        As for :func:`ink_weight`.
    """
    encoded = np.asarray(encoded, np.float32)
    rows, cols = np.asarray(rows, np.intp), np.asarray(cols, np.intp)
    if rows.size > _GATHERED_SHARE * encoded.shape[0] * encoded.shape[1]:
        return ink_weight(encoded, shares, span=span)[rows, cols]
    replicated = np.pad(encoded, ((1, 1), (1, 1), (0, 0)), mode="edge")
    # Row by row, as _extremes visits them.
    extremes = _pick_extremes(np.ascontiguousarray(replicated[rows + dy, cols + dx].T)
                              for dy in range(3) for dx in range(3))
    radius = INK_RADIUS
    outside = np.pad(encoded, ((radius, radius), (radius, radius), (0, 0)), constant_values=np.nan)
    counts = [(np.zeros(rows.size, np.int32), np.zeros(rows.size, np.int32)) for _ in extremes]
    _count_recurrences((outside[rows + dy, cols + dx].T for dy in range(2 * radius + 1) for dx in range(2 * radius + 1)),
                       extremes, span, counts)
    return _ink_weight(np.ascontiguousarray(encoded[rows, cols].T), extremes, counts, shares, INK_REPEATS)


def _ink_weight(planes, extremes, recurrences, shares, repeats):
    """The weight from the pixels' colours `planes` ``(3, ...)``, their two extremes and
    each extreme's recurrences (:func:`ink_weight`)."""
    weight = np.zeros(planes.shape[1:], np.float32)
    for (ink, other), (equal, near) in zip((extremes, extremes[::-1]), recurrences):
        drawn = (equal >= repeats) & (2 * near <= equal) & (ink.max(axis=0) > np.float32(INK_DARK))
        span = np.sqrt(np.square(other - ink).sum(axis=0, dtype=np.float32))
        distance = np.sqrt(np.square(planes - ink).sum(axis=0, dtype=np.float32))
        share = np.where(span > 0, np.float32(1) - distance / np.where(span > 0, span, np.float32(1)), np.float32(0))
        low, high = shares
        rise = _smoothstep((share - np.float32(low)) / np.float32(high - low))
        weight = np.maximum(weight, np.where(drawn, rise, np.float32(0)))
    return weight


def _extremes(planes):
    """The brightest and darkest colour ``(3, H, W)`` of each 3 x 3 neighbourhood (borders
    replicated), by the sum of the channels, the first in row order among sums within
    :data:`INK_TIE`."""
    return _pick_extremes(np.moveaxis(colour, -1, 0) for colour in _shifted(np.moveaxis(planes, 0, -1), 1))


def _pick_extremes(colours):
    """The brightest and darkest of `colours` (planes ``(3, ...)`` in row order): a later
    colour replaces the one kept only when its sum is more than :data:`INK_TIE` beyond it."""
    tie = np.float32(INK_TIE)
    brightest = darkest = None
    for colour in colours:
        brightness = colour[0] + colour[1] + colour[2]
        if brightest is None:
            brightest, darkest = colour.copy(), colour.copy()
            high, low = brightness, brightness.copy()
            continue
        higher, lower = brightness > high + tie, brightness < low - tie
        np.copyto(brightest, colour, where=higher)
        np.copyto(darkest, colour, where=lower)
        np.copyto(high, brightness, where=higher)
        np.copyto(low, brightness, where=lower)
    return brightest, darkest


def _luma(colour):
    """float32: the luma of encoded colour planes ``(3, ...)`` (:data:`INK_LUMA_SATURATION`)."""
    return colour[0] * LUMA_WEIGHTS[0] + colour[1] * LUMA_WEIGHTS[1] + colour[2] * LUMA_WEIGHTS[2]


def _by_luma(ink, span):
    """bool ``(...)``: where the extreme `ink` ``(3, ...)`` recurs by its luma
    (:data:`INK_LUMA_SATURATION`); None where `span` is the 8-bit level's."""
    if span <= FLAT_SPAN:
        return None
    brightest = ink.max(axis=0)
    return (brightest - ink.min(axis=0) <= np.float32(INK_LUMA_SATURATION)) & (brightest >= np.float32(INK_LUMA_DARK))


def _ink_distance(colour, ink, by_luma, ink_luma):
    """float32: how far `colour` lies from the extreme `ink` (planes ``(3, ...)``): the largest
    channel difference, or where `by_luma` the luma difference less :data:`_LUMA_TIE`."""
    distance = np.abs(colour[0] - ink[0])
    for channel in (1, 2):
        np.maximum(distance, np.abs(colour[channel] - ink[channel]), out=distance)
    if by_luma is not None:
        np.copyto(distance, np.abs(_luma(colour) - ink_luma) - np.float32(_LUMA_TIE), where=by_luma)
    return distance


def _count_recurrences(colours, extremes, span, counts):
    """Add to `counts` (per extreme, ``(equal, near)``) the recurrences of each extreme among
    `colours` (planes ``(3, ...)``, one per pixel of the square; NaN outside the image)."""
    tests = [(ink, by_luma, None if by_luma is None else _luma(ink))
             for ink, by_luma in ((ink, _by_luma(ink, span)) for ink in extremes)]
    for colour in colours:
        for (ink, by_luma, ink_luma), (equal, near) in zip(tests, counts):
            distance = _ink_distance(colour, ink, by_luma, ink_luma)
            same = distance <= np.float32(span)
            equal += same
            near += ~same & (distance <= np.float32(INK_NEAR_SPAN))
    return counts


def _recurrences(planes, extremes, span=FLAT_SPAN):
    """Per extreme: how many pixels of the square of :data:`INK_RADIUS` (inside the image)
    equal it within `span`, and how many lie farther but within :data:`INK_NEAR_SPAN` (none
    where `span` is as wide); on a JPEG's span by luma (:data:`INK_LUMA_SATURATION`)."""
    radius = INK_RADIUS
    height, width = planes.shape[1:]
    # The outside is not there (NaN is equal and near to nothing): replicated borders would
    # repeat every border pixel's colour.
    padded = np.pad(planes, ((0, 0), (radius, radius), (radius, radius)), constant_values=np.nan)
    counts = [(np.zeros((height, width), np.int32), np.zeros((height, width), np.int32)) for _ in extremes]
    return _count_recurrences((padded[:, dy:dy + height, dx:dx + width]
                               for dy in range(2 * radius + 1) for dx in range(2 * radius + 1)), extremes, span, counts)


def kept_contrast(encoded_original, encoded_filtered, high=KEPT_CONTRAST_HIGH):
    """float32 ``(H, W)``: how fully F kept O's contrast around each pixel, 0 to 1.

    The smoothstep from :data:`KEPT_CONTRAST_LOW` to `high` of F's span over O's in the
    3 x 3 neighbourhood (borders replicated; the largest channel's span, max minus min); 0
    where O is flat.

    Parameters
    ----------
    encoded_original, encoded_filtered : ndarray of float32, shape (H, W, 3)
        O's and F's sRGB-encoded colour.
    high : float, optional
        The ratio at which it is full: :data:`KEPT_CONTRAST_HIGH`, or
        :data:`STEEPENED_CONTRAST_HIGH` for every pixel's move towards O.
    """
    return _kept_from(_span_ratio(encoded_original, encoded_filtered), high)


def _span_ratio(encoded_original, encoded_filtered):
    """F's 3 x 3 span over O's (largest channel), 0 where O is flat (:func:`kept_contrast`)."""
    def span(encoded):
        highest, lowest = neighbourhood_extremes(encoded)
        return (highest - lowest).max(axis=-1)

    original_span = span(encoded_original)
    return np.where(original_span > 0, span(encoded_filtered) / np.where(original_span > 0, original_span, 1), 0)


def _kept_from(ratio, high):
    """:func:`kept_contrast` of a span ratio: the smoothstep from KEPT_CONTRAST_LOW to `high`."""
    t = np.clip((ratio - np.float32(KEPT_CONTRAST_LOW)) / np.float32(high - KEPT_CONTRAST_LOW), 0, 1)
    return (t * t * (3 - 2 * t)).astype(np.float32)


def _box_sum(mask, radius):
    """Sum of `mask` over the square of `radius` around each pixel, the image's outside 0.

    Counts are whole numbers: the sums are exact, so a tile gives the whole image's.
    """
    padded = np.pad(mask.astype(np.float64), ((radius + 1, radius), (radius + 1, radius)))
    table = padded.cumsum(axis=0).cumsum(axis=1)
    side = 2 * radius + 1
    height, width = mask.shape
    return (table[side:side + height, side:side + width] - table[:height, side:side + width]
            - table[side:side + height, :width] + table[:height, :width])


def flat_share(encoded, radius=REGION_RADIUS):
    """float32 ``(H, W)``: the share of flat pixels in the square of `radius` around each pixel."""
    inside = _box_sum(np.ones(encoded.shape[:2], bool), radius)
    return (_box_sum(flat_pixels(encoded), radius) / inside).astype(np.float32)


def hard_edged_weight(share):
    """1 where a region's flat share is a drawing's, 0 where it is a photo's, smooth between."""
    t = np.clip((share - np.float32(TEXTURED_SHARE)) / np.float32(HARD_EDGED_SHARE - TEXTURED_SHARE), 0, 1)
    return (t * t * (3 - 2 * t)).astype(np.float32)


@dataclass(frozen=True)
class LocalStrength:
    """The local plan of a point-wise filter: the confidence's factor per pixel.

    Attributes
    ----------
    textured : float
        The factor in textured regions: the calibrated strength for a photo, in (0, 1); a
        fixed strength for hatching and screentone under a smoothing filter (``aarecovery.plan.hatching``);
        0 for a photo under a neighbourhood filter, kept as F around the drawn regions
        (``aarecovery.plan.mixed_content``).
    textured_regions : str
        What the textured regions are, for the summary line.
    drawn_ink : bool
        Whether drawn ink (:func:`ink_weight`) also counts as hard-edged: yes over a photo,
        where captions and lines drawn on it repeat their colour exactly; no on hatching and
        screentone, whose strokes repeat theirs too but lose at full strength under a
        smoothing filter (``aarecovery.plan.hatching``).
    ink_shares : (float, float)
        The pixel's share of the drawn ink at which its weight starts to rise and is full
        (:func:`ink_weight`'s `shares`): :data:`INK_SHARE_LOW`, :data:`INK_SHARE_HIGH`, or
        under a sharpening filter over a photo :data:`SHARPENED_INK_SHARE_LOW`,
        :data:`SHARPENED_INK_SHARE_HIGH`.
    """

    textured: float
    textured_regions: str = "photo"
    drawn_ink: bool = True
    ink_shares: tuple = (INK_SHARE_LOW, INK_SHARE_HIGH)

    #: How far the factor at a pixel reads O (a tile's extra halo).
    reach = REACH

    def factor(self, encoded):
        """float32 ``(H, W)``: from :attr:`textured` (photo) to 1 (hard-edged), per pixel of O.

        Parameters
        ----------
        encoded : ndarray of float32, shape (H, W, 3)
            O's sRGB-encoded colour.
        """
        weight = self.region_weight(encoded)
        if self.drawn_ink:
            weight = np.maximum(weight, ink_weight(encoded, self.ink_shares))
        return self._from_weight(weight)

    @staticmethod
    def region_weight(encoded):
        """float32 ``(H, W)``: the regions' weight alone, 0 (textured) to 1 (hard-edged), smooth
        between (:func:`hard_edged_weight` of :func:`flat_share`), without the drawn ink: where
        the pure colours of a prior that acts on drawn content only act
        (``aarecovery.spec.pure_colours.PureColourPrior.drawn_only``).

        Parameters
        ----------
        encoded : ndarray of float32, shape (H, W, 3)
            O's sRGB-encoded colour.
        """
        return hard_edged_weight(flat_share(encoded))

    @staticmethod
    def gate(encoded, ink, ink_span=FLAT_SPAN):
        """float32 ``(H, W)``: where the pure colours of a prior that acts on drawn content only
        act: :meth:`region_weight`, or with `ink` (``PureColourPrior.ink_gate``) the larger of
        it and :func:`ink_weight` at the gate's shares and recurrences (:data:`INK_GATE_SHARE_LOW`,
        :data:`INK_GATE_SHARE_HIGH`, :data:`INK_GATE_REPEATS`).

        Parameters
        ----------
        encoded : ndarray of float32, shape (H, W, 3)
            O's sRGB-encoded colour.
        ink : bool
        ink_span : float, optional
            Within what the ink recurs (:func:`ink_weight`'s `span`; ``PureColourPrior.ink_span``).
        """
        weight = LocalStrength.region_weight(encoded)
        return np.maximum(weight, ink_weight(encoded, (INK_GATE_SHARE_LOW, INK_GATE_SHARE_HIGH), INK_GATE_REPEATS,
                                             ink_span)) if ink else weight

    @staticmethod
    def kept_ink(encoded, encoded_filtered):
        """float32 ``(H, W)``: the drawn ink's weight towards O where the pure colours' gate
        leaves the ink out (text over a photo under a smoothing filter): the gate with the ink
        (:meth:`gate`) times how fully F kept O's contrast there (:func:`kept_contrast`), or
        where larger, how far F steepened O's contrast at any pixel (:func:`kept_contrast`
        full at :data:`STEEPENED_CONTRAST_HIGH`).

        Parameters
        ----------
        encoded, encoded_filtered : ndarray of float32, shape (H, W, 3)
            O's and F's sRGB-encoded colour.
        """
        # One span ratio for both smoothsteps, as the GL twin reads it once.
        ratio = _span_ratio(encoded, encoded_filtered)
        return np.maximum(LocalStrength.gate(encoded, True) * _kept_from(ratio, KEPT_CONTRAST_HIGH),
                          _kept_from(ratio, STEEPENED_CONTRAST_HIGH)).astype(np.float32)

    def factor_at(self, encoded, rows, cols):
        """float32 ``(K,)``: :meth:`factor` at the pixels ``(rows[k], cols[k])`` of O only,
        the same values (the drawn ink read only around them).

        Parameters
        ----------
        encoded : ndarray of float32, shape (H, W, 3)
            O's sRGB-encoded colour.
        rows, cols : ndarray of int, shape (K,)
            The pixels.
        """
        weight = hard_edged_weight(flat_share(encoded)[rows, cols])
        if self.drawn_ink:
            weight = np.maximum(weight, ink_weight_at(encoded, rows, cols, shares=self.ink_shares))
        return self._from_weight(weight)

    def hard_edged_share(self, encoded, edges):
        """The share of the `edges` pixels whose factor is nearer 1 (hard-edged: text,
        drawings, ink) than :attr:`textured`; 0 without edge pixels.

        Parameters
        ----------
        encoded : ndarray of float32, shape (H, W, 3)
            O's sRGB-encoded colour.
        edges : ndarray of bool, shape (H, W)
        """
        rows, cols = np.nonzero(edges)
        if rows.size == 0:
            return 0.0
        return float((self.factor_at(encoded, rows, cols) > (1 + self.textured) / 2).mean())

    def _from_weight(self, weight):
        return (np.float32(self.textured) + np.float32(1 - self.textured) * weight).astype(np.float32)


def encoded_colour(rgba, linear_input):
    """O's sRGB-encoded colour ``(H, W, 3)``, which the local plan reads, from contract RGBA."""
    return linear_to_srgb(rgba[..., :3]) if linear_input else rgba[..., :3]


def strength_map(plan, factor, shape):
    """The map of the strength that multiplied the confidence: `plan`'s strength times the
    local plan's `factor` (None: the one strength), float32 of `shape`."""
    if factor is None:
        return np.full(shape, plan.strength, np.float32)
    return (np.float32(plan.strength) * factor).astype(np.float32)
