"""Whether the GL backend lists the blocks the pure colours' fit covers (``Plan.pure_colour_blocks``).

With pure colours the fit needs O's active blocks, not only F's: a thin feature that the
filter erased leaves F flat where it must be restored. Where O has edges and F none, the fit
gives F exactly unless a neighbour could be a thin feature's ridge, and where no possible
ridge is near (or the gate of drawn content is shut, over a photo) it needs none of its
extension tests. A GL 4.3 backend can first mark those pixels and list O's blocks near a
possible ridge or a change of F, fit those alone, and the ones with no ridge near without
the tests (``backends/gl/blocks.pure_colour_mask``). The marks are a pass over O's active
blocks, and they pay only where enough of them are spared: on a page of text every block of
O's edges holds F's edges and a ridge, and the pass is all cost.

Measured on 4096 x 4096 8-bit pairs (llvmpipe, 2 cores, one process, tiles alone, the same
R): random filled shapes and strokes under a threshold (O's active blocks flat in F: 0.53 of
the image's) 1.26 -> 0.98 s, its fit over 20 % of the blocks instead of O's 31 %, half of
them without the tests; the built-in text scene tiled and thresholded (none flat in F) would
keep every block and lose 0.20 s. So a prior on the whole image is listed where at least
:data:`FLAT_FILTERED_SHARE` of the window's active blocks of O are flat in F. The window the
analysis reads (``aarecovery.sample``) is chosen for its edges and holds more of F's than
the image does: on the shapes 0.28 of its O's blocks are flat in F, and on the text page
none. A prior gated to drawn content is always listed: over the photo the gate is shut and
the fit needs no tests, which cost most of it there. A photo-like pair with text and
interface chrome over a ninth of it, posterized: 5.40 -> 4.02 s; the dense case, a poster
tiled so that its text covers most blocks: 7.32 -> 7.68 s.
"""

import numpy as np

from ..backends.gl.blocks import active_mask

__all__ = ["FLAT_FILTERED_SHARE", "pure_colour_blocks_pay"]

#: The least share of O's active blocks in the analysis window where F is flat (no active
#: block of F) for the pure colours' blocks on the whole image to be listed: about half the
#: image's share where listing spares what it costs, as the window favours F's edges (above).
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
