"""Float32 ``.npy`` files without NumPy: how pixels travel between a host and the worker.

A host's Python (GIMP's on Windows, Krita's AppImage) may have no NumPy; the worker process,
which has it, reads these with ``numpy.load`` and answers with ``numpy.save``.
"""

import struct

from . import PluginError

__all__ = ["write_npy", "read_npy"]

MAGIC = b"\x93NUMPY"


def write_npy(path, data, shape):
    """Write float32 little-endian bytes `data` of `shape` as a version 1.0 ``.npy`` file."""
    header = "{'descr': '<f4', 'fortran_order': False, 'shape': %r, }" % (tuple(shape),)
    header += " " * ((-(10 + len(header) + 1)) % 64) + "\n"      # data aligned to 64 bytes
    with open(path, "wb") as fh:
        fh.write(MAGIC + b"\x01\x00" + struct.pack("<H", len(header)) + header.encode("latin1"))
        fh.write(data)


def read_npy(path, nbytes):
    """The float32 payload of a ``.npy`` file written by ``numpy.save``; check it has `nbytes`."""
    with open(path, "rb") as fh:
        magic = fh.read(8)
        if magic[:6] != MAGIC:
            raise PluginError(f"{path} is not a .npy file")
        version_1 = magic[6] == 1
        size = struct.unpack("<H" if version_1 else "<I", fh.read(2 if version_1 else 4))[0]
        header = fh.read(size).decode("latin1")
        if "'<f4'" not in header or "False" not in header:
            raise PluginError(f"the worker wrote an unexpected array ({header.strip()})")
        data = fh.read()
    if len(data) != nbytes:
        raise PluginError(f"the worker returned {len(data)} bytes, expected {nbytes}")
    return data
