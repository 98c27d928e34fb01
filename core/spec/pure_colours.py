"""Pure colours of thin features, for point-wise filters on hard-edged content (safe default).

The paper blends the recovered colours found at the two extreme pixels of the 3x3
neighbourhood. Text of 7-16 px, lines under 1.5 px and converging wedges never show a pure
ink pixel: their darkest pixel is itself a blend, so the paper blends between colours that
are already mixed (measured: 35-60 % of the error recovered there, against 85-95 % on
shapes). When the filter is point-wise, ``F = f(O)``, and ``f`` is known as a lookup table
(``aarecovery.plan.pointwise``), the pure colour of such a feature can be estimated and
filtered directly:

* An extreme pixel q holds a thin feature's partial colour when it is a **ridge** along the
  colour line: some pair of opposite neighbours of q (N/S, W/E or a diagonal pair) both lie
  on the line and both are less extreme than q by more than a tenth of the line's span.
* It is **not** a partial colour when it is one of the image's flat colours (the
  **palette**: colours of pixels whose whole 3x3 neighbourhood is equal, the 32 most
  frequent; on a JPEG also a colour with a flat colour's luma, whose chroma the JPEG smeared:
  :func:`is_flat_colour`), or when q lies on the image border (a feature cut by the border
  looks thin).
* Nor when q is O's darkest or brightest colour (every key within 1/255 of an end of O's key
  range) and the other extreme is neither O's opposite end nor a flat colour: the dark paper
  between 0.5 px white lines has no flat pixel, but it is pure; extended to black it turned
  the whole paper into a blend of f(black) and f(white). Black lines on white alone still
  extend their darkest pixel (the other extreme is the white end). Quick suite sRGB 0.734 ->
  0.761, linear 0.774 -> 0.780 (lines/sRGB: equalize 0.40 -> 0.74, posterize 0.43 -> 0.63,
  gamma 0.61 -> 0.72); full 0.789 -> 0.806, 0.790 -> 0.794; no case lost.
* A partial colour is extended along the colour line, away from the other extreme, to the
  edge of the colour cube (the prior: inks of thin features are saturated, black or white,
  as in text and line art). Its filtered colour is ``f`` of that, from the table, provided
  the table reproduces F at the observed extreme (within 0.02) and is keyed per channel or
  by luma; keys on the mean or maximum channel matched F only by coincidence on images of
  few colours (colour-to-grey on the line scene) and predicted nonsense off them.
* Coverage ``alpha`` is re-measured against the extended colours, and the Jacobi step
  blends the fixed filtered colours in place of ``R`` at the extreme pixels.

* Tone mapping and histogram equalization are not functions of each channel or of luma on
  colour content: they map luma (equalization, encoded values) or luminance (tone mapping,
  linear light) and scale the colour with it. The scale keys (:data:`SCALE_KEYS`,
  :func:`scale_transfer`) are that form; with them the extension covers those filters
  (quick suite: tonemap on text/lines 0.39-0.52 -> 0.72-0.96, equalize 0.37-0.47 -> 0.81-0.90).

* The table must be monotone (``aarecovery.plan.pure_colours.is_monotone``), or, failing
  that, turn at most once per column (``turns_at_most_once``: a colour map of the grey
  value, such as JET): tables that match colour to grey or a hue swap by coincidence zigzag,
  and extending with them lost up to 7.9 dB (chart).

* A palette quantiser (indexed colour) is point-wise but no table of one key explains it on
  a colour drawing: its 3-D table of the whole colour (:data:`COLOUR_KEY`,
  :func:`colour_map_at`; ``aarecovery.plan.colour_map.indexed_colour_prior``) gives the
  extended colour its filtered colour instead.

* Over a photo (text, logos and interface chrome drawn on it, ``PureColourPrior.drawn_only``)
  the extension acts only in the regions the local plan reads as drawn, by their smooth
  weight (the ``gate`` of :func:`fit_pure_colour_model`): a partial colour is extended that
  share of the way, and where the weight is 0 the model is the paper's, so that the photo
  does not move and no seam shows (``aarecovery.plan.analysis`` has the measurements). On a
  lossless O there, a partial colour is extended only against one of O's flat colours or
  towards a pure colour O shows (``PureColourPrior.backed_or_seen``): the gate is open over
  a few pixels of the photo beside a drawn region, and the photo's texture is no thin feature.

Measured (synthetic scenes, blur excluded, mean edge-band error reduction): quick suite
linear 0.600 -> 0.712, sRGB 0.628 -> 0.686; full suite 0.642 -> 0.751 and 0.681 -> 0.749;
thresholded 7 px text 0.51 -> 0.93, thin lines 0.43 -> 0.95; no case worse than F. A stricter purity test (a pixel with an equally
extreme neighbour whose opposite is lower is pure) protected shapes as well as the palette
but gave back most of the gain on text, whose strokes straddle two pixels. The converse, a
**two-pixel ridge** (q, a neighbour as extreme within the margin, and lower pixels beyond
both), was measured and not taken: a line straddling two pixels evenly passes no ridge test,
but a line two pixels wide at full coverage looks the same. Tuning half, drawings, scans and
mixed scenes at 96 px, PNG and JPEG (736 cases): 153 up, 65 down, the star burst's PNG mean
0.692 -> 0.716 and the maps' 0.514 -> 0.520, but the screenshot's interface chrome 0.385 ->
0.362 and its text and graphics regions with the other mixed scene's 0.349 -> 0.340.
Nor is a ridge exempt where it runs along a row or column in one exact colour (8 pixels
or more: a rule one pixel wide on the pixel grid, drawn in its own grey, looks like a
half-pixel hairline of black there, and the held-out pie charts lose 0.38 dB by it). On
the same 736 tuning cases such runs were mostly thin features' partial colours: 9 up, 152
down (the screenshot's interface rules 0.385 -> 0.370, the manga's panel borders 0.568 ->
0.551, the maps 0.514 -> 0.502).

This module is the NumPy specification; ``pure_colours.glsl``, included by the GL fit pass
(``#if PURE_COLOURS``), is its GL twin. ``aarecovery.plan.pure_colours`` builds the prior.
"""

from dataclasses import dataclass

import numpy as np

from ..colour import LUMA_WEIGHTS, LUMINANCE_D50, REC601_LUMA, linear_to_srgb, srgb_to_linear
from .blend_model import BlendModel, confidence, coverage, fit_extremes
from .local_plan import FLAT_SPAN
from .neighbourhood import NEIGHBOUR_OFFSETS, OPPOSITE_PAIRS, dot, neighbours, planes
from .sobel import ridge_magnitude, sobel_magnitude

__all__ = ["PureColourPrior", "is_flat_colour", "PALETTE_SIZE", "INK_COUNT", "ON_LINE_TOLERANCE", "KEPT_CONTRAST", "EXTENSION_KEYS",
           "SCALE_KEYS", "SHIFT_KEYS", "filtered_colour", "transfer_encoded", "extend_extreme", "scale_transfer", "key_values", "shift_grey",
           "rec601_grey", "fit_pure_colour_model", "RIDGE_EDGE_SCALE", "possible_ridges", "COLOUR_KEY", "colour_map_at"]

