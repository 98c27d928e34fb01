"""The Krita 5 plug-in for aarecovery: the pykrita plug-in and ``aarecovery krita install``.

The plug-in itself is ``pykrita/`` in this package (Krita imports it, not this Python);
:mod:`aarecovery.krita.install` copies it, with the shared ``aarecovery_bridge``, into a Krita
resource folder and enables it in ``kritarc``.
"""

from ..gimp import InstallError

__all__ = ["InstallError"]
