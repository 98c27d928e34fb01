"""Compression evidence: is O a decoded JPEG, where is its 8 x 8 block grid, how large is its noise?

A JPEG stores each 8 x 8 block (16 x 16 for chroma subsampled 4:2:0) as quantized DCT
coefficients, so its error has two properties the safe default needs:

* it stays **inside the block**: a block of one flat colour decodes flat (its only
  coefficient is the mean), and the ringing of an edge fills the block that holds the edge,
  up to 7 pixels from it, but no other block. The texture measure
  (:mod:`aarecovery.plan.texture`) reads grain only in blocks without an edge, where a
  drawing is flat and a photo keeps its texture;
  A block of a drawing without an edge is therefore flat in luma (within the decoder's
  rounding) however low the quality, while a photo's keeps its shading
  (:func:`quiet_block_grain`);
* it is **bounded by the quantization tables**: each coefficient is off by at most half its
  step, so a pixel's error has a standard deviation of about ``sqrt(mean(q^2) / 12)`` levels
  (:func:`noise_from_tables`). The pure colours of thin features ignore contrasts of that
  size (:mod:`aarecovery.plan.pure_colours`): a ringing pixel on the paper next to a letter
  is not a thin stroke to restore.

The evidence comes from the file where there is one (``aarecovery.io.jpeg`` reads the tables
of a JPEG, and only of a JPEG), else from the pixels: on the block grid, a JPEG's high frequencies are quantized to zero
(:func:`detect_block_grid`), and the steps of its low frequencies give the table's scale.
The grid's phase is always measured on the pixels, since the analysis reads a window that
need not start on the grid.
"""

from dataclasses import dataclass

import numpy as np

from ..colour import REC601_LUMA

__all__ = ["quiet_block_grain", "hidden_compression", "BLOCK_GRAIN_SHARE", "CompressionEvidence", "NO_COMPRESSION", "BLOCK", "noise_from_tables", "detect_block_grid",
           "compression_evidence", "GRID_MARGIN", "STANDARD_LUMA_TABLE",
           "NOISE_CONTRAST_SIGMAS", "MIN_NOISE_CONTRAST",
           "COMPRESSED_REPAIR_TO_ERROR", "COMPRESSED_SMOOTHED_STRENGTH", "COMPRESSED_SHARPENED_STRENGTH", "COMPRESSED_SHARPENED_BLEND_SPACE", "COMPRESSED_HARD_EDGED_BLEND_SPACE", "LOSSLESS_TEST_PHASES", "LOSSLESS_PHASE_GAP"]