#: Most palette colours kept (a uniform array in the GL pass).
PALETTE_SIZE = 32
# An extreme colour within this distance (working space) of a palette colour is pure.
PALETTE_TOLERANCE = 0.03
# Ridge test: neighbours count when they lie within this distance of the colour line, and
# are "less extreme" when lower by more than this share of the line's span. A tenth, made
# 0.1001: synthetic scenes have exact coverages, so a neighbour can sit exactly 10 % below
# the extreme, and with a margin of exactly 0.1 rounding decided the test, differently in
# GL and NumPy (beta differed by 0.08-0.22 on shapes under a cube curve). No suite case moved.
LINE_TOLERANCE = 0.05
RIDGE_MARGIN = 0.1001
#: A flat colour of O beyond the extreme stops the extension as the feature's ink when it lies
#: within this distance of the colour line (working space). At :data:`LINE_TOLERANCE` a grey
#: photo's flat greys stopped the extension of light interface text over a dark bar: the sRGB
#: screenshot's title, its ink (235, 235, 242) never flat, was stopped at the photo's grey 197
#: 0.028 off the line (reach 1.13 instead of the 1.52 of the window's white, 0.014 off it), and
#: its pixels ended near F (152 where the reference has 178). Tuning half, half the ridge
#: tolerance: 69 cases moved, 52 up (the screenshot in both spaces under 30 tools, up to
#: +0.17 under Pillow's YCbCr equalization; serif in sRGB up to +0.011), 17 down by at most
#: 0.02 (the screenshot under GEGL's posterize), mean +0.018. Held out, run after the choice: 48
#: moved, 16 up, 32 down by at most 0.021, mean -0.001 (no light text over a grey photo there).
INK_LINE_TOLERANCE = 0.025
#: Above compression noise (``PureColourPrior.ridge_noise``), the neighbours must also lie
#: lower than the extreme by this many times the noise's contrast: a JPEG's ringing between
#: sub-pixel spokes made ridges of noise, extended to the cube (the star burst under OpenCV's
#: gamma at q 85 lost 0.34 dB). Measured on the real-tools tuning half, JPEG originals under
#: ten point-wise tools, mean error reduction of drawings (100 cases) / scans of text (40):
#: 0 (the span's share alone) 0.259 / 0.418, 1 0.264 / 0.418, 1.5 0.266 / 0.417, 2 0.267 /
#: 0.411, 3 0.269 / 0.391; from 1 the star burst's loss is a gain, serif text gains up to
#: 0.11, and above 1.5 the scans' text strokes (noisier at q 75-80) lose their pure colours.
#: PNG originals have no noise contrast and do not move. Not above a paper's grain: at 3 the
#: grained page (notice, PNG and JPEG) fell from 0.71 to 0.53.
RIDGE_NOISE_MARGIN = 1.5
#: A partial colour is extended only when the pure colour lies beyond it by more than a fifth
#: of the line's span: an extreme that is already (nearly) at the edge of the cube is the ink
#: itself, seen whole in a 1 px line. Extending it anyway mixed a little paper into lines
#: that F and the reference show black (a star burst's dark-blue spokes under GEGL's levels,
#: in-low 0.3 in-high 0.4: up to 0.13 of yellow in 88 black pixels; none now). Measured:
#: real-tools tuning half, drawings with PNG originals 0.606 -> 0.643; built-in quick suite
#: linear 0.781 -> 0.766, sRGB 0.762 -> 0.781; full 0.791 -> 0.774, 0.805 -> 0.812.
#: 1.2001, not 1.2, as RIDGE_MARGIN: box-filtered coverages reach exactly 1.2 ((1 - 4/16) /
#: (14/16 - 4/16), the text scene in linear light), and rounding then decided the test,
#: differently on an NVIDIA H100 and in NumPy (R 0.045 apart after one iteration). Built-in
#: suite: two text cases +0.001, the means unchanged; real-tools quick tuning half unchanged.
MIN_REACH = 1.2001
#: ... unless the pure colour is one O shows: a flat colour of O stops the extension (see
#: :func:`extend_extreme`), or the point on the cube lies within this (encoded, each channel)
#: of one of O's recurring inks (``PureColourPrior.inks``). Then the extreme is a partial
#: colour after all, however close to its ink: a pixel 86 % covered by green ink (0, 89, 38)
#: on grey-green paper, under G'MIC's ``-pow 3`` (whose curve ends in a step at 6 levels),
#: shows 36 in the reference and 255 in F, and without its pure colour it stayed 255. Tuning
#: half, drawings, scans and mixed scenes at 96 px (736 cases, PNG and JPEG): 134 up, 6 down
#: by at most 0.032 (the star burst under ImageMagick's unsharp mask 0.69-0.72 -> 0.66-0.69,
#: the memo under GEGL's posterize at q 80 0.355 -> 0.325); manga PNG 0.568 -> 0.608, JPEG
#: 0.518 -> 0.557, serif PNG 0.870 -> 0.883 (under ``-pow 3`` 0.08 -> 0.16-0.24), the
#: screenshot 0.385 -> 0.406. The flat colours alone gave 0.579 on the manga, the inks alone
#: 75 up and 2 down; any recurring colour as an ink (no face, no cap) 126 up, 7 down; two
#: recurrences instead of four 8 down; no rule at all (MIN_REACH 1) 261 up and 53 down, the
#: star burst under GEGL's levels 0.52 -> 0.11, as above. Against this tolerance, 1/255: 1 up
#: and 6 down (the manga under Pillow's YCbCr equalize at q 90 0.886 -> 0.817); 4/255: 5 up
#: and 4 down (the memo under GEGL's posterize at q 85 0.461 -> 0.421).
INK_TOLERANCE = 2.0 / 255
#: Most inks kept (a uniform array in the GL pass), the most frequent first.
INK_COUNT = 16
#: An extreme on the colour cube's face already (reach 1) is its own pure colour.
SHORT_REACH = 1.0001
#: The edge strength of O in the pure colours' model is the larger of its Sobel magnitude and
#: this times :func:`~aarecovery.spec.sobel.ridge_magnitude`: a 1 px line or dot centred on
#: a pixel has no Sobel gradient, so the paper's confidence kept F there (a screentone's
#: regular grid of dots kept whole, every pixel of it symmetric about its centre: the manga
#: in linear light under GEGL's threshold 0.638 of its edge error). A half, so that a line
#: stands out as much as a step of the same contrast beside it (Sobel 1/2). Gated as the
#: filtered extremes' contrast is (``gate``): a photo keeps the paper's edge strength.
#: Tuning half (`aarecovery eval --suite realtools --half tune`, 920 cases): 292 up, 9 down
#: (the sRGB maps under the unsharp masks 0.163 -> 0.119 and 0.284 -> 0.246), drawings
#: 0.784 -> 0.826, the manga 0.64-0.90 -> 0.95-0.99 under the point-wise tools. Beside it
#: (NumPy harness, 460 PNG cases): 1 instead of a half 0.607 against 0.605 with more down;
#: the least over the pairs (dots only) kept a quarter of the gain. Held out: 156 up, 42
#: down, drawings 0.714 -> 0.721; the plots' one-pixel grey rules read as hairlines (-0.16).
RIDGE_EDGE_SCALE = 0.5
# The table must reproduce F at the observed extreme within this (working space).
EXPLAIN_TOLERANCE = 0.02
#: Without a fitted table (a neighbourhood filter that keeps flat colours), F at the extreme
#: must lie within this of O's colour line through the two extremes (working space): the
#: built-in colour replacement of sRGB text reached that plan and lost 0.79 -> -2.0 without
#: it; per-channel clipping of overshoot moves F off the line a little (real-tools tuning
#: half, neighbourhood filters on drawings: 0.628 at 0.05, 0.658 at 0.1, 0.673 at 0.15).
ON_LINE_TOLERANCE = 0.15
#: ... and keep at least this share of the extremes' contrast in O along that line: the
#: built-in bilateral filter erases thin sRGB text, and so does its reference; extending it
#: lost 0.33 -> -0.67, with this test 0.79.
KEPT_CONTRAST = 0.5
#: An extreme is tested only when it differs from the other extreme by more than 8 levels of
#: an 8-bit image in some encoded channel or in alpha. Below that the two extremes of a
#: smooth gradient's quantisation noise (O stepping by 1-2 levels, F flat after a threshold)
#: passed the ridge test, were extended to the cube and painted colours F does not have
#: (a gradient under a per-channel threshold: (0, 13, 0) and (20, 20, 0) on black, beta
#: 0.17-0.32); and the principal direction of such a near-flat neighbourhood is decided
#: by rounding, so 1-ulp differences in O (GIMP's own u8-to-float conversion) picked other
#: extremes and the GL and NumPy results differed there by up to 20/255. Half a level above
#: 8 keeps 8-bit inputs away from the threshold. Measured: no change of any case's error
#: reduction on the quick and full suites (16.5/255 cost 0.0001 on the full suite's sRGB mean).
MIN_CONTRAST = 8.5 / 255
#: Keys of a **luma shift**, ``f(c) = clip(c + s(Y))``, the same offset on every channel: a
#: curve of the 8-bit Y of JPEG's YCbCr with the chroma kept (``aarecovery.plan.pointwise``
#: fits them), Y computed exactly as the tool does (:func:`shift_grey`): ``"luma601_shift"``
#: as OpenCV's YCrCb, ``"luma601_floor_shift"`` as Pillow's YCbCr. Column 0 of the table holds
#: the offset per grey level.
SHIFT_KEYS = ("luma601_shift", "luma601_floor_shift")
#: The key of a 3-D colour map (``aarecovery.plan.colour_map``: a palette quantiser): the whole
#: encoded colour indexes a table of shape (B, B, B, 3), read between bin centres
#: (:func:`colour_map_at`).
COLOUR_KEY = "colour"
#: Table keys for which the extension is used (see the module notes).
EXTENSION_KEYS = ("channel", "luma", "luma_scale", "luminance_scale", "luminance", "luminance_d50",
                  "luma601") + SHIFT_KEYS + (COLOUR_KEY,)
