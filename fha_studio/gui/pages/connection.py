"""Connection page: which drive, which actuator, and whether they belong together."""

from __future__ import annotations

from PySide6.QtCore import QSettings, Qt, Slot
from PySide6.QtWidgets import (
    QComboBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QVBoxLayout,
)

from fha_studio.gui.connect_dialog import catalogue_codes
from fha_studio.gui.link import LinkInfo
from fha_studio.gui.pages.base import BasePage
from fha_studio.gui.session import Session
from fha_studio.hardware.sim.options import drive_words
from fha_studio.logic.pairing import PairingCheck


def _value_label() -> QLabel:
    label = QLabel("—")
    label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
    label.setWordWrap(True)
    return label


#: The order of the work on a drive FHA Studio reads and writes over CN3.
COMMISSIONING_ORDER = (
    "<b>Commissioning order</b>: 1. connect · 2. check the actuator against the driver label · "
    "3. <i>Parameters</i>: read all (a backup is saved before the first write) · "
    "4. <i>Rotary direction</i>: set and check it · 5. <i>Jog &amp; test run</i> · "
    "6. <i>Alarms</i>: clear what is left · 7. <i>Parameters</i>: save the parameter file."
)
#: The same on a drive of the manual's commands (no parameters, jog or alarms over CN3): the
#: front panel, the controller and CN2 do what CN3 cannot.
COMMISSIONING_ORDER_PANEL = (
    "<b>Commissioning order</b> (this drive gives no parameter access and no jog over CN3): "
    "1. connect · 2. check the actuator against the driver label · "
    "3. <i>Parameters</i>: read each item on the drive's front panel and enter it · "
    "4. <i>DGR checks</i> (absolute encoder): the encoder, the rotary direction with the "
    "controller's FWD command, the sensor dogs, the absolute origin · "
    "5. <i>Scope</i> → <i>Bench</i>: watch the controller's moves on CN2 · "
    "6. <i>Alarms</i>: enter the front panel's code · "
    "7. <i>Parameters</i>: save the parameter file."
)