#: Side of a JPEG block, in pixels of the luma plane.
BLOCK = 8
#: Share of O's edge-free blocks (on the grid) whose luma is not flat, above which a
#: compressed O is a photo. Measured on the real-tools tuning half's analysis windows (PNG
#: and JPEG q 75-98 alike): drawings 0.00-0.17 (serif 0.04-0.08, star burst 0.00-0.17),
#: photos 0.93-1.00; but photos at their camera's resolution (crops of the bundled photos
#: saved at q 75) 0.22-0.95: a uniform sky decodes flat. Hence the low bar, and at least 16
#: edge-free blocks (the maps' 5-7 blocks read 0.20-0.43 from their soft fills). At 768 px
#: the star burst at q 95 reads 0.20 and is kept F under an unsharp mask (the paper's method
#: gains 0.29 there): its grainy blocks share a 16 x 16 chroma MCU with an edge. Counting only
#: blocks whose whole MCU is edge-free (the least share over the four MCU alignments), the
#: tuning drawings at 768 px read 0.00-0.15 (star burst q 95 0.15, serif 0.00), the bundled
#: photos at their own size at q 75-90 0.28-1.00, but most 768 px photo and scan windows keep
#: fewer than 16 such blocks: measured, not taken (the star burst sits at the bar).
BLOCK_GRAIN_SHARE = 0.15
#: A lossless drawing that reads as textured (a comic's screentone) has flat edge-free blocks
#: at every phase of the grid, a JPEG only near its own, whose ringing the other phases cut
#: across. Where at least LOSSLESS_TEST_PHASES of the 64 phases hold 16 edge-free blocks, the
#: median phase's grainy share must exceed the least by LOSSLESS_PHASE_GAP for the flat blocks
#: to say JPEG (``hidden_compression``). Measured on the tuning half's drawings rendered at
#: 768 px (their 512 x 512 windows, 64 phases each), least / median share: PNG manga 0.00 /
#: 0.00, map 0.025 / 0.038, serif 0.016 / 0.063; JPEG (q 85-95) manga 0.00 / 0.10-0.11, map
#: 0.03 / 0.45-0.49, serif 0.14 / 0.34-0.45, star burst 0.075 / 0.83; a sparse screentone page
#: (tests/test_jpeg_evidence.py) 0.00 / 0.00 as a PNG, 0.00 / 0.028 and 0.024 at q 90 and 95,
#: 0.00 / 0.00 at q 98. Between the lossless 0.013 and the sparse JPEG's 0.024 (serif's PNG,
#: 0.047, still reads as compressed, as before the test). Of the 240 cases at 768 px (ten
#: tools, PNG and JPEG), one moved: the manga under OpenCV's bilateral filter, 0.51 -> 0.93 of
#: its edge error (its edges move towards O again). At 96 px 5-25 phases hold 16 blocks and
#: the gap does not separate (the star burst at q 98: 0.125 / 0.125): the least share alone
#: decides there, as before.
LOSSLESS_TEST_PHASES = 32
LOSSLESS_PHASE_GAP = 0.02
# A block spanning less than this in luma (8-bit levels) is flat: a flat block decodes to one
# value, and the colour conversion rounds it by a level or two.
_BLOCK_GRAIN_RANGE = 2.5
# A block spanning more than this holds an edge (and its ringing): it says nothing of grain.
_BLOCK_EDGE_RANGE = 24.0
# Fewer edge-free blocks than this leave the grain undecided (dense line art). Reading 4-15
# blocks (a share of at most 0.5 grainy makes a drawing) turned the maps into compressed
# drawings and lost on the tuning half (maps' JPEG twins 0.247 -> 0.235: the textured reading's
# local plan and ink gate serve them better; Pillow's YCbCr equalize -0.22).
_MIN_QUIET_BLOCKS = 16
#: The repair-to-error ratio (``aarecovery.plan.model_error``) a smoothing filter
#: (``aarecovery.plan.smoothing``) on compressed hard-edged content needs before it is
#: repaired at all: the model's error carried through the filter underestimates what the
#: filter does to the ringing there. Tuning half, JPEG drawings: G'MIC's bilateral on the
#: star burst (q 85) ratio 5.9 lost 0.14 dB. Set above the loss with a margin, not swept:
#: held out, every repaired case had a ratio over 100. A sharpening filter (an unsharp mask)
#: needs only :data:`~aarecovery.plan.model_error.MIN_REPAIR_TO_ERROR`: on the tuning half's
#: JPEG drawings it gained at every ratio from 5 up (the star burst 5.0 and 6.9: 0.60 and 0.28
#: of its edge error; serif 13-20: 0.20-0.66), and the bar kept F on the star burst; below
#: it a sharpening filter runs at :data:`COMPRESSED_SHARPENED_STRENGTH`.
COMPRESSED_REPAIR_TO_ERROR = 10.0
#: The strength under a smoothing filter (``aarecovery.plan.smoothing``) on hard-edged
#: content from a JPEG, without pure colours: the filter spreads the compression noise over
#: the edges. Tuning half, maps, serif, icons, star burst and manga under G'MIC's and OpenCV's
#: bilateral filters and OpenCV's edge-preserving smoothing (60 cases, PNG and JPEG): at full
#: strength (0.75 with pure colours where flat colours are kept) 2 cases worse than F by over
#: 0.1 dB (serif under OpenCV's smoothing at q 75: 0.91 dB); 0.75: 1 (0.34 dB); 0.5: none.
COMPRESSED_SMOOTHED_STRENGTH = 0.5
#: The space a smoothing filter's repair blends in on hard-edged colour content from a JPEG
#: (not from linear-light input, not on a grey image), at :data:`COMPRESSED_SMOOTHED_STRENGTH`,
#: as under point-wise and sharpening filters: the JPEG averaged the encoded values across the
#: edges. Tuning half, the three cases this reading takes (serif under OpenCV's smoothing at
#: q 75 and 90, G'MIC's bilateral at q 98): 0.025 -> 0.077, 0.158 -> 0.227, 0.198 -> 0.256 of
#: the edge error; held out, no case takes it.
COMPRESSED_SMOOTHED_BLEND_SPACE = "srgb"
#: The strength under a sharpening filter (an unsharp mask, detail enhancement) on hard-edged
#: content from a JPEG whose repair-to-error ratio is below :data:`COMPRESSED_REPAIR_TO_ERROR`:
#: the filter sharpens the ringing beside the edges with them, and the pure colours' repair
#: lays the model's error over it. Tuning half, maps, serif, icons, star burst and manga under
#: GEGL's and ImageMagick's unsharp masks from JPEGs (q 75-98; 18 cases reach it, the star
#: burst at 96 px, the maps at 768 px), mean edge error reduction at full strength 0.323 (the
#: sRGB maps at 768 px worse than F by 0.10-0.42 dB), 0.75: 0.420, 0.5: 0.441 (least 0.247).
#: Above the ratio full strength did better on most (serif and manga, 96 and 768 px: 0.75
#: lower on 25 of 30 cases; higher on 3 of serif's 4 at 768 px, by 0.010-0.029).
COMPRESSED_SHARPENED_STRENGTH = 0.5
#: The space a sharpening filter's repair blends in on hard-edged content from a JPEG (not
#: from linear-light input, not on a coarse paper grain: ``paper_grain``), whatever space
#: O's colour lines told: the compression's noise and ringing lie in the encoded values,
#: and the filter sharpens them there. Tuning half, drawings under GEGL's and ImageMagick's
#: unsharp masks from JPEGs (q 75-98), the cases it moved: 96 px 0.513 -> 0.519 (24 cases:
#: manga up to +0.30, serif down to -0.26), 768 px 0.536 -> 0.626 (25: serif +0.09 to
#: +0.23, manga +0.03 to +0.36, maps -0.15 to +0.07); none worse than F. Held out (chosen
#: before they were run): 96 px, 12 families under G'MIC's and Pillow's unsharp masks and
#: OpenCV's detail enhancement, 10 cases moved, 0.547 -> 0.709, every one up; 768 px, the
#: hatching, comic strip, pie charts and plots under Pillow's unsharp mask and OpenCV's
#: detail enhancement, 8 cases, 0.313 -> 0.498, every one up.
COMPRESSED_SHARPENED_BLEND_SPACE = "srgb"
#: A point-wise filter on hard-edged colour content from a JPEG (not linear-light input) blends
#: in sRGB values whatever O's colour lines told: a JPEG's quantized DCT and its 4:2:0 chroma
#: average the encoded values across an edge, so its edge pixels are blends of encoded colour
#: (a grey JPEG has no chroma to average: its manga pages lost 0.17 in summed reduction). The
#: calibration and the pure colours still read O's colour lines in their own space (calibrated
#: in sRGB values too, the serif page under Pillow's autocontrast at q 90 fell 0.315 -> 0).
#: Tuning half, the 49 cases it moved: 0.430 -> 0.533 of the edge error, 37 up (the serif
#: page under OpenCV's JET at q 95 0.237 -> 0.851, under Pillow's solarize at q 85 0.244 ->
#: 0.648), 9 down (the star burst in linear light at q 98, up to 0.21 under JET), none worse
#: than F; JPEG share of the PNG gain 0.53 -> 0.55. Held out, run after the choice: 35 moved,
#: 0.499 -> 0.506, 20 up and 15 down (drawings antialiased in linear light, down to -0.21).
COMPRESSED_HARD_EDGED_BLEND_SPACE = "srgb"
#: Extremes closer than this many standard deviations of the compression noise are not a
#: thin feature and its paper (``PureColourPrior.noise_contrast``). Measured on JPEG scans of
#: text on tinted paper thresholded at 55 % (256 x 256 pages, 40 px margins), F's background
#: pixels (5 x 5 all white) made darker by more than 10 levels: with the contrast's floor of
#: 8.5 levels alone, 4 pages each at q 75 / 85 / 95: 9550 / 7686 / 234; 5 deviations (49 /
#: 29 / 9.7 levels) 5 / 71 / 207; on the two worst pages at q 85 / 95, 5 deviations 71 / 207,
#: 7 deviations 0 / 2, 9: 0 / 0. The real-tools quick tuning half did not move at 5.
NOISE_CONTRAST_SIGMAS = 7.0
#: The least contrast a compressed O's extremes need: ringing next to a letter does not shrink
#: with the noise's deviation as fast as the tables do. At q 95 (1.9 levels, 7 deviations
#: 13.6 levels) 3 of 8 pages (192 x 192, tinted and textured paper) kept 1-12 darkened
#: bare-paper pixels; at 20 levels none (nor at 10 deviations). Half a level above, as
#: ``spec.pure_colours.MIN_CONTRAST``: at exactly 20 levels 8-bit extremes tied with it, and
#: where the pixels' noise estimate fell to this floor GL and NumPy decided those ties apart
#: (a thresholded page saved at q 90, 128 x 128: 20 pixels up to 38 levels apart).
MIN_NOISE_CONTRAST = 20.5 / 255
#: The share of zero high-frequency coefficients at the best grid phase over that at the
#: second best, above which the pixels show a block grid (see :func:`detect_block_grid`).
#: Measured on the real-tools quick suite's analysis windows: PNG originals 0.000-0.055
#: (the star burst's symmetric spokes), JPEG q 85 0.15-0.39, q 95 0.10-0.32 but the star
#: burst's 0.036 (undetected: at q 95 its noise is below a level).
GRID_MARGIN = 0.08
# A block takes part when some AC coefficient exceeds this (8-bit levels, orthonormal DCT):
# flat blocks are all zeros at every phase and say nothing.
_BUSY_COEFFICIENT = 8.0
# A coefficient counts as zero within this (the decoder's rounding to 8 bits and the colour
# conversion leave about 0.3).
_ZERO_COEFFICIENT = 0.75
# Fewer busy blocks than this leave the grid undecided.
_MIN_BUSY_BLOCKS = 8
# Frequencies whose quantization step the grid path estimates, and the steps it tries.
_PROBED = ((0, 1), (1, 0), (1, 1), (0, 2), (2, 0))
_STEPS = np.arange(1, 64)
_LATTICE_SCORE = 0.6
# Steps of 1-2 levels (quality 95 and up) fit every lattice within the decoder's rounding and
# cannot be measured: a grid without a measured step gets quality 95's table (libjpeg's scale
# 0.1), the smallest noise the grid test detects.
_SMALLEST_SCALE = 0.1
#: The luma quantization table of the JPEG standard (ITU-T T.81, Annex K), which libjpeg
#: scales by the quality setting: the grid path scales it to the steps it measures.
STANDARD_LUMA_TABLE = np.array([
    16, 11, 10, 16, 24, 40, 51, 61, 12, 12, 14, 19, 26, 58, 60, 55,
    14, 13, 16, 24, 40, 57, 69, 56, 14, 17, 22, 29, 51, 87, 80, 62,
    18, 22, 37, 56, 68, 109, 103, 77, 24, 35, 55, 64, 81, 104, 113, 92,
    49, 64, 78, 87, 103, 121, 120, 101, 72, 92, 95, 98, 112, 100, 103, 99], np.float64).reshape(BLOCK, BLOCK)
