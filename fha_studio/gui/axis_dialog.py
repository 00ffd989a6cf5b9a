"""The dialog that adds an axis to a machine."""

from __future__ import annotations

from typing import Any

from PySide6.QtWidgets import (
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFormLayout,
    QLabel,
    QLineEdit,
    QWidget,
)


class AxisDialog(QDialog):
    """A new axis: name, actuator model code, driver, port, declared load inertia, serial number,
    notes. What is wrong is said in the dialog, which stays open."""

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        self.setWindowTitle("Add an axis")
        form = QFormLayout(self)
        self.name_edit = QLineEdit()
        self.name_edit.setPlaceholderText("e.g. table, tilt, wrist roll")
        self.actuator_edit = QLineEdit()
        self.actuator_edit.setPlaceholderText("model code on the label, e.g. FHA-25C-50-US250")
        self.driver_edit = QLineEdit()
        self.driver_edit.setPlaceholderText(
            "TYPE line of the driver, e.g. HA-655-2-200 (the drive says it too)"
        )
        self.port_edit = QLineEdit()
        self.port_edit.setPlaceholderText("/dev/ttyUSB0, COM3, socket://host:port or sim://FHA-25C-50-US250")
        self.inertia_spin = QDoubleSpinBox()
        self.inertia_spin.setRange(0.0, 10000.0)
        self.inertia_spin.setDecimals(4)
        self.inertia_spin.setSuffix(" kg·m²")
        self.serial_edit = QLineEdit()
        self.serial_edit.setPlaceholderText("from the actuator's label")
        self.notes_edit = QLineEdit()
        self.error_label = QLabel("")
        self.error_label.setWordWrap(True)
        self.error_label.setStyleSheet("color: #b00020; font-weight: bold;")
        for label, widget in (
            ("&Name:", self.name_edit),
            ("&Actuator:", self.actuator_edit),
            ("&Driver:", self.driver_edit),
            ("&Port:", self.port_edit),
            ("&Load inertia:", self.inertia_spin),
            ("&Serial number:", self.serial_edit),
            ("N&otes:", self.notes_edit),
        ):
            form.addRow(label, widget)
        form.addRow(self.error_label)
        buttons = QDialogButtonBox(
            QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel
        )
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        form.addRow(buttons)

    def values(self) -> dict[str, Any]:
        return {
            "name": self.name_edit.text().strip(),
            "actuator_code": self.actuator_edit.text().strip(),
            "driver_model": self.driver_edit.text().strip(),
            "port_url": self.port_edit.text().strip(),
            "load_inertia_kgm2": self.inertia_spin.value(),
            "notes": self.notes_edit.text(),
            "serial_number": self.serial_edit.text().strip(),
        }
