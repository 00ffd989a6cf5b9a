"""The connect dialog: the embedded simulated drive (default), a serial port found on the machine,
or an address typed by hand (pty path, socket://). Remembers the last choice."""

from __future__ import annotations

from PySide6.QtCore import QSettings, Slot
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QLabel,
    QLineEdit,
    QPushButton,
    QRadioButton,
    QVBoxLayout,
    QWidget,
)

from fha_studio.catalog import DEFAULT_ACTUATOR, all_model_codes
from fha_studio.gui.forms import child, load_form
from fha_studio.hardware.protocol import BAUD_RATES, BAUDRATE


def list_serial_ports() -> list[tuple[str, str]]:
    """(device, description) of the serial ports found, e.g. ('/dev/ttyUSB0', 'FT232R USB UART')."""
    try:
        from serial.tools import list_ports
    except ImportError:
        return []
    found = []
    for port in sorted(list_ports.comports(), key=lambda p: p.device):
        description = port.description if port.description and port.description != "n/a" else ""
        found.append((port.device, description))
    return found


def catalogue_codes() -> list[str]:
    """The model codes of the catalogue (FHA-C manual 1-3), to offer in the actuator boxes."""
    return all_model_codes()


#: A person's simulated drive has the friction the catalogue gives (TF, 2-4-4) unless they
#: untick it: the tool's default axis is a realistic one (a bare sim:// is frictionless).
SIM_FRICTION_BY_DEFAULT = True


def sim_url(actuator_code: str, load_inertia_kgm2: float = 0.0, documented: bool = False,
            catalogue_friction: bool = SIM_FRICTION_BY_DEFAULT, **options: str) -> str:
    """The embedded simulated drive for ``actuator_code`` with the declared load inertia [kg m^2]
    on its output (none when 0); ``documented``: its profile of a real HA-655 (DGR and OWW only);
    ``catalogue_friction``: the friction the catalogue gives (TF, 2-4-4); ``options``: any other
    sim:// option (docs/sim.md), e.g. ``paced="0"``, added as given."""
    query = ([f"load_inertia={load_inertia_kgm2!r}"] if load_inertia_kgm2 > 0 else []) + (
        ["catalogue_friction=1"] if catalogue_friction else []) + (
        ["profile=documented"] if documented else []) + [f"{key}={value}" for key, value in options.items()]
    url = f"sim://{actuator_code.strip().upper()}"
    return f"{url}?{'&'.join(query)}" if query else url


