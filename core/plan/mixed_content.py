"""Text and drawings over a photo under a neighbourhood filter: repair the drawing, keep the photo.

A filter that is neither point-wise nor a colour map (an unsharp mask, a bilateral or
edge-preserving smoothing) cannot be simulated, so on a photo F is kept: the model would
flatten its texture. A poster, a slide or a screenshot is a photo with text, logos and
interface chrome drawn over it, and the drawn part is hard-edged content, which such
filters damage and the model repairs (``analysis``'s neighbourhood branch for drawings).
The local plan (``aarecovery.spec.local_plan``) tells the two apart per pixel; with a
textured strength of 0 it keeps F in the photo and repairs where O is drawn.

Whether a textured window holds drawn content at all is read from the same evidence: the
share of its edge pixels whose local factor reads as drawn. Measured on the real-tools
suite's tuning half, every case that kept F under a neighbourhood filter (113): the mixed
scenes with PNG originals 0.21 (poster) and 0.27 (screenshot); every photo, drawing read
as textured and JPEG original (whose compression leaves no exactly flat pixel) at most
0.025 (the camera photo 0.024, serif as JPEG 0.025). At :data:`MIXED_DRAWN_SHARE`, tuning
half: the ten mixed cases under the five neighbourhood filters gained 0.05-0.26 of their
edge error (kept F before), their text and graphics 0.15-0.32, their photo regions -0.009 to
+0.02 (within 0.04 dB of F); no other case moved; every mixed case's text and graphics
0.276 -> 0.339, whole edge band 0.251 -> 0.290.
Held out (not used to choose): text and graphics 0.286 -> 0.333, whole band 0.232 -> 0.260,
the banner's photo regions -0.013 to +0.0003, and the plots as high-quality JPEGs, whose
flat areas survive, gained 0.002-0.165; no case lost.

Where the filter keeps flat colours (``aarecovery.plan.flat_colours``), thin features in the
drawn regions also get their pure colours, gated by the local plan's regions' weight
(``aarecovery.spec.pure_colours.PureColourPrior.drawn_only``); ``analysis`` has the figures.
A window with (almost) no drawn region gets no such prior (:func:`drawn_only`): the prior's
passes run over O's every active block, and on a photo, whose edges cover it, they took the
4096 x 4096 bench photo's tiles from 1.2 to 4.5 s (llvmpipe) to change one pixel by one level.
"""

import dataclasses

import numpy as np

from ..spec.local_plan import FLAT_SPAN, LocalStrength, ink_weight_at

__all__ = ["drawn_at", "drawn_share", "drawn_only", "MIXED_DRAWN_SHARE", "DRAWN_REGION_SHARE", "COMPRESSED_INK_SPAN"]

#: The share of a textured window's edge pixels that must read as drawn for its drawn
#: regions to be repaired under a neighbourhood filter (F kept in the photo): between the
#: tuning half's photos (at most 0.025) and its mixed scenes (0.21 and more).
MIXED_DRAWN_SHARE = 0.1

#: The share of a textured window's edge pixels where a prior that acts on drawn regions
#: only would act (``LocalStrength.region_weight`` above 0, or the drawn ink with an ink
#: gate) below which it is not made: it would change next to nothing and cost the prior's
#: passes everywhere. The 4096 x 4096 bench photo's window reads 0 (with the ink too). The
#: ink is read here with the strength's test (``ink_weight_at``: three recurrences, from 0.3
#: of the ink), stricter than the gate's own (``INK_GATE_REPEATS``, ``INK_GATE_SHARE_LOW``):
#: which pairs get the prior did not change when the gate widened.
DRAWN_REGION_SHARE = 0.01