_KEY_CODES = {"channel": 0, "luma": 1, "luma_scale": 2, "luminance_scale": 3, "luminance": 4, "luminance_d50": 5,
              "luma601_shift": 6, "luma601_floor_shift": 7, "luma601": 8, COLOUR_KEY: 9}
# The tools' fixed-point Rec. 601 Y of 8-bit R, G, B (each matched 262,144 random colours
# exactly): OpenCV's weights in 1/16384 with rounding; Pillow's YCbCr sums its weights times
# 64, each rounded to a whole number, and truncates (its Y is a level below the rounded
# luma's on half of all colours, and on 1 % below the truncated luma's). Whole numbers below
# 2^24: exact in float32 on both backends.
_OPENCV_Y = (4899.0, 9617.0, 1868.0, 16384.0)
_PILLOW_Y = (19.136, 37.568, 7.296, 64.0)
# The rounded Rec. 601 grey of 8-bit R, G, B in thousandths (``"luma601"``, :func:`rec601_grey`):
# whole numbers, so both backends round the same grey at a tie.
_REC601_Y = tuple(float(round(weight * 1000)) for weight in REC601_LUMA) + (1000.0,)
#: Keys of one value per pixel: the encoded value of the luminance of linear light, with the
#: Rec. 709 weights or babl's D50 ones (colour to grey and thresholds by luminance).
LUMINANCE_KEYS = {"luminance": LUMA_WEIGHTS, "luminance_d50": np.array(LUMINANCE_D50, np.float32)}
#: Keys whose table maps a luma to a new luma and scales the colour with it (keeping hue):
#: ``"luma_scale"`` on encoded values (histogram equalization), ``"luminance_scale"`` on
#: linear light (tone mapping). Column 0 of the table holds the mapped value; black (key
#: 0) maps to that grey.
SCALE_KEYS = ("luma_scale", "luminance_scale")
_SCALE_BLACK = 1e-6
_LUMA = LUMA_WEIGHTS


