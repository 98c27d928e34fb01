"""A test-only pykrita plug-in: drives the real Krita GUI (under Xvfb) through the menu entry.

test_krita_gui.py installs it as ``aarecovery_gui_check`` beside the real plug-in and enables
both in a throwaway kritarc. When Krita's window is up it: lists the menu entries whose text
names antialiasing; opens a document with the test's O (below) and F (above, active); triggers
the action ``aarecovery_from_layer`` exactly as the menu does, which shows the plug-in's dialog;
grabs the screen with the dialog open (``dialog.png``) and presses OK; exports the new
repaired layer (``R.raw``) and grabs the screen again (``result.png``); presses Edit > Undo once and
exports the filtered layer (``U.raw``); writes ``gui.json`` and quits.
Any other modal window (an error box) is recorded, closed, and ends the run.

Paths come from ``$AARECOVERY_KRITA_GUI`` (a folder with ``case.json``, ``O.raw``, ``F.raw``).
"""

import functools
import json
import os
import traceback

from krita import Extension, Krita
from PyQt5.QtCore import QTimer
from PyQt5.QtWidgets import QApplication

FOLDER = os.environ.get("AARECOVERY_KRITA_GUI", "")
GIVE_UP_MS = 120_000


def step(method):
    """A failing step records its traceback and ends Krita, rather than leave it waiting."""
    @functools.wraps(method)
    def guarded(self, *args):
        try:
            return method(self, *args)
        except Exception:
            self.record["error"] = traceback.format_exc()
            self.save()
            QApplication.quit()
    return guarded


class GuiCheck(Extension):
    """Runs the steps below one after another on Krita's event loop."""

    def setup(self):
        self.record = {"modal": []}

    def createActions(self, window):
        QTimer.singleShot(1500, self.open_document)
        QTimer.singleShot(GIVE_UP_MS, functools.partial(self.give_up, "the run did not finish"))

    def give_up(self, why):
        self.record.setdefault("error", why)
        self.save()
        QApplication.quit()

    def save(self):
        with open(os.path.join(FOLDER, "gui.json"), "w") as fh:
            json.dump(self.record, fh, indent=1)

    def grab(self, name):
        """The screen where Krita's window is, with any dialog over it (no window manager)."""
        area = Krita.instance().activeWindow().qwindow().frameGeometry()
        QApplication.primaryScreen().grabWindow(0, area.x(), area.y(), area.width(), area.height()).save(
            os.path.join(FOLDER, name), "PNG")

    @step
    def open_document(self):
        krita = Krita.instance()
        window = krita.activeWindow()
        window.qwindow().setGeometry(0, 0, 1100, 640)
        entries = []

        def walk(menu, path):
            for action in menu.actions():
                if action.menu():
                    walk(action.menu(), path + [action.text().replace("&", "")])
                elif "antialias" in action.text().lower():
                    entries.append(" > ".join(path + [action.text().replace("&", "")]))
        walk(window.qwindow().menuBar(), [])
        self.record["menu"] = entries
        with open(os.path.join(FOLDER, "case.json")) as fh:
            case = json.load(fh)
        w, h = case["size"]
        doc = krita.createDocument(w, h, "aarecovery", "RGBA", "U8", "", 72.0)
        for node in doc.rootNode().childNodes():
            node.remove()
        for name in ("original", "filtered"):
            node = doc.createNode(name, "paintlayer")
            doc.rootNode().addChildNode(node, None)
            with open(os.path.join(FOLDER, f"{name[0].upper()}.raw"), "rb") as fh:
                node.setPixelData(fh.read(), 0, 0, w, h)
        self.doc, self.layer = doc, node
        window.addView(doc)
        doc.setActiveNode(node)
        doc.refreshProjection()
        window.activeView().canvas().setZoomLevel(3.0)
        QTimer.singleShot(1500, self.run_action)

    @step
    def run_action(self):
        QTimer.singleShot(2000, self.answer_dialog)
        Krita.instance().action("aarecovery_from_layer").trigger()     # returns when the dialog closed
        QTimer.singleShot(1500, self.finish)

    @step
    def answer_dialog(self):
        dialog = QApplication.activeModalWidget()
        if dialog is None:
            self.record["modal"].append("no dialog opened")
            return
        self.record["dialog_title"] = dialog.windowTitle()
        self.grab("dialog.png")
        dialog.accept()
        QTimer.singleShot(1000, self.close_strays)

    @step
    def close_strays(self):
        stray = QApplication.activeModalWidget()
        if stray is not None:                                # an error box: record, close, go on
            self.record["modal"].append(stray.text() if hasattr(stray, "text") else stray.windowTitle())
            stray.close()

    def export(self, node, name):
        with open(os.path.join(FOLDER, name), "wb") as fh:
            fh.write(bytes(node.pixelData(0, 0, self.doc.width(), self.doc.height())))

    @step
    def finish(self):
        self.export(self.doc.nodeByName("filtered (repaired)"), "R.raw")
        self.record["layers"] = [(n.name(), n.visible()) for n in self.doc.rootNode().childNodes()
                                 if n.type() == "paintlayer"]
        self.grab("result.png")
        # What Edit > Undo does after the repair (docs/krita.md says what Krita's API allows).
        Krita.instance().action("edit_undo").trigger()
        QTimer.singleShot(1000, self.after_undo)

    @step
    def after_undo(self):
        self.export(self.layer, "U.raw")
        self.record["layers_after_undo"] = [n.name() for n in self.doc.rootNode().childNodes()
                                            if n.type() == "paintlayer"]
        self.save()
        self.doc.setModified(False)
        QApplication.quit()


if FOLDER:
    Krita.instance().addExtension(GuiCheck(Krita.instance()))