class ConnectDialog(QDialog):
    """Asks where the drive is. `url()` and `baud_rate()` give the answer after exec().

    ``load_inertia_kgm2``: the axis's declared load inertia, put on the simulated drive's output."""

    def __init__(self, parent: QWidget | None = None, ports: list[tuple[str, str]] | None = None,
                 load_inertia_kgm2: float = 0.0):
        super().__init__(parent)
        self.load_inertia_kgm2 = load_inertia_kgm2
        self.setWindowTitle("Connect to a drive")
        self.form = load_form("connect_dialog.ui", self)
        layout = QVBoxLayout(self)
        layout.addWidget(self.form)
        self.buttons = QDialogButtonBox(
            QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel
        )
        self.buttons.button(QDialogButtonBox.StandardButton.Ok).setText("C&onnect")
        self.buttons.accepted.connect(self._accept)
        self.buttons.rejected.connect(self.reject)
        layout.addWidget(self.buttons)
        self.sim_radio = child(self.form, QRadioButton, "simRadio")
        self.serial_radio = child(self.form, QRadioButton, "serialRadio")
        self.address_radio = child(self.form, QRadioButton, "addressRadio")
        self.sim_actuator = child(self.form, QComboBox, "simActuatorCombo")
        self.sim_friction = child(self.form, QCheckBox, "simFrictionCheck")
        self.sim_documented = child(self.form, QCheckBox, "simDocumentedCheck")
        self.port_combo = child(self.form, QComboBox, "portCombo")
        self.refresh_button = child(self.form, QPushButton, "refreshButton")
        self.address_edit = child(self.form, QLineEdit, "addressEdit")
        self.baud_combo = child(self.form, QComboBox, "baudCombo")
        self.problem_label = child(self.form, QLabel, "problemLabel")
        self.sim_actuator.addItems(catalogue_codes())
        for rate in BAUD_RATES:
            self.baud_combo.addItem(str(rate), rate)
        if len(BAUD_RATES) == 1:  # nothing to choose: say why
            self.baud_combo.setEnabled(False)
            self.baud_combo.setToolTip(f"CN3 runs at {BAUDRATE} bit/s and at no other rate")
        self.refresh_button.clicked.connect(lambda: self.refresh_ports())
        self.port_combo.activated.connect(lambda: self.serial_radio.setChecked(True))
        self.address_edit.textEdited.connect(lambda: self.address_radio.setChecked(True))
        self.sim_actuator.activated.connect(lambda: self.sim_radio.setChecked(True))
        self.sim_friction.toggled.connect(lambda: self.sim_radio.setChecked(True))
        self.sim_documented.toggled.connect(lambda: self.sim_radio.setChecked(True))
        self.refresh_ports(ports)
        self._restore()
        self.resize(max(self.width(), 600), self.sizeHint().height())

    @Slot()
    def refresh_ports(self, ports: list[tuple[str, str]] | None = None) -> None:
        ports = list_serial_ports() if ports is None else ports
        current = self.port_combo.currentData()
        self.port_combo.clear()
        for device, description in ports:
            self.port_combo.addItem(f"{device} — {description}" if description else device, device)
        if not ports:
            self.port_combo.addItem("(no serial port found)", None)
        index = self.port_combo.findData(current)
        if index >= 0:
            self.port_combo.setCurrentIndex(index)

    def _restore(self) -> None:
        settings = QSettings()
        kind = str(settings.value("connect/kind", "sim"))
        actuator = settings.value("connect/actuator", DEFAULT_ACTUATOR)
        self.sim_actuator.setCurrentText(str(actuator))
        default_friction = "true" if SIM_FRICTION_BY_DEFAULT else "false"
        self.sim_friction.setChecked(str(settings.value("connect/sim_friction", default_friction)) == "true")
        self.sim_documented.setChecked(str(settings.value("connect/sim_documented", "false")) == "true")
        port = settings.value("connect/port", "")
        index = self.port_combo.findData(port)
        if index >= 0:
            self.port_combo.setCurrentIndex(index)
        self.address_edit.setText(str(settings.value("connect/address", "")))
        baud = int(str(settings.value("connect/baud", BAUDRATE)))
        self.baud_combo.setCurrentIndex(max(0, self.baud_combo.findData(baud)))
        {"serial": self.serial_radio, "address": self.address_radio}.get(kind, self.sim_radio).setChecked(
            True
        )

    def _save(self) -> None:
        settings = QSettings()
        kind = (
            "serial"
            if self.serial_radio.isChecked()
            else "address"
            if self.address_radio.isChecked()
            else "sim"
        )
        settings.setValue("connect/kind", kind)
        settings.setValue("connect/actuator", self.sim_actuator.currentText().strip())
        settings.setValue("connect/sim_friction", "true" if self.sim_friction.isChecked() else "false")
        settings.setValue("connect/sim_documented", "true" if self.sim_documented.isChecked() else "false")
        if self.port_combo.currentData():
            settings.setValue("connect/port", self.port_combo.currentData())
        settings.setValue("connect/address", self.address_edit.text().strip())
        settings.setValue("connect/baud", self.baud_rate())

    def problem(self) -> str:
        """What is wrong with the choice, or '' when it can be tried."""
        if self.serial_radio.isChecked() and not self.port_combo.currentData():
            return "No serial port is selected. Plug in the adapter and press Refresh, or type an address."
        if self.address_radio.isChecked() and not self.address_edit.text().strip():
            return "Type a device or pty path (/dev/pts/5) or a socket://host:port address."
        if self.sim_radio.isChecked() and not self.sim_actuator.currentText().strip():
            return "Choose the actuator the simulated drive should drive."
        return ""

    def url(self) -> str:
        if self.serial_radio.isChecked():
            return str(self.port_combo.currentData())
        if self.address_radio.isChecked():
            return self.address_edit.text().strip()
        return sim_url(self.sim_actuator.currentText(), self.load_inertia_kgm2,
                       documented=self.sim_documented.isChecked(),
                       catalogue_friction=self.sim_friction.isChecked())

    def baud_rate(self) -> int:
        return int(self.baud_combo.currentData() or BAUDRATE)

    @Slot()
    def _accept(self) -> None:
        problem = self.problem()
        self.problem_label.setText(problem)
        if problem:
            return
        self._save()
        self.accept()