_INDEX = np.arange(BLOCK)
_DCT = np.sqrt(2.0 / BLOCK) * np.cos(np.pi * (2 * _INDEX[None, :] + 1) * _INDEX[:, None] / (2 * BLOCK))
_DCT[0] /= np.sqrt(2.0)


@dataclass(frozen=True)
class CompressionEvidence:
    """What O's pixels or file say about block compression.

    Attributes
    ----------
    source : {"none", "quantization tables", "block grid", "flat blocks"}
        Where the evidence came from; "none": O shows no compression; "flat blocks": no grid
        was found, but the pixels' grain lies only in blocks that hold an edge
        (:func:`hidden_compression`).
    noise : float
        Standard deviation of the compression error per pixel, encoded values in [0, 1];
        0 without compression.
    phase : tuple of int
        ``(row, column)`` of the first block's top-left corner in the analysed window.
    margin : float
        How clearly the grid stands out (:func:`detect_block_grid`; 0 without one).
    """

    source: str = "none"
    noise: float = 0.0
    phase: tuple = (0, 0)
    margin: float = 0.0

    @property
    def compressed(self):
        """bool: O carries block-compression noise."""
        return self.source != "none"

    @property
    def contrast(self):
        """float: the contrast two extremes need to be told from this noise (encoded); 0 uncompressed."""
        if not self.compressed:
            return 0.0
        return max(NOISE_CONTRAST_SIGMAS * self.noise, MIN_NOISE_CONTRAST)

    def describe(self):
        """A few words for the plan's reason."""
        if not self.compressed:
            return "no compression"
        return f"JPEG ({self.source}, noise {self.noise * 255:.1f} levels)"


