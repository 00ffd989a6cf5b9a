"""Pages that work without a drive: sizing, the connect dialog, layout memory, pairing warning."""

from __future__ import annotations

from PySide6.QtCore import QSettings

from fha_studio.gui.connect_dialog import ConnectDialog
from fha_studio.hardware.sim import SimDrive


def test_sizing_page_adds_parts_checks_and_suggests(make_window, qtbot):
    window = make_window()
    page = window.show_page("sizing")
    # no drive, no actuator yet: what the duty passes on is listed, nothing is sized
    qtbot.waitUntil(lambda: bool(page.suggested), timeout=10000)
    assert page.result is None and "No actuator" in page.verdict.text()
    page.actuator_combo.setCurrentText("FHA-25C-50-US250")
    page.actuator_combo.lineEdit().returnPressed.emit()
    assert window.state.actuator_code == "FHA-25C-50-US250"  # the axis's actuator, for every page
    qtbot.waitUntil(lambda: page.result is not None, timeout=10000)
    page.shape_combo.setCurrentIndex(page.shape_combo.findData("cylinder"))
    page.dim_spins["radius_m"].setValue(150.0)
    page.dim_spins["length_m"].setValue(20.0)
    shape, inertia = page.current_part()
    assert abs(inertia - shape.mass_kg * 0.15**2 / 2) < 1e-9  # about its own axis, no offset
    page.add_part()
    assert abs(page.inertia_spin.value() - inertia) < 1e-4
    assert page.checks_table.rowCount() == len(page.result.checks)
    assert page.suggested and "passes" in page.verdict.text()
    page.cycle_spin.setValue(0.2)  # far too short a cycle for the effective torque
    page.calculate()
    assert "fails" in page.verdict.text()
    texts = [page.checks_table.item(r, 3).text() for r in range(page.checks_table.rowCount())]
    assert "FAIL" in texts


def test_connect_dialog_defaults_to_the_simulated_drive_and_remembers(qtbot):
    dialog = ConnectDialog(ports=[("/dev/ttyUSB0", "FT232R USB UART")])
    qtbot.addWidget(dialog)
    assert dialog.sim_radio.isChecked()
    assert dialog.url() == "sim://FHA-25C-50-US250?catalogue_friction=1"  # a realistic axis
    assert dialog.baud_rate() == 19200
    assert dialog.port_combo.itemText(0) == "/dev/ttyUSB0 — FT232R USB UART"
    dialog.address_radio.setChecked(True)
    dialog._accept()
    assert "Type a device" in dialog.problem_label.text()  # nothing typed: refused, stays open
    dialog.address_edit.setText("socket://127.0.0.1:5020")
    dialog._accept()
    assert dialog.result() == ConnectDialog.DialogCode.Accepted
    again = ConnectDialog(ports=[])
    qtbot.addWidget(again)
    assert again.address_radio.isChecked() and again.url() == "socket://127.0.0.1:5020"


def test_connect_dialog_offers_the_simulated_drive_as_a_real_ha655_and_remembers_it(qtbot):
    """A trainee picks the simulated drive of the manual's commands (DGR, OWW; CN3 silent while
    the servo is on) in the dialog, not only with --url on the command line."""
    dialog = ConnectDialog(ports=[], load_inertia_kgm2=0.5)
    qtbot.addWidget(dialog)
    assert not dialog.sim_documented.isChecked()
    dialog.address_radio.setChecked(True)
    dialog.sim_documented.setChecked(True)  # the simulated drive is meant
    assert dialog.sim_radio.isChecked()
    assert dialog.url() == "sim://FHA-25C-50-US250?load_inertia=0.5&catalogue_friction=1&profile=documented"
    dialog._accept()
    again = ConnectDialog(ports=[])
    qtbot.addWidget(again)
    assert again.sim_documented.isChecked()
    assert again.url() == "sim://FHA-25C-50-US250?catalogue_friction=1&profile=documented"


