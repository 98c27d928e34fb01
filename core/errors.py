"""The exceptions users catch (bad input, not enough memory) and the warnings aarecovery gives."""

__all__ = ["InputError", "NotEnoughMemory", "AarecoveryWarning", "BackendFallbackWarning", "OrderWarning",
           "TileSizeWarning", "OrientationWarning"]


class InputError(ValueError):
    """Raised when an input image or parameter cannot be used.

    The message says what was wrong and how to fix it; the command line prints it
    as its one-line error.
    """


class AarecoveryWarning(UserWarning):
    """Base of aarecovery's warnings; the command line prints each as one line."""


class BackendFallbackWarning(AarecoveryWarning, RuntimeWarning):
    """``backend="auto"`` found no OpenGL 3.3 and runs the NumPy backend (the same
    result up to float rounding, slower)."""


class OrderWarning(AarecoveryWarning):
    """ORIGINAL and FILTERED look swapped: the image given as filtered has the antialiased edges.

    ``aarecovery.plan.order`` decides it; the message is one line that says why.
    """


class OrientationWarning(AarecoveryWarning):
    """ORIGINAL and FILTERED declare different orientations (EXIF / TIFF tags).

    Each is turned upright as tagged; when a program dropped or changed the tag without
    turning the pixels, a square pair still matches in size but is misaligned.
    """


class TileSizeWarning(AarecoveryWarning):
    """A ``tile_size`` so small that the run takes many times longer (``aarecovery.tiling``)."""


class NotEnoughMemory(MemoryError):
    """Memory ran out; the message says how much the image needs and what to do (one line)."""