@dataclass(frozen=True)
class PureColourPrior:
    """What the extension needs besides O and F: the filter's table and the flat colours.

    Attributes
    ----------
    key : str
        One of :data:`EXTENSION_KEYS`: how :attr:`table` is indexed: each channel of the encoded colour, its luma, or the
        encoded value of its luminance (:data:`LUMINANCE_KEYS`); the scale keys map luma
        (encoded) or luminance (linear) and scale colour with it (:func:`scale_transfer`);
        the shift keys add an offset of the 8-bit Rec. 601 grey to every channel
        (:data:`SHIFT_KEYS`); ``"luma601"`` indexes every column by that grey, rounded
        (:func:`rec601_grey`: OpenCV's colour maps of a colour image); :data:`COLOUR_KEY`
        indexes a 3-D table by the whole colour (a palette quantiser).
    table : ndarray of float32, shape (256, 3), or (B, B, B, 3) for :data:`COLOUR_KEY`
        Encoded output colour per bin of the key; read with linear interpolation between
        bin centres ``(i + 0.5) / 256`` (trilinear for the colour key: :func:`colour_map_at`).
    palette : ndarray of float32, shape (N, 3), N <= PALETTE_SIZE
        sRGB-encoded flat colours of O.
    key_low, key_high : ndarray of float32, shape (3,), optional
        The key range O shows (bin centres of the table's first and last filled bins, per
        column; the scale keys use column 0). Beyond it the table is extrapolated
        (``aarecovery.plan.pure_colours.extrapolate_table``); an extreme whose key lies at an end of the range (within
        :data:`RANGE_TOLERANCE`) is read with its keys clamped to the range, as before the
        extrapolation (see :func:`extend_extreme`). Default: no clamping.
    to_cube : bool
        Extend a partial colour to the colour cube when no flat colour of O lies beyond it on
        its line. False where the fitted tables that explain F equally well disagree on the
        cube (two colours fit any key), so that f there is a guess, and where F is an affine
        function of the table's key on O's edges (``aarecovery.plan.pure_colours``), so
        that the guess could only add its own error.
    explain_filtered : bool
        The table must reproduce F at the observed extreme (:data:`EXPLAIN_TOLERANCE`): true
        for a fitted point-wise table. False for a neighbourhood filter that keeps flat
        colours (``aarecovery.plan.flat_colours``): its table is what it does to a flat
        area, and F at a thin feature differs from that by the very damage to repair.
    noise_contrast : float
        Extremes closer than this in every encoded channel are not tested, where it exceeds
        :data:`MIN_CONTRAST`: the compression noise O carries (``aarecovery.plan.compression``),
        whose ringing next to a letter is not a thin stroke. 0: O is not compressed.
    ridge_noise : float
        O's compression noise as a contrast: a ridge's neighbours must lie lower than the
        extreme by :data:`RIDGE_NOISE_MARGIN` times it too (:func:`extend_extreme`). Not a
        paper's grain, which `noise_contrast` may hold. 0: O is not compressed.
    drawn_only : bool
        False: the prior acts everywhere. True (text and drawings over a photo): it acts only
        in the regions that the local plan reads as drawn, in proportion to their weight
        (``aarecovery.spec.local_plan.LocalStrength.region_weight``, the ``gate`` of
        :func:`fit_pure_colour_model`), so that the photo is not extended.
    ink_gate : bool
        With `drawn_only`: the drawn ink (``aarecovery.spec.local_plan.ink_weight``: a
        stroke's colour recurring exactly nearby) opens the gate too, where it is larger than
        the regions' weight: captions and lines drawn straight on the photo, with no flat
        region around them. Only on colour images (``aarecovery.plan.analysis``): a grey
        photo's levels recur as exactly as ink.
    ink_span : float
        With `ink_gate`: how close a colour must be to the ink to recur (encoded; the `span`
        of ``aarecovery.spec.local_plan.ink_weight``): the 8-bit level, or on a JPEG, whose
        ink recurs only within its noise, a wider span (``aarecovery.plan.mixed_content``).
    inks : ndarray of float32, shape (N, 3), N <= INK_COUNT, optional
        sRGB-encoded colours that O shows at four pixels or more and that lie on the colour
        cube's faces (within :data:`INK_TOLERANCE`): black, white, saturated inks, seen
        whole somewhere though not flat (``aarecovery.plan.pure_colours.inks_of``). A partial
        colour whose extension to the cube lands on one is extended even when the reach is
        short (:data:`MIN_REACH`). None: no inks.
    luma_purity : float
        An extreme whose luma lies within this of a flat colour's (working space, Rec. 709
        weights on the premultiplied colours) is that flat colour too (:func:`is_flat_colour`):
        a JPEG keeps luma at full resolution and quantises chroma more coarsely, often at
        half resolution, so the paper in a gap between two strokes keeps its luma while its
        chroma takes on the strokes' (``aarecovery.plan.pure_colours`` has the figures).
        0: colours only (O is not compressed).
    """

    key: str
    table: np.ndarray
    palette: np.ndarray
    key_low: np.ndarray = None
    key_high: np.ndarray = None
    to_cube: bool = True
    explain_filtered: bool = True
    noise_contrast: float = 0.0
    ridge_noise: float = 0.0
    drawn_only: bool = False
    ink_gate: bool = False
    ink_span: float = FLAT_SPAN
    luma_purity: float = 0.0
    inks: np.ndarray = None

    @property
    def backed_or_seen(self):
        """bool: gated by the local plan (:attr:`drawn_only`), a partial colour is extended only
        against one of O's flat colours or towards a pure colour that O shows (a flat colour on
        the line beyond it, or one of :attr:`inks` at the cube); on a lossless O, without paper
        grain (:attr:`noise_contrast` 0).

        Beside a drawn region (a banner, a label, a button) the gate stays open over a few
        pixels of the photo, whose texture passes the ridge test with its own small contrast:
        extended to the cube both ways, a photo pixel read as a blend of two far colours (the
        mixed probe's coffee under GEGL's levels: R's red 186-220 where F and the reference
        clip to 255). Text and lines drawn on a flat backing keep their extension (the other
        extreme is the backing), and so does ink that O shows. Measured, tuning half
        (``aarecovery.lab.mixed_probe``, 16 cases): graphics 0.622 -> 0.658, photo regions
        0.343 -> 0.382, the worst photo region -0.234 -> +0.042 (every case up or equal); the
        real-tools suite's tuning half, 26 cases moved, the poster's text under G'MIC's
        ``-pow 3`` -0.114 -> +0.234 (its extension crossed that curve's step at 6 levels), the
        poster's and screenshot's other text and graphics regions by -0.008 to +0.015, their
        photo regions by 0.000 to +0.010. On every O the same rule lost broadly (120 cases
        moved, 93 down; 76 of the 96 JPEG cases down, the maps at q 85 under G'MIC's threshold
        0.310 -> 0.172): a JPEG's drawn backing is seldom one of its flat colours.
        """
        return self.drawn_only and self.noise_contrast == 0

    @property
    def min_contrast(self):
        """float: the contrast below which two extremes are not a thin feature on its paper."""
        return max(MIN_CONTRAST, float(self.noise_contrast))

    def key_range(self):
        """Observed key range (bin centres of the first and last filled bins), each shape (3,)."""
        low = np.zeros(3, np.float32) if self.key_low is None else np.asarray(self.key_low, np.float32)
        high = np.ones(3, np.float32) if self.key_high is None else np.asarray(self.key_high, np.float32)
        return low, high

    @property
    def key_code(self):
        """int: the GL define ``TABLE_KEY`` (0 channel, 1 luma, 2 luma_scale, 3 luminance_scale,
        4 luminance, 5 luminance_d50, 6 luma601_shift, 7 luma601_floor_shift, 8 luma601,
        9 colour)."""
        return _KEY_CODES[self.key]

    def palette_in(self, blend_space):
        """The palette as opaque working-space colours, ndarray of float32, shape (N, 3)."""
        colour = self.palette.astype(np.float32)
        return srgb_to_linear(colour) if blend_space == "linear" else colour


def _table_at(column, keys):
    """Linear interpolation of a table column between bin centres ``(i + 0.5) / 256``."""
    position = np.clip(keys * np.float32(256) - np.float32(0.5), 0, 255).astype(np.float32)
    lower = np.minimum(np.floor(position).astype(np.intp), 254)
    fraction = position - lower.astype(np.float32)
    below, above = column[lower], column[lower + 1]
    return below + (above - below) * fraction


