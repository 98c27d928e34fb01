"""Which plans take the ramp lookup (``aarecovery.spec.ramp_lookup``), and with which table.

The ramp lookup averages the filter's table across pixels where O is a ramp; it needs a
point-wise table that explains F. Plans that repair at a calibrated strength take it: photos
and the photo regions of mixed scenes (``POINTWISE_CALIBRATED``), and drawings read through a
JPEG's noise or a paper's grain (``POINTWISE_HARD_EDGED_COMPRESSED``, ``_GRAINED``), whose
smooth ramps are that noise. Tuning half, 96 px, edge-band error removed: photos (PNG) 0.309
-> 0.358, their JPEG twins 0.245 -> 0.276; the mixed scenes' text and graphics (PNG) 0.589 ->
0.600, photo regions 0.287 -> 0.321; compressed drawings 0.491 -> 0.506 (77 up, none down);
grained pages 0.555 -> 0.578. Not full-strength drawings (``POINTWISE_HARD_EDGED``): there
the model covers the edges and the flat colours have no ramp (183 PNG cases 0.800 -> 0.802,
none down), and the lookup's pass would read O and F around every pixel of F's active blocks
for nothing a user sees.
"""

from ..spec.pure_colours import COLOUR_KEY, EXTENSION_KEYS
from ..spec.ramp_lookup import RAMP_BEND, RampTable, table_bends

__all__ = ["RAMP_WINDOW", "ROUNDING_BEND", "ramp_table_of"]

#: A table takes the lookup only where some span of this many bins bends by more than
#: ``RAMP_BEND`` beyond ``ROUNDING_BEND`` at each bin: a step, a clipped end, a jagged
#: equalization. A smooth curve (a gamma, a sigmoid) fitted from 8-bit F is a staircase of
#: whole levels, which rounding bends by up to two levels at a bin (three values each within
#: half a level); averaged across ramps it moves pixels by a fraction of a level, while its
#: pass takes nine samples at nearly every pixel of a photo under such a curve: the bench's
#: gamma pair at 4096 x 4096 on llvmpipe, passes 1.4 s without the lookup, 5.9 s with it
#: (the lookup's pass 4.5 s). Tuning half (920 cases), against counting every bend: photos
#: under point-wise filters 0.347 -> 0.339, 84 cases down by at most 0.01 (ImageMagick's
#: sigmoidal, OpenCV's gamma; the icons under the sigmoidal at q 75 and 90 again 0.31 and
#: 0.16 dB below F, as before the lookup, not 0.25 and 0.08); the rounding left out per pixel too
#: (``table_bends(beyond=)`` in the passes) 0.336, 122 down. 16 bins is 24 levels of slope per
#: pixel, an edge's, where the model acts.
RAMP_WINDOW = 16
ROUNDING_BEND = 2.0 / 255



def ramp_table_of(transfer, prior):
    """The table the ramp lookup reads: the pure colours' when the plan has them (the backends
    hold one table), else the fitted transfer's; None where its key has no GL twin, and where
    the pure colours read a 3-D colour map (``plan.colour_map.indexed_colour_prior``).

    Parameters
    ----------
    transfer : PointwiseTransfer
    prior : PureColourPrior or None

    Returns
    -------
    RampTable or None
        None also for a table that bends by at most ``RAMP_BEND`` beyond rounding in every
        span of :data:`RAMP_WINDOW` bins.
    """
    if prior is not None and prior.key == COLOUR_KEY:
        # The passes hold one table, and the ramp lookup's is of one key.
        return None
    if prior is not None:
        table = RampTable(prior.key, prior.table)
    elif transfer.key in EXTENSION_KEYS:
        table = RampTable(transfer.key, transfer.table)
    else:
        return None
    # A table that bends nowhere by more than RAMP_BEND within a pixel's reach changes next to
    # no pixel, while its pass would still read every pixel where F varies (below).
    bends = table_bends(table.table, beyond=ROUNDING_BEND)
    windows = bends[RAMP_WINDOW:] - bends[:-RAMP_WINDOW]
    return table if windows.max() > RAMP_BEND else None
