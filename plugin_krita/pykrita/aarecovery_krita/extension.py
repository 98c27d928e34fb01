"""The menu entries: Tools > Scripts > Repair antialiasing (from layer below / apply filter)."""

from krita import Extension, Krita
from PyQt5.QtWidgets import QMessageBox

from aarecovery_bridge import PluginError

from . import dialog
from .repair import APPLY_FILTER, FROM_LAYER, repair

ACTIONS = {   # action id: (menu text, entry)
    "aarecovery_from_layer": ("Repair antialiasing (from layer below)...", FROM_LAYER),
    "aarecovery_apply_filter": ("Repair antialiasing (apply filter)...", APPLY_FILTER),
}


class RepairExtension(Extension):
    """Adds the two actions to every window."""

    def setup(self):
        pass

    def createActions(self, window):
        for action_id, (text, entry) in ACTIONS.items():
            action = window.createAction(action_id, text, "tools/scripts")
            action.triggered.connect(lambda checked=False, entry=entry: self.run(entry))

    def run(self, entry):
        krita = Krita.instance()
        window = krita.activeWindow()
        parent = window.qwindow() if window else None
        doc = krita.activeDocument()
        try:
            if doc is None:
                raise PluginError("open an image first")
            settings = dialog.ask(krita, entry, parent)
            if settings is None:
                return
            _, outcome = repair(doc, doc.activeNode(), entry, settings)
        except PluginError as error:
            QMessageBox.warning(parent, "Repair antialiasing", str(error))
            return
        for alert in outcome.alerts:                  # a swapped pair, F kept unchanged
            QMessageBox.information(parent, "Repair antialiasing", alert)
        line = " | ".join(filter(None, [outcome.summary, *outcome.notes]))   # e.g. the GL fallback
        if window is not None and window.activeView() is not None and line:
            window.activeView().showFloatingMessage(f"aarecovery: {line}", krita.icon("krita_tool_smart_patch"),
                                                    8000, 1)
