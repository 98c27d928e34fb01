"""Native file dialogs (portable-file-dialogs), polled between frames so the window stays live."""

import os
import shutil
import sys

__all__ = ["NativeFileDialogs", "native_dialogs_available"]

_IMAGE_FILTERS = ["Images", "*.png *.tif *.tiff *.jpg *.jpeg *.webp *.bmp *.npy", "All files", "*"]


def native_dialogs_available():
    """Native file dialogs exist on Windows and macOS, and on Linux with zenity or kdialog."""
    if sys.platform in ("win32", "darwin"):
        return True
    return any(shutil.which(tool) for tool in ("zenity", "kdialog", "matedialog", "qarma"))


class NativeFileDialogs:
    """At most one open dialog at a time, for the panel's ``...`` and Browse buttons.

    Attributes
    ----------
    available : bool
        Whether this system has native dialogs (the buttons are hidden otherwise).
    """

    def __init__(self):
        self.available = native_dialogs_available()
        self._open = None  # (role, portable_file_dialogs object)

    @property
    def is_open(self):
        """bool: a dialog is waiting for the user."""
        return self._open is not None

    def browse(self, role, panel):
        """Open a dialog for ``"original"``, ``"filtered"`` or ``"save"``, starting where `panel` points."""
        from imgui_bundle import portable_file_dialogs as pfd
        if self._open is not None:
            return
        if role == "save":
            dialog = pfd.save_file("Save R", panel.save_path, _IMAGE_FILTERS)
        else:
            start = panel.original_path or os.getcwd()
            dialog = pfd.open_file(f"Open {role.upper()}", os.path.dirname(start) or ".", _IMAGE_FILTERS)
        self._open = (role, dialog)

    def poll(self, panel):
        """If the open dialog has closed, put the chosen file into `panel`'s field."""
        if self._open is None or not self._open[1].ready(0):
            return
        role, dialog = self._open
        self._open = None
        result = dialog.result()
        chosen = result[0] if isinstance(result, list) and result else result if isinstance(result, str) else ""
        if chosen:
            panel.take_chosen_file(role, chosen)
