"""The GIMP 3 plug-in for aarecovery: the plug-in script and ``aarecovery gimp install``.

The script itself is ``aarecovery-gimp/aarecovery-gimp.py`` in this package (GIMP runs it, not
Python's import system); :mod:`aarecovery.gimp.install` puts it into GIMP's plug-ins folder.
"""