#: O as a lossless file or an array without a block grid.
NO_COMPRESSION = CompressionEvidence()


def noise_from_tables(tables):
    """The per-pixel standard deviation of the error the quantization tables allow.

    Each coefficient's rounding error is uniform within its step ``q`` (variance
    ``q^2 / 12``); the 8 x 8 DCT is orthonormal, so a pixel's error variance is the mean of
    those over the 64 coefficients. The luma table (the first) decides: threshold and
    levels key on luma, and chroma error is blurred by the subsampling. It is a bound: where
    a coefficient is smaller than half its step the error is the coefficient itself.

    Parameters
    ----------
    tables : sequence of sequence of int
        Quantization tables, 64 steps each, luma first (8-bit levels).

    Returns
    -------
    float
        Encoded values in [0, 1].
    """
    luma = np.asarray(tables[0], np.float64).reshape(-1)
    if luma.size != BLOCK * BLOCK:
        raise ValueError(f"a quantization table has 64 steps, got {luma.size}")
    return float(np.sqrt(np.mean(luma * luma) / 12.0) / 255.0)


def _column_transforms(luma, row):
    """The first half of the 8 x 8 DCTs at a row phase: each block row's columns, shape (rows, 8, W).

    The grid search shares it between the 8 column phases of a row phase: the same products
    as the whole DCT, bit for bit, and the search over a 512 x 512 window took 95 ms of CPU
    before, 50 ms with it and the faster :func:`_busy` (measured).
    """
    rows = (luma.shape[0] - row) // BLOCK
    return _DCT @ luma[row:row + rows * BLOCK].reshape(rows, BLOCK, luma.shape[1])


