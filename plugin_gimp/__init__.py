"""The GIMP 3 plug-in for aarecovery: the plug-in script and ``aarecovery gimp install``.

The script itself is ``aarecovery-gimp/aarecovery-gimp.py`` in this package (GIMP runs it, not
Python's import system); :mod:`aarecovery.gimp.install` puts it into a GIMP profile, with the
core and its binary dependencies bundled next to it when asked (:mod:`aarecovery.gimp.bundle`).
"""

__all__ = ["InstallError"]


class InstallError(Exception):
    """An installation step failed; the message is one line that says what to do about it."""
