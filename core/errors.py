"""The one exception type users catch for bad input."""

__all__ = ["InputError"]


class InputError(ValueError):
    """Raised when an input image or parameter cannot be used.

    The message says what was wrong and how to fix it; the command line prints it
    as its one-line error.
    """
