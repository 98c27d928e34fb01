"""The settings dialog of both entries; remembers the last values in Krita's settings."""

import json

from PyQt5.QtWidgets import (QCheckBox, QComboBox, QDialog, QDialogButtonBox, QDoubleSpinBox,
                             QFormLayout, QLineEdit, QSpinBox)

from aarecovery_bridge import filters, parameters

from .repair import APPLY_FILTER, DEFAULTS

SETTINGS_GROUP, SETTINGS_KEY = "aarecovery", "dialog"


def remembered(krita):
    """The values of the last run (JSON in kritarc), over the defaults."""
    try:
        saved = json.loads(krita.readSetting(SETTINGS_GROUP, SETTINGS_KEY, "{}") or "{}")
    except ValueError:
        saved = {}
    return {**DEFAULTS, **{k: v for k, v in saved.items() if k in DEFAULTS}}


class RepairDialog(QDialog):
    """The filter (apply-filter entry), the recovery parameters, the backend and the Python."""

    def __init__(self, entry, values, parent=None):
        super().__init__(parent)
        self.setWindowTitle("Repair antialiasing" + (" (apply filter)" if entry == APPLY_FILTER else ""))
        form = QFormLayout(self)
        self.fields = {}
        if entry == APPLY_FILTER:
            choice = QComboBox()
            for key, (_, label, _) in filters.KRITA_FILTERS.items():
                choice.addItem(label, key)
            choice.setCurrentIndex(max(0, choice.findData(values["filter"])))
            properties = QLineEdit(values["properties"] or filters.KRITA_FILTERS[values["filter"]][2])
            properties.setToolTip("name=value pairs of the filter's configuration; empty: its defaults")
            choice.currentIndexChanged.connect(
                lambda _: properties.setText(filters.KRITA_FILTERS[choice.currentData()][2]))
            form.addRow("Filter", choice)
            form.addRow("Filter properties", properties)
            self.fields.update(filter=(choice, choice.currentData), properties=(properties, properties.text))
        for name, label, kind, minimum, maximum, default, blurb in parameters.RECOVERY_ARGUMENTS:
            if name in parameters.AUTOMATIC_ARGUMENTS:
                auto_name, auto_label, auto_help = parameters.AUTOMATIC_ARGUMENTS[name]
                box = QCheckBox(auto_label.replace("_", ""))
                box.setChecked(bool(values[auto_name]))
                box.setToolTip(f"Ticked: {auto_help}; unticked: the value below")
                form.addRow("", box)
                self.fields[auto_name] = (box, box.isChecked)
            spin = QSpinBox() if kind == "int" else QDoubleSpinBox()
            if kind != "int":
                spin.setDecimals(4)
                spin.setSingleStep(0.01)
            spin.setRange(minimum, maximum)
            spin.setValue(values[name])
            spin.setToolTip(blurb[0].upper() + blurb[1:])
            form.addRow(label.replace("_", ""), spin)
            self.fields[name] = (spin, spin.value)
        backend = QComboBox()
        backend.addItems(parameters.BACKENDS)
        backend.setCurrentText(values["backend"])
        python = QLineEdit(values["python"])
        python.setPlaceholderText("only if Krita's Python cannot import aarecovery")
        form.addRow("Backend", backend)
        form.addRow("Python with aarecovery", python)
        self.fields.update(backend=(backend, backend.currentText), python=(python, python.text))
        buttons = QDialogButtonBox(QDialogButtonBox.Ok | QDialogButtonBox.Cancel)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)

    def values(self):
        return {name: read() for name, (_, read) in self.fields.items()}


def ask(krita, entry, parent=None):
    """Show the dialog; return the chosen values (remembered for next time), or None."""
    dialog = RepairDialog(entry, remembered(krita), parent)
    if dialog.exec_() != QDialog.Accepted:
        return None
    values = dialog.values()
    krita.writeSetting(SETTINGS_GROUP, SETTINGS_KEY, json.dumps({**remembered(krita), **values}))
    return values
