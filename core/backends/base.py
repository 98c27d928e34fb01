"""What every backend is given and gives back: the Plan, the maps, and the Backend protocol.

These types live below the engine and the plan layer, so that both can use them and no
import runs back up: the plan layer makes a :class:`Plan`, the engine hands it to a
:class:`Backend`, and the backend returns pixels and :class:`RecoveryMaps`.
"""

import enum
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ..spec.local_plan import REACH as LOCAL_REACH

__all__ = ["Decision", "Plan", "RecoveryMaps", "Capabilities", "Backend", "ReadyResult"]


class Decision(str, enum.Enum):
    """Which of the plan's exits was taken: its name, for tests, reports and messages.

    The safe default's exits are listed in the order ``aarecovery.plan.analysis.analyse``
    takes them; the value is the name reports print. A ``str`` enum, so that a report's
    column and a comparison with the name as text both work.
    """

    PAPER = "paper"
    """``mode="paper"``: the published method, no analysis."""
    LOWPASS_KEPT = "lowpass-kept"
    """F is a blur of O: its soft edges are the filter's intent, F is kept."""
    AFFINE_KEPT = "affine-kept"
    """F is an affine map of O on its edges: the edges are already right, F is kept."""
    POINTWISE_HARD_EDGED = "pointwise-hard-edged"
    """A point-wise filter on hard-edged content: full strength (and pure colours of thin
    features when the table allows)."""
    POINTWISE_HARD_EDGED_COMPRESSED = "pointwise-hard-edged-compressed"
    """A point-wise filter on hard-edged content whose O was JPEG-compressed: the strength
    self-calibration finds (the compression noise goes through the filter too), and pure
    colours of thin features only between extremes farther apart than that noise."""
    POINTWISE_HARD_EDGED_GRAINED = "pointwise-hard-edged-grained"
    """The same on a scanned page whose coarse paper grain leaves no flat pixel
    (``aarecovery.plan.paper_grain``): the grain goes through the filter like compression
    noise, so the calibrated strength, and pure colours only above the grain."""
    POINTWISE_CALIBRATED = "pointwise-calibrated"
    """A point-wise filter on a textured image: the strength self-calibration finds, in the
    regions that read as textured; full strength in those that read as hard-edged (text or
    drawings over the photo: the local plan, ``aarecovery.spec.local_plan``)."""
    NEIGHBOURHOOD_TEXTURED_KEPT = "neighbourhood-textured-kept"
    """A filter that is neither point-wise nor a colour map, on a textured image: F is kept."""
    NEIGHBOURHOOD_TEXTURED = "neighbourhood-textured"
    """A neighbourhood filter on a grey textured image, or a sharpening filter (an unsharp
    mask) on a colour one: a low strength, which repairs part of the filter's damage without
    flattening the texture into two colours."""
    NEIGHBOURHOOD_MIXED = "neighbourhood-mixed"
    """The same on a photo with text or drawings over part of it: the drawn regions are
    repaired, F is kept in the photo (the local plan with a textured strength of 0), or under
    a sharpening filter repaired at a photo's low strength (0.25 grey, 0.1 in colour)."""
    COLOUR_MAP_KEPT = "colour-map-kept"
    """A colour map on a textured image whose repairs would be no larger than the model's
    own error: F is kept."""
    COLOUR_MAP_CALIBRATED = "colour-map-calibrated"
    """A colour map (a palette quantiser) on a textured image: the calibrated strength."""
    COLOUR_MAP_HARD_EDGED = "colour-map-hard-edged"
    """A colour map (a palette quantiser) on hard-edged content: full strength, or on a JPEG
    original the calibrated strength; no pure colours."""
    NEIGHBOURHOOD_HARD_EDGED_KEPT = "neighbourhood-hard-edged-kept"
    """A neighbourhood filter on hard-edged content whose repairs would be no larger than the
    model's own error: F is kept."""
    NEIGHBOURHOOD_HARD_EDGED = "neighbourhood-hard-edged"
    """A neighbourhood filter on hard-edged content: the paper's passes at full strength."""

    def __str__(self):
        return self.value