#: Within what a JPEG original's drawn ink recurs, for the gate of pure colours
#: (``PureColourPrior.ink_span``; encoded). A JPEG leaves no colour exactly where it was, so the
#: 8-bit test (:data:`~aarecovery.spec.local_plan.FLAT_SPAN`) found almost no ink on a
#: compressed image, and the drawings the texture test reads as textured (maps, icons, the star
#: burst as JPEGs) and the mixed scenes got no pure colours on their thin features. The prior's
#: own guards against the compression noise (``noise_contrast``, ``ridge_noise``) keep them off
#: a photo's grain, which at this span reads as ink too (the JPEG photos' windows: 0.23-0.65 of
#: their edge pixels, 0.00-0.03 at the 8-bit span). Tuning half, JPEG originals (q 85 and 95)
#: under the 15 point-wise filters, mean edge-band error reduction at 0.5 (the 8-bit span) / 2.5
#: / 3.5 / 4.5 levels: maps 0.168 / 0.230 / 0.277 / 0.291, the mixed scenes' text and graphics
#: 0.244 / 0.296 / 0.325 / 0.338 and photo regions 0.231 / 0.225 / 0.221 / 0.222 (the least
#: -0.004 / -0.011 / -0.101 / -0.121), the space photo 0.162 / 0.171 / 0.186 / 0.188; the memo
#: page under G'MIC's equalize at q 95 22 / 86 / 132 / 132 paper pixels darker than F (its
#: grain, which the filter amplified and the reference keeps: at 2.5, 83% of those pixels end
#: closer to the reference than F's, 11.5 against 13.5 levels); from 3.5 the space photo under
#: Pillow's autocontrast (q 95) lost 0.13-0.14 dB against F. At 3.0: maps 0.277, text and
#: graphics 0.324, but a photo region 0.099 of its error below F (the screenshot under OpenCV's
#: gamma at q 95, its whole band 0.386 -> 0.441) and the memo's 132 pixels: 2.5 keeps every
#: region within 0.011 of F. Grey images (no ink gate) and the JPEGs whose grid the pixels did
#: not show (serif at q 95) did not move.
# The strength's ink test stays at the 8-bit span: at this span (by luma) it gave JPEG photos
# full strength on their recurring levels (tuning half, the space photo 0.165 -> -0.022, coffee
# 0.177 -> 0.079, up to 1.85 dB below F).
COMPRESSED_INK_SPAN = 2.5 / 255


def drawn_at(encoded, rows, cols):
    """bool ``(K,)``: whether the local plan reads each pixel ``(rows[k], cols[k])`` of O as
    drawn (text, graphics, ink: its factor at a textured strength of 0 over one half).

    Parameters
    ----------
    encoded : ndarray of float32, shape (H, W, 3)
        O's sRGB-encoded colour (the analysis window).
    rows, cols : ndarray of int, shape (K,)
    """
    return LocalStrength(0.0).factor_at(encoded, rows, cols) > np.float32(0.5)


def drawn_share(encoded, edges):
    """The share of the edge pixels that the local plan reads as drawn (text, graphics, ink).

    Parameters
    ----------
    encoded : ndarray of float32, shape (H, W, 3)
        O's sRGB-encoded colour (the analysis window).
    edges : ndarray of bool, shape (H, W)

    Returns
    -------
    float
        0 without edge pixels.
    """
    # The summary line's share of text and drawings, with a textured strength of 0.
    rows, cols = np.nonzero(edges)
    return float(np.mean(drawn_at(encoded, rows, cols))) if rows.size else 0.0


def drawn_only(prior, encoded, edges, ink=False, ink_span=FLAT_SPAN):
    """`prior` marked to act on the drawn regions only, or None where the window has almost none.

    Parameters
    ----------
    prior : PureColourPrior or None
    encoded : ndarray of float32, shape (H, W, 3)
        O's sRGB-encoded colour (the analysis window).
    edges : ndarray of bool, shape (H, W)
    ink : bool
        The drawn ink opens the gate too (``PureColourPrior.ink_gate``; colour images).
    ink_span : float, optional
        Within what the ink recurs (``PureColourPrior.ink_span``): the 8-bit level, or
        :data:`COMPRESSED_INK_SPAN` on a JPEG.

    Returns
    -------
    PureColourPrior or None
        With ``drawn_only=True`` (and ``ink_gate=ink``, ``ink_span``) where at least
        :data:`DRAWN_REGION_SHARE` of the edge pixels lie where the gate is open (its ink
        read with the strength's stricter test, :data:`DRAWN_REGION_SHARE` says why).
    """
    if prior is None or not edges.any():
        return None
    rows, cols = np.nonzero(edges)
    weight = LocalStrength.region_weight(encoded)[rows, cols]
    if ink:
        weight = np.maximum(weight, ink_weight_at(encoded, rows, cols, ink_span))
    share = float(np.mean(weight > 0))
    return (dataclasses.replace(prior, drawn_only=True, ink_gate=bool(ink), ink_span=float(ink_span))
            if share >= DRAWN_REGION_SHARE else None)