def colour_map_at(table, encoded):
    """A 3-D table of encoded colour read at encoded colours, trilinearly between bin centres
    ``(i + 0.5) / B`` (clamped at the outer ones).

    Parameters
    ----------
    table : ndarray of float32, shape (B, B, B, 3)
        Output colour per bin of (R, G, B).
    encoded : ndarray of float32, shape (..., 3)

    Returns
    -------
    ndarray of float32, shape (..., 3)
    """
    # The corners in this order, each weight a product over R, G, B: GL's colour_map_at
    # (transfer_table.glsl) sums them the same way.
    bins = table.shape[0]
    position = np.clip(encoded * np.float32(bins) - np.float32(0.5), 0, bins - 1).astype(np.float32)
    low = np.minimum(position.astype(np.intp), bins - 2)
    weight = (position - low).astype(np.float32)
    result = np.zeros(encoded.shape, np.float32)
    for corner in range(8):
        step = [(corner >> axis) & 1 for axis in range(3)]
        corner_weight = np.ones(encoded.shape[:-1], np.float32)
        for axis in range(3):
            corner_weight *= weight[..., axis] if step[axis] else np.float32(1) - weight[..., axis]
        value = table[low[..., 0] + step[0], low[..., 1] + step[1], low[..., 2] + step[2]]
        result += corner_weight[..., None] * value
    return result


def scale_transfer(encoded, key, table, keys=None):
    """A scale key's ``f``: map the luma (or luminance) by the table, scale colour with it.

    Parameters
    ----------
    encoded : ndarray of float32, shape (3, N)
        sRGB-encoded colour planes.
    key : {"luma_scale", "luminance_scale"}
    table : ndarray of float32, shape (256, 3)
        Column 0: the mapped luma (encoded) or luminance (linear) per bin.
    keys : ndarray of float32, shape (N,), optional
        The table key to read at, when it differs from the colour's own luma (clamped to
        O's range, see :func:`filtered_colour`).

    Returns
    -------
    ndarray of float32, shape (3, N)
        Encoded ``f(encoded)``, clipped to [0, 1].
    """
    values = srgb_to_linear(encoded.T).T if key == "luminance_scale" else encoded
    values = values.astype(np.float32)
    luma = values[0] * _LUMA[0] + values[1] * _LUMA[1] + values[2] * _LUMA[2]
    mapped = _table_at(table[:, 0], luma if keys is None else keys).astype(np.float32)
    lit = luma > np.float32(_SCALE_BLACK)
    ratio = mapped / np.where(lit, luma, np.float32(1))
    out = np.clip(np.where(lit, values * ratio, mapped), 0, 1).astype(np.float32)
    return (linear_to_srgb(out.T).T if key == "luminance_scale" else out).astype(np.float32)


def _encoded_of(colour, blend_space):
    alpha = colour[3]
    visible = alpha > 0
    straight = np.clip(colour[:3] / np.where(visible, alpha, np.float32(1)), 0, 1).astype(np.float32)
    return (linear_to_srgb(straight.T).T if blend_space == "linear" else straight).astype(np.float32)


def shift_grey(encoded, key):
    """A shift key's 8-bit Rec. 601 grey level of encoded colour planes ``(3, N)`` (or ``(3,
    ...)``), as its tool computes it from the 8-bit channels: float32 of whole numbers in
    [0, 255].

    ``luma601_shift``: OpenCV's, ``(4899 R + 9617 G + 1868 B + 8192) >> 14``;
    ``luma601_floor_shift``: Pillow's YCbCr, ``(round(19.136 R) + round(37.568 G) +
    round(7.296 B)) >> 6`` (each product's fraction is a multiple of 0.008, so no rounding
    is a tie).
    """
    levels = [np.floor(np.clip(encoded[c], 0, 1) * np.float32(255) + np.float32(0.5)) for c in range(3)]
    if key == "luma601_shift":
        r, g, b, scale = (np.float32(v) for v in _OPENCV_Y)
        grey = np.floor((levels[0] * r + levels[1] * g + levels[2] * b + scale / 2) / scale)
    else:
        r, g, b, scale = (np.float32(v) for v in _PILLOW_Y)
        half = np.float32(0.5)
        grey = np.floor((np.floor(levels[0] * r + half) + np.floor(levels[1] * g + half)
                         + np.floor(levels[2] * b + half)) / scale)
    return np.clip(grey, 0, 255).astype(np.float32)


def rec601_grey(encoded):
    """The 8-bit Rec. 601 grey level of encoded colour planes ``(3, ...)``, rounded: float32
    of whole numbers in [0, 255].

    The grey that OpenCV's colour maps, Pillow's ``convert("L")`` and ImageMagick's
    ``Rec601Luma`` index by (each to within a level at a tie), from the 8-bit channels in
    thousandths, ``(299 R + 587 G + 114 B + 500) // 1000``: whole numbers below 2^24, exact
    in float32 on both backends.
    """
    levels = [np.floor(np.clip(encoded[c], 0, 1) * np.float32(255) + np.float32(0.5)) for c in range(3)]
    r, g, b, scale = (np.float32(v) for v in _REC601_Y)
    grey = np.floor((levels[0] * r + levels[1] * g + levels[2] * b + scale / 2) / scale)
    return np.clip(grey, 0, 255).astype(np.float32)


def key_values(encoded, key):
    """The table keys of encoded colour planes ``(3, N)``: shape (3, N), one row per table
    column (luma, luminance, the scale and the shift keys repeat one value; a shift key's is
    its grey level's bin centre)."""
    if key in SHIFT_KEYS:
        return np.broadcast_to(((shift_grey(encoded, key) + np.float32(0.5)) / np.float32(256)).astype(np.float32),
                               encoded.shape)
    if key == "luma601":
        return np.broadcast_to(((rec601_grey(encoded) + np.float32(0.5)) / np.float32(256)).astype(np.float32),
                               encoded.shape)
    if key in LUMINANCE_KEYS:
        weights = LUMINANCE_KEYS[key]
        values = srgb_to_linear(encoded.T).T.astype(np.float32)
        luminance = values[0] * weights[0] + values[1] * weights[1] + values[2] * weights[2]
        return np.broadcast_to(linear_to_srgb(luminance), encoded.shape)
    if key in SCALE_KEYS:
        values = srgb_to_linear(encoded.T).T.astype(np.float32) if key == "luminance_scale" else encoded
        luma = values[0] * _LUMA[0] + values[1] * _LUMA[1] + values[2] * _LUMA[2]
        return np.broadcast_to(luma, encoded.shape)
    if key == "luma":
        return np.broadcast_to(encoded[0] * _LUMA[0] + encoded[1] * _LUMA[1] + encoded[2] * _LUMA[2],
                               encoded.shape)
    return encoded