def test_connect_dialog_offers_the_catalogue_friction_on_by_default_and_remembers_it(qtbot):
    """The simulated drive a person connects to stops like a real axis: the friction the catalogue
    gives (TF, 2-4-4) is on unless they turn it off, and the dialog says what it is."""
    dialog = ConnectDialog(ports=[], load_inertia_kgm2=1.5)
    qtbot.addWidget(dialog)
    assert dialog.sim_friction.isChecked()
    assert "Friction as the catalogue gives it (TF, 2-4-4)" in dialog.sim_friction.text().replace("&", "")
    assert "TF = KT × Im − TM" in dialog.sim_friction.toolTip()
    with SimDrive.from_url(dialog.url() + "&stepped=1") as drive:  # the drive that address builds
        assert drive.model.effects.enabled() == ["coulomb_friction", "viscous_friction"]
        assert drive.model.load_inertia_kgm2 == 1.5
    dialog.address_radio.setChecked(True)
    dialog.sim_friction.setChecked(False)  # a frictionless axis: the simulated drive is meant
    assert dialog.sim_radio.isChecked()
    assert dialog.url() == "sim://FHA-25C-50-US250?load_inertia=1.5"
    with SimDrive.from_url(dialog.url() + "&stepped=1") as drive:
        assert drive.model.effects.enabled() == []
    dialog._accept()
    again = ConnectDialog(ports=[])
    qtbot.addWidget(again)
    assert not again.sim_friction.isChecked() and again.url() == "sim://FHA-25C-50-US250"


def test_a_window_connected_without_an_address_gets_the_catalogue_friction(make_window):
    """fha-studio without --url connects to the embedded drive as the dialog's default has it."""
    window = make_window(show=False)
    window.state.set_load_inertia(0.5)
    opened = []
    window.link.open = lambda url, baud: opened.append(url)
    assert window.connect_to()
    assert opened == ["sim://FHA-25C-50-US250?load_inertia=0.5&catalogue_friction=1"]


def test_window_layout_and_page_are_remembered(make_window):
    window = make_window()
    window.resize(1024, 600)  # narrower than its minimum width would be clamped
    window.show_page("alarms")
    window.save_layout()
    assert QSettings().value("window/page") == "alarms"  # by name: tab order may change
    second = make_window()
    assert second.tabs.currentIndex() == 3
    assert second.size().height() == 600  # not the default 720


def test_pairing_warning_must_be_acknowledged(make_window, qtbot):
    from tests.gui.fake_drive import FakeDriveClient

    fake = FakeDriveClient()  # driver HA-655-2-200, ADJUSTED FOR USE WITH FHA-25C-50-US250
    window = make_window(open_client=lambda url, baud: fake, connect="fake://")
    page = window.connection_page
    assert not page.warning_pending  # the label's actuator was taken over: no warning
    assert page.warning_label.isVisible()  # but a positive result, saying what was checked
    assert page.warning_label.text().startswith("✓ The pair is right: HA-655-2-200 is adjusted for")
    page.actuator_combo.setCurrentText("FHA-32C-50-US250")
    page.check_pairing()
    assert page.warning_pending
    text = page.warning_label.text()
    assert "ADJUSTED FOR USE WITH FHA-25C-50-US250" in text and "HA-655-4-200" in text
    assert not window.state.actuator_acknowledged
    page.acknowledge()
    assert not page.warning_pending and window.state.actuator_acknowledged


def test_sizing_says_which_assumption_decides_and_takes_an_acceleration_time(make_window, qtbot):
    """FHA-25C-50 fails the effective torque at its own maximum torque (the manual's method) where
    a smaller frame passes; the page says so, and with the machine's acceleration time it passes.
    Calculate stays in sight at 1366x768."""
    window = make_window()
    window.resize(1366, 740)
    window.state.set_actuator("FHA-25C-50-US250")
    window.state.set_load_inertia(1.2)
    page = window.show_page("sizing")
    page.speed_spin.setValue(40.0)
    page.angle_spin.setValue(120.0)
    page.cycle_spin.setValue(1.5)
    page.calculate()
    qtbot.waitUntil(lambda: page.result is not None, timeout=10000)
    assert any(c.name == "effective torque" and not c.ok for c in page.result.checks)
    assert "at the maximum torque TM = 150 N·m" in page.assumption.text()
    assert page.accel_spin.text() == "at the maximum torque (2-4-4)"
    page.accel_spin.setValue(0.15)
    page.calculate()
    assert page.result.ok and "in the given 0.15 s" in page.assumption.text()
    assert not page.calculate_button.visibleRegion().isEmpty()