def _block_dct(luma, row, column, columns_done=None, only=None):
    """Orthonormal 8 x 8 DCTs of the blocks of a grid at a phase, shape (N, 8, 8).

    `columns_done`: :func:`_column_transforms` of `luma` at `row`, where already computed.
    `only`: bool, shape (block rows, block columns): the blocks to transform (N of them, in
    row order), each to the same values as among all of them.
    """
    half = _column_transforms(luma, row) if columns_done is None else columns_done
    rows, columns = half.shape[0], (half.shape[2] - column) // BLOCK
    blocks = half[:, :, column:column + columns * BLOCK].reshape(rows, BLOCK, columns, BLOCK).transpose(0, 2, 1, 3)
    blocks = blocks[only] if only is not None else np.ascontiguousarray(blocks)
    # One product of all the blocks' rows, not a stack of 8 x 8 ones: the same values, bit
    # for bit (tests/test_exact_speedups.py), in 0.97 ms against 2.22 ms a phase on a noisy
    # 512 x 512 window, whose grid search transforms every block at all 64 phases (the photo
    # bench pair's window: the search 0.25-0.32 -> 0.16-0.21 s, fastest of 7 runs, two
    # processes of each in turn on a loaded 2-core Xeon).
    return (blocks.reshape(-1, BLOCK) @ _DCT.T).reshape(-1, BLOCK, BLOCK)


#: The share of a phase's blocks that may be busy (:func:`_may_be_busy`) below which the grid
#: search transforms those only: a photo's 61% took 0.133 s against 0.119 s for all of them.
_GATHERED_SHARE = 0.5