def transfer_encoded(encoded, key, table, keys=None):
    """``f`` of encoded colour planes by a table: encoded too.

    Parameters
    ----------
    encoded : ndarray of float32, shape (3, N)
        sRGB-encoded colour planes.
    key : str
        One of :data:`EXTENSION_KEYS`.
    table : ndarray of float32, shape (256, 3), or (B, B, B, 3) for :data:`COLOUR_KEY`
        Encoded output colour per bin of the key (see :class:`PureColourPrior`).
    keys : ndarray of float32, shape (3, N), optional
        The table keys to read at (:func:`key_values`, perhaps clamped); default: the
        colour's own.

    Returns
    -------
    ndarray of float32, shape (3, N)
    """
    if key == COLOUR_KEY:
        return colour_map_at(table, np.ascontiguousarray(encoded.T)).T
    if keys is None:
        keys = key_values(encoded, key)
    if key in SCALE_KEYS:
        return scale_transfer(encoded, key, table, keys[0])
    if key in SHIFT_KEYS:
        return np.clip(encoded + _table_at(table[:, 0], keys[0]), 0, 1).astype(np.float32)
    return np.stack([_table_at(table[:, c], keys[c]) for c in range(3)]).astype(np.float32)


def filtered_colour(colour, prior, blend_space, low_end=None, high_end=None):
    """``f`` of working-space colours, by the prior's table.

    Parameters
    ----------
    colour : ndarray of float32, shape (4, N)
        Premultiplied working-space colours (channel planes).
    prior : PureColourPrior
    blend_space : {"linear", "srgb"}
    low_end, high_end : ndarray of bool, shape (3, N), optional
        Where to clamp the keys to O's key range from below / above (per table column).

    Returns
    -------
    ndarray of float32, shape (4, N)
        Premultiplied working-space ``f(colour)``, with the colour's own alpha.
    """
    alpha = colour[3]
    encoded = _encoded_of(colour, blend_space)
    keys = key_values(encoded, prior.key)
    if low_end is not None:
        low, high = prior.key_range()
        keys = np.where(low_end, np.maximum(keys, low[:, None]), keys)
        keys = np.where(high_end, np.minimum(keys, high[:, None]), keys).astype(np.float32)
    out = transfer_encoded(encoded, prior.key, prior.table, keys)
    decoded = srgb_to_linear(np.clip(out, 0, 1).T).T if blend_space == "linear" else out
    return np.concatenate([decoded * alpha, alpha[None]], axis=0).astype(np.float32)


#: An extreme whose key lies within this of an end of O's key range is read with the
#: table clamped there (see :class:`PureColourPrior`).
RANGE_TOLERANCE = 0.05
#: An extreme whose keys all lie within this of an end of O's key range is O's darkest or
#: brightest colour (see :func:`extend_extreme`).
END_TOLERANCE = 1.0 / 255


def is_flat_colour(colour, palette, prior):
    """bool ``(N,)``: `colour` is one of O's flat colours: within :data:`PALETTE_TOLERANCE` of a
    palette colour, or with the prior's `luma_purity`, its luma within that of one's.

    Parameters
    ----------
    colour : ndarray of float32, shape (4, N)
        Premultiplied working-space colours.
    palette : ndarray of float32, shape (P, 3)
        Opaque working-space flat colours.
    prior : PureColourPrior
    """
    flat = np.zeros(colour.shape[1:], bool)
    luma = np.float32(prior.luma_purity)
    for entry in palette:
        miss = colour[:3] - entry[:, None] * colour[3]
        flat |= miss[0] * miss[0] + miss[1] * miss[1] + miss[2] * miss[2] \
            < np.float32(PALETTE_TOLERANCE * PALETTE_TOLERANCE)
        if luma > 0:
            flat |= np.abs(miss[0] * LUMA_WEIGHTS[0] + miss[1] * LUMA_WEIGHTS[1] + miss[2] * LUMA_WEIGHTS[2]) < luma
    return flat


#: Rounding room of :func:`possible_ridges`: its bound leaves this much, on squared working-space
#: distances, to the float arithmetic of :func:`extend_extreme`'s line and ridge tests.
RIDGE_BOUND_SLACK = 1e-4


def possible_ridges(colours, floor=0.0):
    """bool ``(H, W)``: where :func:`extend_extreme` could find a ridge, whatever the other extreme.

    A necessary condition of its ridge test at pixel q, from O alone: an opposite pair of
    q's neighbours n1, n2 lies within :data:`LINE_TOLERANCE` of the line through the two
    extremes, and lower than q along it. With a = O(q) - O(n1) and b = O(q) - O(n2), each
    lies within that distance of the line's direction and points along it, so the angle
    between them is at most the sum of the angles each may make with the line:
    ``a . b >= sqrt(|a|^2 - L^2) sqrt(|b|^2 - L^2) - min(|a|, L) min(|b|, L)`` (the first
    product 0 where a side is within L), with neither a nor b zero, nor shorter than the
    ridge's noise margin (`floor`: both lie lower than q by more). A straight edge's
    neighbours across it (one brighter, one darker) fail it, and so do flat areas: on a
    4096 x 4096 pair of filled shapes and strokes, 0.3 % of the pixels pass, and the blocks
    within reach of them are a third of O's active ones. The GL backend fits pure colours only
    in O's blocks near such a pixel or near a change of F (``blocks.pure_colour_mask``):
    elsewhere the fit gives F exactly. Image borders pass nowhere, as in the ridge test.

    Parameters
    ----------
    colours : list of 9 ndarray of float32, shape (4, H, W)
        O's working-space neighbourhood (``aarecovery.spec.neighbourhood.neighbours``).
    floor : float
        :data:`RIDGE_NOISE_MARGIN` times the prior's ``ridge_noise`` (0 on a lossless O).

    Returns
    -------
    ndarray of bool, shape (H, W)
    """
    slack = np.float32(RIDGE_BOUND_SLACK)
    line_sq = np.float32(LINE_TOLERANCE) * np.float32(LINE_TOLERANCE) + slack
    zero = np.float32(0)
    floor_sq = np.float32(floor) * np.float32(floor)
    possible = np.zeros(colours[0].shape[1:], bool)
    for i, j in OPPOSITE_PAIRS:
        a, b = colours[0] - colours[i], colours[0] - colours[j]
        a_sq, b_sq = dot(a, a), dot(b, b)
        along = np.sqrt(np.maximum(a_sq - line_sq, zero)) * np.sqrt(np.maximum(b_sq - line_sq, zero))
        across = np.sqrt(np.minimum(a_sq, line_sq)) * np.sqrt(np.minimum(b_sq, line_sq))
        possible |= (a_sq > floor_sq) & (b_sq > floor_sq) & (a_sq > zero) & (b_sq > zero) \
            & (dot(a, b) >= along - across - slack)
    possible[0, :] = possible[-1, :] = False
    possible[:, 0] = possible[:, -1] = False
    return possible


