"""Krita 5 plug-in: repair the antialiased edges that Krita's filters damage (aarecovery).

Tools > Scripts > Repair antialiasing (from layer below) and (apply filter)...; see
docs/krita.md. :mod:`.repair` does the work, :mod:`.pixels` moves the pixels, :mod:`.dialog`
asks for the settings and :mod:`.extension` adds the menu entries. Running the core (in
Krita's Python, or in a worker process with a configured Python) is ``aarecovery_bridge``,
installed beside this package and shared with the GIMP plug-in.
"""

import os

from aarecovery_bridge import worker

AARECOVERY_VERSION = "0.1.0"          # aarecovery_bridge must be the same release
HOST = worker.Host("Krita", "aarecovery krita", os.path.dirname(os.path.abspath(__file__)),
                   "the dialog's 'Python with aarecovery' field",
                   "the dialog's Strength with Automatic strength unticked", bundles=False)

from krita import Krita  # noqa: E402  (the modules below import HOST from here)

from .extension import RepairExtension  # noqa: E402

Krita.instance().addExtension(RepairExtension(Krita.instance()))
