"""What the command line prints of text it did not write: file names, tools' messages."""

__all__ = ["printable"]


def printable(text):
    """`text` as one safe terminal line: control characters (newlines, ESC of terminal escape
    sequences, DEL, C1) as Python escapes (``\\n``, ``\\x1b``), and bytes of a file name that
    are not UTF-8 (``os.fsdecode``'s surrogates) as ``\\xNN``; printable text unchanged."""
    text = str(text)
    if text.isprintable():
        return text
    shown = []
    for character in text:
        code = ord(character)
        if 0xDC80 <= code <= 0xDCFF:  # one undecodable byte of a file name
            shown.append(f"\\x{code - 0xDC00:02x}")
        elif character.isprintable() or character == " ":
            shown.append(character)
        else:
            shown.append(repr(character)[1:-1] if code < 0x10000 and not 0xD800 <= code <= 0xDFFF
                         else f"\\u{code:04x}")
    return "".join(shown)