def extend_extreme(far, near, around, filtered_far, on_border, palette, prior, blend_space, gate=None):
    """Decide whether an extreme colour is a thin feature's partial colour, and extend it.

    Parameters
    ----------
    far : ndarray of float32, shape (4, N)
        The extreme colour of O being tested (at pixel q).
    near : ndarray of float32, shape (4, N)
        The other extreme.
    around : list of 9 ndarray of float32, shape (4, N)
        O around q in ``NEIGHBOUR_OFFSETS`` order.
    filtered_far : ndarray of float32, shape (4, N)
        F at q.
    on_border : ndarray of bool, shape (N,)
        q lies on the image border.
    palette : ndarray of float32, shape (P, 3)
        Opaque working-space flat colours.
    prior : PureColourPrior
    blend_space : {"linear", "srgb"}
    gate : ndarray of float32, shape (N,), optional
        In [0, 1] at the fitted pixels (see :func:`fit_pure_colour_model`): the extension goes
        this share of the way from the extreme to its pure colour, none where 0. None: all
        the way.

    Returns
    -------
    extended : ndarray of bool, shape (N,)
    colour : ndarray of float32, shape (4, N)
        The pure colour: `far` extended to the colour cube where `extended`, else `far`.
    filtered : ndarray of float32, shape (4, N)
        ``f(colour)`` where `extended` (unused elsewhere).
    """
    span = far - near
    length = np.sqrt(dot(span, span))
    steps = np.abs(_encoded_of(far, blend_space) - _encoded_of(near, blend_space)).max(axis=0)
    defined = (length > np.float32(1e-6)) & (np.maximum(steps, np.abs(span[3])) >= np.float32(prior.min_contrast))
    direction = span / np.where(defined, length, np.float32(1))
    t_far = dot(far - near, direction)
    margin = np.maximum(np.float32(RIDGE_MARGIN) * length,
                        np.float32(RIDGE_NOISE_MARGIN) * np.float32(prior.ridge_noise))
    limit = t_far - margin
    reach_sq = np.float32(LINE_TOLERANCE * LINE_TOLERANCE)
    ink_reach_sq = np.float32(INK_LINE_TOLERANCE * INK_LINE_TOLERANCE)
    ridge = np.zeros(length.shape, bool)
    for i, j in OPPOSITE_PAIRS:
        first, second = around[i] - near, around[j] - near
        t_first, t_second = dot(first, direction), dot(second, direction)
        on_line = (dot(first, first) - t_first * t_first < reach_sq) & \
            (dot(second, second) - t_second * t_second < reach_sq)
        ridge |= on_line & (t_first < limit) & (t_second < limit)
    candidate = defined & ridge & ~on_border & ~is_flat_colour(far, palette, prior)
    # A fitted table must explain F at the observed extreme. Without one, F there must lie on
    # O's colour line (sharpening moves a thin feature along it; a hue change moves it off,
    # and the identity table would undo the change) and keep the feature's contrast (an
    # edge-aware smoothing that erased it meant to, and its reference has it erased too).
    if prior.explain_filtered:
        explained = filtered_colour(far, prior, blend_space)
        miss = np.abs(explained - filtered_far)[:3].max(axis=0)
        candidate &= miss < np.float32(EXPLAIN_TOLERANCE)
    else:
        moved = filtered_far - near
        along = dot(moved, direction)
        candidate &= (dot(moved, moved) - along * along < np.float32(ON_LINE_TOLERANCE * ON_LINE_TOLERANCE)) \
            & (along >= np.float32(KEPT_CONTRAST) * length)
    # Largest s >= 1 with near + s (far - near) inside the premultiplied colour cube:
    # 0 <= rgb <= alpha <= 1.
    reach = np.full(length.shape, np.float32(1e6))
    for c in range(4):
        step = span[c] - (span[3] if c < 3 else 0)
        room_up = (near[3] if c < 3 else np.float32(1)) - near[c]
        up = np.where(step > 1e-9, room_up / np.where(step > 1e-9, step, 1), np.float32(1e6))
        down = np.where(span[c] < -1e-9, -near[c] / np.where(span[c] < -1e-9, span[c], -1), np.float32(1e6))
        reach = np.minimum(reach, np.minimum(up, down))
    reach = np.maximum(reach, np.float32(1)).astype(np.float32)
    # A flat colour of O beyond the extreme, on its line, is the feature's ink, before the
    # cube: the ink of thin features is seen flat where they are thick (a star's centre, a
    # legend). Measured on the real-tools tuning half, drawings with PNG originals: mean
    # error reduction 0.488 -> 0.544 (levels 0.33 -> 0.64: dark-blue spokes were extended
    # to a black they never were); built-in quick suite +0.001 in both spaces.
    cube_reach = reach
    nearest = np.full(length.shape, np.float32(1e6))
    for colour in palette:
        ink = np.concatenate([colour, [np.float32(1)]])[:, None].astype(np.float32)
        offset = ink - near
        along = dot(offset, direction)
        off_line = dot(offset, offset) - along * along
        beyond = (along > t_far * np.float32(1 + RIDGE_MARGIN)) & (off_line < ink_reach_sq)
        nearest = np.where(beyond, np.minimum(nearest, along / np.where(defined, length, 1)), nearest)
    found = nearest < np.float32(1e5)
    reach = np.where(found, np.minimum(nearest, reach), reach).astype(np.float32)
    if not prior.to_cube:
        candidate &= found
    # A short reach is the ink itself, unless O shows the pure colour: a flat colour stopped
    # the extension, or the cube's point is one of O's inks.
    seen = found & (nearest <= cube_reach)
    if prior.inks is not None and len(prior.inks):
        pure = _encoded_of(near + reach * span, blend_space)
        for ink in np.asarray(prior.inks, np.float32):
            seen |= np.abs(pure - ink[:, None]).max(axis=0) <= np.float32(INK_TOLERANCE)
    candidate &= (reach > np.float32(MIN_REACH)) | (seen & (reach > np.float32(SHORT_REACH)))
    if gate is not None and prior.backed_or_seen:
        candidate &= is_flat_colour(near, palette, prior) | seen
    if gate is not None:
        candidate &= gate > 0
        reach = (np.float32(1) + gate * (reach - np.float32(1))).astype(np.float32)
    low_end = high_end = None
    if prior.key_low is not None:
        low, high = prior.key_range()
        far_keys = key_values(_encoded_of(far, blend_space), prior.key)
        tolerance = np.float32(RANGE_TOLERANCE)
        low_end = far_keys <= low[:, None] + tolerance
        high_end = far_keys >= high[:, None] - tolerance
        # O's darkest (brightest) colour is pure, a paper between thin lines rather than a
        # blend of unseen ink, unless the other extreme is O's opposite end or a flat colour:
        # then the window is a thin feature on its paper, and its darkest pixel may be the
        # darkest of the image (0.7 px black lines on white alone). Extending the dark paper
        # between 0.5 px white lines to black recovered the whole paper as a blend of f(black)
        # and f(white) (lines/sRGB: equalize 0.40, posterize 0.43, gamma 0.61).
        end = np.float32(END_TOLERANCE)
        near_keys = key_values(_encoded_of(near, blend_space), prior.key)
        near_pure = is_flat_colour(near, palette, prior)
        far_low = (far_keys <= low[:, None] + end).all(axis=0)
        far_high = (far_keys >= high[:, None] - end).all(axis=0)
        near_low = (near_keys <= low[:, None] + end).all(axis=0)
        near_high = (near_keys >= high[:, None] - end).all(axis=0)
        candidate &= ~((far_low & ~near_high | far_high & ~near_low) & ~near_pure)
    colour = np.where(candidate, near + reach * span, far).astype(np.float32)
    # At an end of O's range the extreme is read with the table clamped there: a dark paper
    # between thin white lines is O's darkest colour, not a blend of unseen ink.
    filtered = filtered_colour(colour, prior, blend_space, low_end, high_end)
    return candidate, colour, filtered