@dataclass(frozen=True)
class Plan:
    """How one image pair is recovered: the parameters and every per-image decision.

    Made once per pair by ``aarecovery.plan.make_plan`` (before any tiling, so that tiles
    share it) and taken as it is by the engine and every backend.

    Attributes
    ----------
    sigma_d, sigma_e : float
    iterations : int
        The recovery parameters (``aarecovery.params``).
    blend_space : {"linear", "srgb"}
        Where the model is fitted and the blend happens.
    strength : float
        Multiplies the confidence ``beta``, in [0, 1]; 0 returns F unchanged, 1 is the paper.
    pure_colours : PureColourPrior or None
        The safe default's pure colours of thin features (``aarecovery.spec.pure_colours``);
        None runs the paper's passes.
    mode : {"safe", "paper"}
    reason : str
        One line saying why, for messages and the evaluation report.
    decision : Decision
        Which exit of the plan was taken, by name.
    local : LocalStrength or None
        The local plan (``aarecovery.spec.local_plan``): a per-pixel factor of ``beta``, read
        from O, on top of `strength`; None: `strength` alone, everywhere.
    untouched_span : float
        Above 0 (a smoothing filter, ``aarecovery.plan.smoothing``), ``beta`` falls to 0 where
        F's pixel is O's: the model's pass multiplies it by a smoothstep of F's change from O
        up to this (working space); 0, the paper's, leaves it as it is.
    toward_original : bool
        A smoothing filter that keeps O's colours (``aarecovery.plan.smoothing``): every Jacobi
        step moves the edge pixels of the drawn content towards O's own colour by the local
        plan's gate, its regions' weight or drawn ink, over a photo the ink where F kept O's
        contrast (``aarecovery.spec.blend_model.toward_original``).
    forcing : Forcing or None
        Where the safe default keeps F: whether forcing a repair may help, and why or what
        it risks (``aarecovery.plan.forcing``).
    ramp_table : RampTable or None
        The ramp lookup's table (``aarecovery.spec.ramp_lookup``): R takes the table averaged
        across each pixel where O is a ramp, as far as the model's confidence leaves it;
        None: no ramp lookup. Only for sRGB-encoded inputs (its delta is in encoded values).
    best_pair : bool
        Where the principal colour line misses a pixel, the pair of its neighbours that
        explains it best gives the model's extremes (``aarecovery.spec.blend_model.best_pair``):
        the safe default on a lossless O; False, the paper's extremes.
    pure_colour_blocks : bool
        With `pure_colours`: a GL 4.3 backend first lists the blocks where the pure colours'
        fit can change anything (O's near a possible ridge or a change of F,
        ``backends/gl/blocks.pure_colour_mask``) and fits those alone, without the extension
        tests where no ridge could be extended; where that pays (``aarecovery.plan.fit_blocks``).
        False: it fits O's active blocks whole. R is the same either way.
    window : tuple of slice or None
        The rows and columns of the pair that the safe default's analysis read
        (``aarecovery.sample``), when the plan was made from the whole pair: the summary
        reads the same window instead of choosing it again; None when unknown.
    """

    sigma_d: float
    sigma_e: float
    iterations: int
    blend_space: str = "linear"
    strength: float = 1.0
    pure_colours: object = None
    mode: str = "paper"
    reason: str = "the published method"
    decision: Decision = Decision.PAPER
    local: object = None
    untouched_span: float = 0.0
    toward_original: bool = False
    forcing: object = None
    window: tuple = None
    ramp_table: object = None
    best_pair: bool = False
    pure_colour_blocks: bool = False

    @property
    def keeps_filtered(self):
        """bool: the plan returns F unchanged (strength 0)."""
        return self.strength == 0

    @property
    def reach(self):
        """int: how far beyond the model's own neighbourhood the plan reads O (the local
        plan's factor, or its gate towards O, which the model reads over its own 3 x 3
        neighbourhood: ``spec.blend_model.toward_weight``; 0 without either): a tile's extra
        halo."""
        if self.local is None:
            return LOCAL_REACH if self.toward_original else 0
        return self.local.reach


@dataclass
class RecoveryMaps:
    """Per-pixel intermediate maps of the last recovery, for viewers and debugging.

    Attributes
    ----------
    alpha : ndarray of float32, shape (H, W)
        Coverage of the first extreme colour.
    beta : ndarray of float32, shape (H, W)
        Confidence in [0, 1]: 0 keeps F, 1 imposes O's blend.
    edge_strength : ndarray of float32, shape (H, W)
        Product of the Sobel magnitudes of O and F.
    residual : ndarray of float32, shape (H, W)
        Distance of O's colour from its two-colour blend.
    strength : ndarray of float32, shape (H, W)
        The plan's strength at each pixel, which multiplies the confidence: the local plan's
        map, or the one strength everywhere.
    """

    alpha: np.ndarray
    beta: np.ndarray
    edge_strength: np.ndarray
    residual: np.ndarray
    strength: np.ndarray

    NAMES = ("alpha", "beta", "edge_strength", "residual", "strength")


@dataclass(frozen=True)
class Capabilities:
    """What a backend can take.

    Attributes
    ----------
    max_tile : int
        The largest tile side it can hold (a texture limit for GL).
    default_tile : int
        The tile side it runs best at (measured; see ``docs/performance.md``).
    gl_paths : tuple of str
        The ways it can run the passes on OpenGL (``aarecovery.params.GL_PATHS``): empty for
        NumPy, ``("fragment",)`` before GL 4.3, ``("fragment", "compute")`` from GL 4.3 on.
    gl_path : str or None
        The one it runs, or None for NumPy.
    """

    max_tile: int
    default_tile: int
    gl_paths: tuple = ()
    gl_path: str = None


class ReadyResult:
    """A result that is already in memory: what :meth:`Backend.start_readback` gives where
    reading back costs nothing or cannot overlap anything."""


    def __init__(self, rgba):
        self._rgba = rgba

    def wait(self):
        """ndarray: the result, as :meth:`Backend.start_readback` describes it."""
        return self._rgba


class Backend(Protocol):
    """A place where the passes run: NumPy (the specification) or OpenGL.

    The engine calls :meth:`load` once per image pair (or tile), then :meth:`run` once per
    plan, then reads back. Images arrive as the caller gave them (any layout and dtype the
    contract accepts, described by their ``Layout``); results go back as straight RGBA.
    :meth:`load` and :meth:`run` may return before the work is done (a GPU's queue); a
    tiled caller overlaps one tile's readback with the next tile's passes through
    :meth:`start_readback`.
    """

    name: str
    capabilities: Capabilities

    def load(self, original, o_layout, filtered, f_layout, linear_input, blend_space):
        """Take a checked pair and move it into the working space of `blend_space`."""

    def run(self, plan, maps):
        """Run the passes of `plan` on the loaded pair; keep the maps when `maps`."""

    def finish(self):
        """Block until the last run is complete."""

    def start_readback(self, window=None):
        """Start reading the last result back (the part `window`, a pair of row and column
        slices, or all of it); return an object whose ``wait()`` gives it: ``(h, w, 4)``
        straight RGBA in float32 or F's integer dtype, or ``(h, w, C)`` in F's own channels
        and dtype. It stays valid while one more result is started."""

    def read_maps(self):
        """The maps of the last run with ``maps=True``, as :class:`RecoveryMaps`."""

    def release(self):
        """Free what the backend holds; it cannot be used afterwards."""