class ConnectionPage(BasePage):
    """Drive identity, the actuator code and the pairing check."""

    def __init__(self, session: Session, main_window=None):
        super().__init__()
        self.session = session
        self.main_window = main_window
        self.pairing: PairingCheck | None = None
        layout = QVBoxLayout(self)

        drive_box = QGroupBox("Drive")
        form = QFormLayout(drive_box)
        self.link_label = _value_label()
        self.driver_label = _value_label()
        self.adjusted_label = _value_label()
        self.firmware_label = _value_label()
        self.caps_label = _value_label()
        form.addRow("Link:", self.link_label)
        form.addRow("Driver model (TYPE):", self.driver_label)
        form.addRow("ADJUSTED FOR USE WITH:", self.adjusted_label)
        form.addRow("Firmware:", self.firmware_label)
        form.addRow("The drive supports:", self.caps_label)
        buttons = QHBoxLayout()
        self.connect_button = QPushButton("&Connect…")
        self.connect_button.setToolTip(
            "Choose the embedded simulated drive, a serial port or an address (Ctrl+K)"
        )
        self.disconnect_button = QPushButton("Dis&connect")
        buttons.addWidget(self.connect_button)
        buttons.addWidget(self.disconnect_button)
        buttons.addStretch(1)
        form.addRow(buttons)
        layout.addWidget(drive_box)

        actuator_box = QGroupBox("Actuator on the axis")
        a_layout = QVBoxLayout(actuator_box)
        row = QHBoxLayout()
        label = QLabel("Model code from the actuator's &label:")
        self.actuator_combo = QComboBox()
        self.actuator_combo.setEditable(True)
        self.actuator_combo.setInsertPolicy(QComboBox.InsertPolicy.NoInsert)
        self.actuator_combo.addItems(catalogue_codes())
        self.actuator_combo.setCurrentText("")
        self.actuator_combo.lineEdit().setPlaceholderText(
            "e.g. FHA-25C-50-US250-B (type it, or pick from the catalogue)"
        )
        self.actuator_combo.setMinimumWidth(320)
        label.setBuddy(self.actuator_combo)
        self.check_button = QPushButton("C&heck pairing")
        row.addWidget(label)
        row.addWidget(self.actuator_combo, 1)
        row.addWidget(self.check_button)
        a_layout.addLayout(row)
        self.actuator_summary = QLabel("")
        self.actuator_summary.setWordWrap(True)
        self.actuator_summary.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        a_layout.addWidget(self.actuator_summary)
        self.warning_label = QLabel("")
        self.warning_label.setObjectName("pairingWarning")
        self.warning_label.setWordWrap(True)
        self.warning_label.setVisible(False)
        a_layout.addWidget(self.warning_label)
        ack_row = QHBoxLayout()
        self.ack_button = QPushButton("I have checked the labels: &acknowledge this warning")
        self.ack_button.setVisible(False)
        ack_row.addWidget(self.ack_button)
        ack_row.addStretch(1)
        a_layout.addLayout(ack_row)
        layout.addWidget(actuator_box)

        self.order_hint = QLabel(COMMISSIONING_ORDER)
        self.order_hint.setObjectName("commissioningOrder")
        self.order_hint.setWordWrap(True)
        layout.addWidget(self.order_hint)
        layout.addStretch(1)

        if main_window is not None:
            self.connect_button.clicked.connect(main_window.show_connect_dialog)
            self.disconnect_button.clicked.connect(main_window.disconnect_drive)
        self.check_button.clicked.connect(self.check_pairing)
        self.actuator_combo.lineEdit().returnPressed.connect(self.check_pairing)
        self.actuator_combo.activated.connect(lambda _i: self.check_pairing())
        self.ack_button.clicked.connect(self.acknowledge)
        session.state.sigActuatorChanged.connect(self._on_actuator_changed)
        self.link_disconnected("not connected", False)

    # -- settings ---------------------------------------------------------------------------------
    def restore_settings(self, settings: QSettings) -> None:
        code = settings.value("session/actuator", "")
        if code and not self.session.state.actuator_code:
            self.actuator_combo.setCurrentText(str(code))

    def save_settings(self, settings: QSettings) -> None:
        if self.session.state.actuator_code:
            settings.setValue("session/actuator", self.session.state.actuator_code)

    # -- behaviour --------------------------------------------------------------------------------
    def link_connected(self, info: LinkInfo) -> None:
        # an embedded drive in words (its address, options and all, is the tooltip's)
        self.link_label.setText(drive_words(info.url, detail=True))
        self.link_label.setToolTip(f"Address: {info.url}")
        self.driver_label.setText(info.driver_model or "not reported by this drive")
        self.adjusted_label.setText(info.adjusted_for or "not reported: read it from the driver's label")
        self.firmware_label.setText(info.firmware or "—")
        self.caps_label.setText(info.capabilities or "—")
        self.order_hint.setText(COMMISSIONING_ORDER if info.can_parameters else COMMISSIONING_ORDER_PANEL)
        self.disconnect_button.setEnabled(True)
        if not self.actuator_combo.currentText().strip() and info.adjusted_for:
            self.actuator_combo.setCurrentText(info.adjusted_for)
        if self.actuator_combo.currentText().strip():
            self.check_pairing()

    def link_disconnected(self, reason: str, lost: bool) -> None:
        if lost:
            self.link_label.setText(f"LINK LOST: {reason}")
        else:  # "not connected" is said once
            self.link_label.setText("not connected" + ("" if reason == "not connected" else f": {reason}"))
            self.link_label.setToolTip("")
        self.link_label.setStyleSheet("color: #b00020; font-weight: bold;" if lost else "")
        self.disconnect_button.setEnabled(False)

    @Slot(str)
    def _on_actuator_changed(self, code: str) -> None:
        # another page (or a resumed procedure session) changed the actuator: show it, check again
        if self.actuator_combo.currentText().strip().upper() != code:
            self.actuator_combo.setCurrentText(code)
            if code:
                self.check_pairing()
            else:
                self.actuator_summary.setText("")
                self._show_warning("")

    @Slot()
    def check_pairing(self) -> None:
        from fha_studio.logic.pairing import check_pairing

        code = self.actuator_combo.currentText().strip().upper()
        state = self.session.state
        if not code:
            self._show_warning("")
            return
        try:
            result = check_pairing(code, state.driver_model, state.adjusted_for)
        except (ValueError, ImportError) as exc:
            self.actuator_summary.setText("")
            self._show_warning(f"<b>{code}</b> is not a model code the catalogue knows: {exc}", can_ack=False)
            return
        self.pairing = result
        self.actuator_summary.setText(self._summary(code, result))
        # a warning acknowledged for this actuator stays acknowledged when the check is repeated
        acknowledged = result.ok or (state.actuator_code == code and state.actuator_acknowledged)
        self.session.state.set_actuator(code, acknowledged=acknowledged)
        if acknowledged and not result.ok:
            self._show_warning("<br>".join(f"⚠ {w}" for w in result.warnings))
            self._show_acknowledged()
            return
        if result.ok:
            self._show_pairing_ok(code, state.driver_model, state.adjusted_for)
        else:
            self._show_warning("<br>".join(f"⚠ {w}" for w in result.warnings))

    def _summary(self, code: str, result) -> str:
        try:
            from fha_studio.catalog import get_actuator

            a = get_actuator(code)
            text = (
                f"<b>{code}</b>: max torque {a.max_torque_nm:g} N·m, max speed {a.max_speed_rpm:g} r/min, "
                f"ratio {a.ratio}, output resolution {a.output_resolution_ppr:,} pulse/rev."
            )
        except Exception:
            text = f"<b>{code}</b>"
        if result.compatible_drivers:
            text += f" Drivers for it (manual 1-3): {', '.join(result.compatible_drivers)}."
        return text

    def _show_pairing_ok(self, code: str, driver_model: str, adjusted_for: str) -> None:
        """A pair that passes says so (green); without the driver's label lines it says what was
        checked and what is still to check by eye."""
        if driver_model and adjusted_for:
            text = (
                f"✓ The pair is right: {driver_model} is adjusted for {adjusted_for} and is a "
                f"driver for {code} in the manual's combination table (1-3)."
            )
        elif driver_model or adjusted_for:
            told = driver_model or f"adjusted for {adjusted_for}"
            text = (
                f"✓ Nothing wrong found: the drive reports {told}. Compare the other line of the "
                "driver's label (TYPE and ADJUSTED FOR USE WITH) with the actuator by eye (manual 3-1)."
            )
        else:
            text = (
                f"✓ {code} is a valid model code. This drive does not report its label: compare the "
                "driver's TYPE and ADJUSTED FOR USE WITH lines with the actuator by eye (manual 3-1)."
            )
        self.warning_label.setText(text)
        self.warning_label.setVisible(True)
        self.warning_label.setStyleSheet(
            "background: #e6f4e7; color: #176b1d; border: 1px solid #5aa65f; padding: 6px; "
            "border-radius: 4px;"
        )
        self.ack_button.setVisible(False)

    def _show_warning(self, html: str, can_ack: bool = True) -> None:
        self.warning_label.setText(html)
        self.warning_label.setVisible(bool(html))
        self.warning_label.setStyleSheet(
            "background: #fff3cd; color: #5c3c00; border: 1px solid #e0a000; padding: 6px; "
            "border-radius: 4px;"
        )
        self.ack_button.setVisible(bool(html) and can_ack)
        self.ack_button.setEnabled(True)
        self.ack_button.setText("I have checked the labels: &acknowledge this warning")

    @Slot()
    def acknowledge(self) -> None:
        self.session.state.set_actuator(self.actuator_combo.currentText(), acknowledged=True)
        self._show_acknowledged()

    def _show_acknowledged(self) -> None:
        self.ack_button.setEnabled(False)
        self.ack_button.setText("Acknowledged for this session")
        self.warning_label.setStyleSheet(
            "background: #f1f1f1; color: #5c3c00; border: 1px solid #bbb; padding: 6px; border-radius: 4px;"
        )

    @property
    def warning_pending(self) -> bool:
        return self.warning_label.isVisible() and self.ack_button.isVisible() and self.ack_button.isEnabled()