def _summed_areas(luma):
    """Summed-area tables of `luma` and of its square, shape (H + 1, W + 1), float64: every
    block's sum and sum of squares in four reads (:func:`_may_be_busy`)."""
    sums = np.zeros((luma.shape[0] + 1, luma.shape[1] + 1))
    squares = np.zeros_like(sums)
    np.cumsum(np.cumsum(luma, axis=0), axis=1, out=sums[1:, 1:])
    np.cumsum(np.cumsum(luma * luma, axis=0), axis=1, out=squares[1:, 1:])
    return sums, squares


def _may_be_busy(sums, squares, row, column):
    """bool, shape (block rows, block columns): the blocks of the grid at a phase that can hold
    an AC coefficient above :data:`_BUSY_COEFFICIENT`; every other block is not busy.

    The AC coefficients of an orthonormal DCT are the block's deviations from its mean in an
    orthonormal basis, so together their squares are the deviations' (Parseval) and none
    exceeds their root sum of squares: a block whose deviations' root sum of squares is at most
    the busy level has no busy coefficient. On a drawing most blocks are flat or nearly so, and
    the grid search transforms the rest only (a thresholded drawing's 512 x 512 window: 17-26%
    of the blocks at a phase, the search 0.22 -> 0.07 s on a slow 2-core machine, separate
    processes in turn; a noisy photo's 61%, all transformed: :data:`_GATHERED_SHARE`). The
    bound has a sixteenth of a level to spare for the tables' rounding: a block near it is
    transformed, as before.
    """
    rows, columns = (sums.shape[0] - 1 - row) // BLOCK, (sums.shape[1] - 1 - column) // BLOCK
    edges_y = np.arange(rows + 1) * BLOCK + row
    edges_x = np.arange(columns + 1) * BLOCK + column

    def block_totals(table):
        corners = table[np.ix_(edges_y, edges_x)]
        return corners[1:, 1:] - corners[:-1, 1:] - corners[1:, :-1] + corners[:-1, :-1]

    total = block_totals(sums)
    deviations = block_totals(squares) - total * total / (BLOCK * BLOCK)
    return deviations > (_BUSY_COEFFICIENT - 1.0 / 16) ** 2


def _busy(coefficients):
    """Blocks with an AC coefficient above :data:`_BUSY_COEFFICIENT`, shape (N,).

    The 64 flags of a block are read as 8 machine words and OR-ed: NumPy's reduction over a
    short last axis cost 3x as much (measured).
    """
    large = np.abs(coefficients) > _BUSY_COEFFICIENT
    large[:, 0, 0] = False
    words = np.ascontiguousarray(large).view(np.uint64).reshape(len(large), BLOCK)
    any_large = words[:, 0]
    for word in range(1, BLOCK):
        any_large = any_large | words[:, word]
    return any_large != 0


def detect_block_grid(encoded):
    """Find an 8 x 8 block grid in O's pixels, and the quantization that made it.

    On the grid, a JPEG's busy blocks (those with some detail) have most high-frequency
    coefficients exactly zero: quantization removed them. Shifted off the grid, the blocks
    straddle the old boundaries and those coefficients are not zero; a lossless image has no
    phase where they vanish more than at its neighbours.

    Parameters
    ----------
    encoded : ndarray of float32, shape (H, W, 3)
        O's encoded colour (the analysis window).

    Returns
    -------
    phase : tuple of int
        ``(row, column)`` offset of the grid in the window.
    margin : float
        Share of zero high-frequency coefficients at the best phase minus that at the second
        best (0 when undecided).
    table : ndarray of float64, shape (8, 8) or None
        The standard luma table scaled to the steps measured at low frequencies on the grid
        (None when undecided: a margin under :data:`GRID_MARGIN`).
    """
    luma = _luma(encoded)
    if min(luma.shape) < 2 * BLOCK:
        return (0, 0), 0.0, None
    shares = np.full((BLOCK, BLOCK), -1.0)
    sums, squares = _summed_areas(luma)
    for row in range(BLOCK):
        columns_done = _column_transforms(luma, row)
        for column in range(BLOCK):
            candidates = _may_be_busy(sums, squares, row, column)
            # Gathering most of the blocks costs more than transforming them all.
            coefficients = _block_dct(luma, row, column, columns_done,
                                      only=candidates if candidates.mean() < _GATHERED_SHARE else None)
            busy = _busy(coefficients)
            if busy.sum() >= _MIN_BUSY_BLOCKS:
                shares[row, column] = float((np.abs(coefficients[busy][:, 3:, 3:]) < _ZERO_COEFFICIENT).mean())
    order = np.argsort(shares.ravel())
    if shares.ravel()[order[-1]] < 0:
        return (0, 0), 0.0, None
    phase = tuple(int(i) for i in np.unravel_index(order[-1], shares.shape))
    margin = float(shares.ravel()[order[-1]] - max(shares.ravel()[order[-2]], 0.0))
    if margin < GRID_MARGIN:
        # Undecided, and no caller reads a table then: measuring it took 38 of a noisy
        # photo window's 243 ms here (slow 2-core Xeon, one process).
        return phase, margin, None
    return phase, margin, _measured_table(_block_dct(luma, *phase))


