"""Image files in and out: every conversion from a file's bit depth happens here or in the contract.

:func:`read_image` gives pixels in the file's own dtype and layout; :func:`write_image`
writes atomically in what the extension's format holds.
"""

from .formats import WRITE_FORMATS
from .read import MAX_PIXELS, read_image
from .write import check_output_path, write_image

__all__ = ["read_image", "write_image", "check_output_path", "WRITE_FORMATS", "MAX_PIXELS"]
