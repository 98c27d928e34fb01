"""What a JPEG file says about its own compression: its quantization tables.

The safe default reads the compression noise of O from them
(``aarecovery.plan.compression``); an image given as an array has no file, and the plan
searches its pixels for the block grid instead. The tables are read from the header's DQT
segments with the standard library alone, nothing decoded: a camera's MPO file (a JPEG
followed by a second picture, which Pillow names MPO rather than JPEG) has them too, and a
pair read without Pillow (the GIMP plug-in's bundle has none) pays for no import.
"""

__all__ = ["read_quantization"]

# Every JPEG file starts with a start-of-image marker followed by another marker.
_JPEG_SIGNATURE = b"\xff\xd8\xff"


def _natural_order():
    """For each coefficient in row-major (natural) order, its position in the zigzag order in
    which a DQT segment stores the steps (Pillow's ``zigzag_index``)."""
    position, order = {}, 0
    for diagonal in range(15):
        cells = [(row, diagonal - row) for row in range(8) if 0 <= diagonal - row < 8]
        # Even diagonals run up and to the right, odd ones down and to the left.
        for row, column in (reversed(cells) if diagonal % 2 == 0 else cells):
            position[row * 8 + column] = order
            order += 1
    return tuple(position[index] for index in range(64))


_ZIGZAG_OF = _natural_order()
# Markers with no length field after them: TEM, RST0-RST7, SOI, EOI.
_BARE_MARKERS = {0x01, *range(0xD0, 0xDA)}
_DQT, _SOS = 0xDB, 0xDA


def _tables_in(data):
    """The quantization tables of the DQT segments before the first scan, by table number;
    None where the header is cut short or malformed."""
    tables, at = {}, 2
    while True:
        # A marker is 0xFF and a code; 0xFF may repeat as fill.
        if at >= len(data) or data[at] != 0xFF:
            return None
        while at < len(data) and data[at] == 0xFF:
            at += 1
        if at >= len(data):
            return None
        marker = data[at]
        at += 1
        if marker in _BARE_MARKERS:
            continue
        if marker == _SOS:
            return tables
        if at + 2 > len(data):
            return None
        length = int.from_bytes(data[at:at + 2], "big")
        segment = data[at + 2:at + length]
        if length < 2 or len(segment) != length - 2:
            return None
        at += length
        if marker != _DQT:
            continue
        while segment:
            precision, number = segment[0] >> 4, segment[0] & 15
            size = 64 * (2 if precision else 1)
            if len(segment) < 1 + size:
                return None
            steps = segment[1:1 + size]
            zigzag = (list(steps) if not precision
                      else [int.from_bytes(steps[2 * i:2 * i + 2], "big") for i in range(64)])
            tables[number] = [zigzag[_ZIGZAG_OF[index]] for index in range(64)]
            segment = segment[1 + size:]


# The header holds the tables; a scan rarely starts later than this (EXIF thumbnails, ICC
# profiles and XMP come first and can be large).
_HEADER_BYTES = 1 << 20


def read_quantization(path):
    """The quantization tables of a JPEG file, or None for any other file.

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    list of list of int or None
        64 steps per table in row-major order, by table number (luma first), as Pillow gives
        them (the noise bound does not depend on the order of the steps); None when the file
        is not a JPEG (a PNG, a TIFF: no compression noise), cannot be read or its header is
        malformed (``read_image`` reports that).
    """
    try:
        with open(path, "rb") as handle:
            if handle.read(len(_JPEG_SIGNATURE)) != _JPEG_SIGNATURE:
                return None
            handle.seek(0)
            data = handle.read(_HEADER_BYTES)
            tables = _tables_in(data)
            while tables is None and len(data) % _HEADER_BYTES == 0 and data:
                # A header longer than the first megabyte (a large embedded profile).
                more = handle.read(_HEADER_BYTES)
                if not more:
                    break
                data += more
                tables = _tables_in(data)
    except OSError:
        return None
    if not tables:
        return None
    return [tables[number] for number in sorted(tables)]