def _measured_table(coefficients):
    """The standard table scaled to the quantization steps of a few low frequencies.

    A coefficient quantized with step q is a multiple of q (within the decoder's rounding):
    the largest step whose lattice the nonzero coefficients fit is the step.
    """
    coefficients = coefficients[_busy(coefficients)]
    scales = []
    for u, v in _PROBED:
        values = coefficients[:, u, v]
        values = values[np.abs(values) > 1.5]
        if values.size < _MIN_BUSY_BLOCKS:
            continue
        scores = np.cos(2 * np.pi * values[None, :] / _STEPS[:, None]).mean(axis=1)
        fitting = _STEPS[scores > _LATTICE_SCORE]
        if fitting.size:
            scales.append(fitting.max() / STANDARD_LUMA_TABLE[u, v])
    scale = float(np.median(scales)) if scales else _SMALLEST_SCALE
    return np.clip(np.rint(STANDARD_LUMA_TABLE * max(scale, _SMALLEST_SCALE)), 1, 255)


def quiet_block_grain(encoded, evidence):
    """Share of O's edge-free blocks that are not flat in luma: grain that compression kept.

    JPEG noise stays inside the blocks that hold an edge, so away from them a decoded
    drawing is flat; the pixel-wise grain (``aarecovery.plan.texture.grain``) reads the
    ringing near edges as texture (JPEG drawings 0.15-0.98).

    Parameters
    ----------
    encoded : ndarray of float32, shape (H, W, 3)
        O's encoded colour (the analysis window).
    evidence : CompressionEvidence
        Its grid (``phase``).

    Returns
    -------
    float or None
        None when fewer than 16 blocks are free of edges.
    """
    return _block_grain_at(_luma(encoded), *evidence.phase)


def _luma(encoded):
    return encoded[..., :3].astype(np.float64) @ np.array(REC601_LUMA) * 255.0


def _block_grain_at(luma, row, column):
    """:func:`quiet_block_grain` of the grid at one phase, on O's luma in 8-bit levels."""
    rows, columns = (luma.shape[0] - row) // BLOCK, (luma.shape[1] - column) // BLOCK
    blocks = luma[row:row + rows * BLOCK, column:column + columns * BLOCK]
    blocks = blocks.reshape(rows, BLOCK, columns, BLOCK).transpose(0, 2, 1, 3).reshape(-1, BLOCK * BLOCK)
    spans = blocks.max(axis=1) - blocks.min(axis=1) if len(blocks) else np.zeros(0)
    quiet = spans[spans < _BLOCK_EDGE_RANGE]
    if quiet.size < _MIN_QUIET_BLOCKS:
        return None
    return float((quiet > _BLOCK_GRAIN_RANGE).mean())


