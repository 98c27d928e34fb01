"""Whether the GL backend lists the blocks the pure colours' fit covers (``Plan.pure_colour_blocks``).

With pure colours the fit needs O's active blocks, not only F's: a thin feature that the
filter erased leaves F flat where it must be restored. Where O has edges and F none, the fit
gives F exactly unless a neighbour could be a thin feature's ridge, so a GL 4.3 backend can
first list O's blocks near a possible ridge or a change of F and fit those alone
(``backends/gl/blocks.pure_colour_mask``). The listing is a pass over O's active blocks, and
it pays only where enough of them are flat in F: on a page of text every block of O's edges
holds F's edges too, and the pass is all cost.

Measured on 4096 x 4096 8-bit pairs (llvmpipe, 2 cores, pass clock, one process): random
filled shapes and strokes under a threshold (O's active blocks flat in F: 0.53 of the
image's) fit 64 % of O's active blocks, and the fit took 0.54 s instead of 0.80-0.84 s for
0.13 s of listing; the built-in text scene tiled and thresholded (none flat in F) kept every
block, and the listing's 0.20 s was lost. The listing costs a sixth of the fit per block of
O's, and of the blocks flat in F it spared two thirds on the shapes: it pays from about a
quarter of O's blocks flat in F. The window the analysis reads (``aarecovery.sample``) is
chosen for its edges and holds more of F's than the image does: on the shapes 0.28 of its
O's blocks are flat in F, and on the text page none.
"""

import numpy as np

from ..backends.gl.blocks import active_mask

__all__ = ["FLAT_FILTERED_SHARE", "pure_colour_blocks_pay"]

#: The least share of O's active blocks in the analysis window where F is flat (no active
#: block of F) for the pure colours' blocks to be listed: about half the image's share where
#: listing spares what it costs, as the window favours F's edges (above).
FLAT_FILTERED_SHARE = 0.15


def pure_colour_blocks_pay(original, filtered):
    """Whether listing the pure colours' blocks pays on this pair.

    Parameters
    ----------
    original, filtered : ndarray of float32, shape (H, W, 4)
        The analysis window of O and F (straight RGBA): equal values there are equal as
        uploaded.

    Returns
    -------
    bool
    """
    o_active = active_mask(np.ascontiguousarray(original))
    f_active = active_mask(np.ascontiguousarray(filtered))
    return bool((o_active & ~f_active).sum() >= FLAT_FILTERED_SHARE * max(int(o_active.sum()), 1))
