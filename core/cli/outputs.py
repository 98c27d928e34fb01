"""Where a command may write: :func:`check_destinations` (``aarecovery.io.destinations``, which
the batch shares), and the part files that interrupted runs left beside the outputs."""

import os

from ..io import remove_stale_parts
from ..io.destinations import check_destinations, same_file

__all__ = ["check_destinations", "remove_stale_parts_of", "same_file"]


def remove_stale_parts_of(outputs):
    """Remove what interrupted earlier runs left beside these outputs (their own parts only)."""
    for output in outputs:
        folder = os.path.dirname(os.path.abspath(output))
        name, extension = os.path.splitext(os.path.basename(output))
        remove_stale_parts(folder, name, extension)