def _block_spans(luma):
    """The luma span (max - min) of the 8 x 8 block whose top-left pixel is at each position
    where one fits, shape ``(H - 7, W - 7)``: every phase's blocks at once, by running extremes
    over 2, 4 and 8 rows, then columns (the same values as each block's own max - min: 64
    phases of block copies took 42 ms on a 512 x 512 window, this 2.4)."""
    brightest, darkest = luma, luma
    for axis in (0, 1):
        for step in (1, 2, 4):
            length = brightest.shape[axis] - step
            ahead = (slice(None),) * axis + (slice(step, None),)
            here = (slice(None),) * axis + (slice(0, length),)
            brightest = np.maximum(brightest[here], brightest[ahead])
            darkest = np.minimum(darkest[here], darkest[ahead])
    return brightest - darkest


def _grain_of_spans(spans):
    """:func:`_block_grain_at` from the blocks' spans."""
    spans = spans.reshape(-1)
    quiet = spans[spans < _BLOCK_EDGE_RANGE]
    if quiet.size < _MIN_QUIET_BLOCKS:
        return None
    return float((quiet > _BLOCK_GRAIN_RANGE).mean())


def hidden_compression(encoded):
    """Evidence of a JPEG whose grid the pixels did not show: flat edge-free blocks at some phase.

    At q 90-98 a JPEG's high frequencies are not all quantized to zero and its grid can go
    undetected (:data:`GRID_MARGIN`), while the ringing around its edges still reads as grain
    in the pixels (``aarecovery.plan.texture.grain``). The edge-free blocks of the grid's phase
    are still flat, and those of a photo are not at any phase: the phase with the fewest
    grainy blocks is taken, so that the grid's phase need not be known. Tuning half's
    windows, PNG and JPEG q 75-98, the least share over the 64 phases (at least 16 edge-free
    blocks): serif 0.00-0.05, the star burst 0.00-0.17; the camera's portrait, coffee,
    Hubble and the screenshot 0.94-1.00 (the maps, icons, manga, handwriting, poster and
    scans have fewer than 16 at this size).
    The caller asks only where O read as textured and no grid was seen in its pixels (no
    evidence of compression, or a JPEG file's tables, which give the noise but not the
    phase): a lossless drawing has flat blocks too, and reads as hard-edged before.

    Parameters
    ----------
    encoded : ndarray of float32, shape (H, W, 3)
        O's encoded colour (the analysis window).

    Returns
    -------
    CompressionEvidence
        Source "flat blocks" at the flattest phase, with the noise of the smallest table the
        grid path assumes (q 95's); :data:`NO_COMPRESSION` when no phase has
        :data:`BLOCK_GRAIN_SHARE` or fewer grainy edge-free blocks among at least 16, or
        when the phases are flat alike (:data:`LOSSLESS_PHASE_GAP`).
    """
    spans = _block_spans(_luma(encoded))
    best, phase, shares = None, (0, 0), []
    for row in range(BLOCK):
        for column in range(BLOCK):
            share = _grain_of_spans(spans[row::BLOCK, column::BLOCK])
            if share is not None:
                shares.append(share)
                if best is None or share < best:
                    best, phase = share, (row, column)
    if best is None or best > BLOCK_GRAIN_SHARE:
        return NO_COMPRESSION
    if len(shares) >= LOSSLESS_TEST_PHASES and np.median(shares) < best + LOSSLESS_PHASE_GAP:
        return NO_COMPRESSION
    table = np.clip(np.rint(STANDARD_LUMA_TABLE * _SMALLEST_SCALE), 1, 255)
    return CompressionEvidence("flat blocks", noise_from_tables([table]), phase)


def compression_evidence(encoded, tables=None):
    """The compression evidence for O's analysis window.

    Parameters
    ----------
    encoded : ndarray of float32, shape (H, W, 3)
        O's encoded colour (the analysis window).
    tables : sequence of sequence of int, optional
        The quantization tables of O's JPEG file (``aarecovery.io.jpeg``); None for an
        array or a lossless file, whose pixels are searched for a block grid.

    Returns
    -------
    CompressionEvidence
    """
    phase, margin, measured = detect_block_grid(encoded)
    if tables is not None:
        return CompressionEvidence("quantization tables", noise_from_tables(tables), phase, margin)
    if margin < GRID_MARGIN:
        return CompressionEvidence(margin=margin)
    return CompressionEvidence("block grid", noise_from_tables([measured]), phase, margin)