def fit_pure_colour_model(original, filtered, sigma_d, sigma_e, strength, prior, blend_space, gate=None, best=False):
    """``fit_blend_model`` with the pure colours of thin features (the safe default).

    For point-wise filters on hard-edged content (see the module notes for the rule and its
    measurements): an extreme that is a thin feature's partial colour is extended along the
    colour line to the colour cube, its filtered colour is taken from the filter's table, and alpha is measured against the extended colours. The edge
    strength uses O's gradient times the larger of F's gradient and the contrast of the
    two filtered extremes, since a thin feature that the filter erased from F (a light
    stroke thresholded away) leaves F flat where it must be restored; measured, this added
    0.05 to the quick suite's mean error reduction on linear-light scenes. O's gradient is
    the larger of its Sobel magnitude and its ridge magnitude (:data:`RIDGE_EDGE_SCALE`),
    so that a thin feature centred on a pixel has one.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 4)
        O and F in the working space.
    sigma_d, sigma_e, strength
        As for ``aarecovery.spec.blend_model.fit_paper_model``.
    prior : PureColourPrior
    blend_space : {"linear", "srgb"}
    gate : ndarray of float32, shape (H, W), optional
        For a prior that acts on drawn content only (:attr:`PureColourPrior.drawn_only`): the
        local plan's weight of the drawn regions, from 0 (a photo) to 1, smooth between. A
        partial colour is extended by that share of the way to its pure colour, so that the
        extension fades in with the weight and leaves no seam where the reading changes; at
        0 the model is the paper's (the edge strength too). None: the prior acts everywhere.
    best : bool
        Where the principal line misses the centre, a better pair of neighbours
        (``aarecovery.spec.blend_model.best_pair``), before the extremes are extended.

    Returns
    -------
    BlendModel
        With `pure_a`, `pure_b`, `fixed_a` and `fixed_b` set.
    """
    height, width = original.shape[:2]
    o_planes, f_planes = planes(original), planes(filtered)
    colours = neighbours(o_planes)
    f_colours = neighbours(f_planes)
    ridge = ridge_magnitude(colours) * np.float32(RIDGE_EDGE_SCALE)
    if gate is not None:
        ridge = ridge * np.asarray(gate, np.float32)
    original_gradient = np.maximum(sobel_magnitude(colours), ridge).astype(np.float32)
    filtered_gradient = sobel_magnitude(f_colours).astype(np.float32)
    shape = (height, width)
    alpha = np.full(shape, 0.5, np.float32)
    beta = np.zeros(shape, np.float32)
    residual = np.zeros(shape, np.float32)
    edge = np.zeros(shape, np.float32)
    index_a = np.zeros(shape, np.uint8)
    index_b = np.zeros(shape, np.uint8)
    pure_a = np.zeros(shape, bool)
    pure_b = np.zeros(shape, bool)
    fixed_a = np.zeros(shape + (4,), np.float32)
    fixed_b = np.zeros(shape + (4,), np.float32)
    pure_colour_a_map = np.zeros(shape + (4,), np.float32)
    pure_colour_b_map = np.zeros(shape + (4,), np.float32)
    # Where O is flat, e_p is 0 whatever F does: nothing to fit.
    fitted = original_gradient > 0
    if fitted.any():
        rows, cols = np.nonzero(fitted)
        columns = [colour[:, fitted] for colour in colours]
        col_alpha, col_residual, col_a, col_b, colour_a, colour_b = fit_extremes(columns, sigma_d, best)
        offsets = np.asarray(NEIGHBOUR_OFFSETS, dtype=np.int64)
        padded_o = np.pad(o_planes, ((0, 0), (2, 2), (2, 2)), mode="edge")
        palette = prior.palette_in(blend_space)
        if gate is not None:
            gate = np.asarray(gate, np.float32)[fitted]

        def at(values, pad, row, col):
            return values[:, np.clip(row, -pad, height - 1 + pad) + pad, np.clip(col, -pad, width - 1 + pad) + pad]

        def extend(index, far, near):
            q_row, q_col = rows + offsets[index, 0], cols + offsets[index, 1]
            border = (q_row <= 0) | (q_row >= height - 1) | (q_col <= 0) | (q_col >= width - 1)
            around = [at(padded_o, 2, q_row + dy, q_col + dx) for dy, dx in NEIGHBOUR_OFFSETS]
            filtered_far = f_planes[:, np.clip(q_row, 0, height - 1), np.clip(q_col, 0, width - 1)]
            extended, pure, fixed = extend_extreme(far, near, around, filtered_far, border, palette, prior,
                                                   blend_space, gate)
            return extended, pure, np.where(extended, fixed, filtered_far)

        extended_a, pure_colour_a, start_a = extend(col_a, colour_a, colour_b)
        extended_b, pure_colour_b, start_b = extend(col_b, colour_b, colour_a)
        either = extended_a | extended_b
        col_alpha = np.where(either, coverage(columns[0], pure_colour_a, pure_colour_b), col_alpha)
        contrast = np.sqrt(dot(start_a - start_b, start_a - start_b))
        if gate is not None:
            # Gated, the photo (gate 0) keeps the paper's edge strength, O's gradient times
            # F's: the filtered extremes' contrast raised it there, and with it the photo's
            # confidence, where no thin feature was restored (tuning half, poster under GEGL's
            # levels: its photo region's error reduction 0.012 without pure colours, -0.041
            # with them and this contrast ungated, 0.006 gated; measured with the first gate
            # tried, which also counted drawn ink).
            contrast = (contrast * gate).astype(np.float32)
        col_edge = (original_gradient[fitted] * np.maximum(filtered_gradient[fitted], contrast)).astype(np.float32)
        alpha[fitted] = col_alpha
        residual[fitted] = col_residual
        edge[fitted] = col_edge
        beta[fitted] = confidence(col_residual, col_edge, sigma_d, sigma_e, strength)
        index_a[fitted], index_b[fitted] = col_a, col_b
        pure_a[fitted], pure_b[fitted] = extended_a, extended_b
        fixed_a[fitted] = np.where(extended_a, start_a, 0).T
        fixed_b[fitted] = np.where(extended_b, start_b, 0).T
        pure_colour_a_map[fitted] = np.where(extended_a, pure_colour_a, 0).T
        pure_colour_b_map[fitted] = np.where(extended_b, pure_colour_b, 0).T
    return BlendModel(alpha, beta, index_a, index_b, residual, edge, pure_a, pure_b, fixed_a, fixed_b,
                      pure_colour_a_map, pure_colour_b_map)
