"""Image files in and out: every conversion from a file's bit depth happens here or in the contract.

:func:`read_image` gives pixels in the file's own dtype and layout; :func:`write_image`
writes atomically in what the extension's format holds.
"""

from .formats import WRITE_FORMATS
from .jpeg import read_quantization
from .limits import DEFAULT_MAX_BYTES, check_decoded_size
from .parts import remove_stale_parts
from .read import declared_image, describe_orientations, orientation_tag, read_image, warn_if_orientations_differ
from .write import DiskError, check_output_path, check_writable_folder, os_error_line, write_image, write_images

__all__ = ["read_image", "write_image", "write_images", "check_output_path", "check_writable_folder", "os_error_line",
           "remove_stale_parts", "DiskError", "WRITE_FORMATS", "DEFAULT_MAX_BYTES", "check_decoded_size",
           "orientation_tag", "describe_orientations", "warn_if_orientations_differ", "declared_image",
           "read_quantization"]
