"""One commissioning state for the whole window: what is typed once (the actuator, the load
inertia) is what every page uses, and what is derived from it follows at once when it changes."""

from __future__ import annotations

import numpy as np
import pytest

from fha_studio.gui.connect_dialog import ConnectDialog
from fha_studio.gui.link import MoveBy, Servo
from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.sim.options import config_from_url
from fha_studio.hardware.transport import pipe_pair
from fha_studio.recording import RecordingMetadata, make_recording, read_recording, write_recording
from tests.support.documented import DocumentedDrive
from tests.support.scripted import ScriptedDrive

DGR_COUNTS = -40000  # motor encoder counts, 8192 per motor turn


@pytest.fixture
def documented_drive():
    """Factory: open_client for make_window, a drive of the manual's command set that answers DGR
    with DGR_COUNTS (servo off), as a real HA-655 does."""
    drives = []

    def open_client(url, baud):
        host, end = pipe_pair("documented")
        drives.append(ScriptedDrive(end, DocumentedDrive(position=DGR_COUNTS)))
        return DriveClient.attach(host)

    yield open_client
    for drive in drives:
        drive.close()


def type_actuator(window, code: str) -> None:
    """What the technician does on the Connection page: type the label's code, check the pairing."""
    page = window.connection_page
    page.actuator_combo.setCurrentText(code)
    page.check_pairing()
    assert window.state.actuator_code == code


def test_counts_are_scaled_with_the_actuator_typed_after_connecting(make_window, qtbot, documented_drive):
    window = make_window(open_client=documented_drive, connect="documented://")
    view = window.show_page("scope").view
    qtbot.waitUntil(lambda: view.controller.connected, timeout=10000)
    type_actuator(window, "FHA-32C-100-S248")  # connect first, then the model code (the README's order)
    view.start_live()
    qtbot.waitUntil(lambda: view._live is not None and len(view._live.ring) > 0, timeout=15000)
    position_deg = view._live.ring.window(1)[0, 1]
    assert position_deg == pytest.approx(DGR_COUNTS * 360 / (8192 * 100))  # -17.6 deg, not -35.2
    assert round(position_deg, 1) == -17.6


def test_a_live_scope_rescales_at_once_when_the_actuator_changes(make_window, qtbot, documented_drive):
    window = make_window(open_client=documented_drive, connect="documented://")
    view = window.show_page("scope").view
    qtbot.waitUntil(lambda: view.controller.connected, timeout=10000)
    type_actuator(window, "FHA-25C-50-S248")
    view.start_live()

    def latest_deg() -> float | None:
        live = view._live
        return float(live.ring.window(1)[0, 1]) if live is not None and len(live.ring) else None

    qtbot.waitUntil(lambda: latest_deg() == pytest.approx(DGR_COUNTS * 360 / (8192 * 50)), timeout=15000)
    type_actuator(window, "FHA-32C-100-S248")  # while watching: the view goes on, at the new ratio
    qtbot.waitUntil(lambda: latest_deg() == pytest.approx(DGR_COUNTS * 360 / (8192 * 100)), timeout=15000)
    assert view.live_button.isChecked()


def test_jog_page_scales_position_pulses_with_the_actuator_typed_after_connecting(make_window, qtbot):
    window = make_window(connect="sim://FHA-25C-50-US250?paced=0")
    link = window.link
    link.send(Servo(True))
    qtbot.waitUntil(lambda: link.servo_on, timeout=10000)
    with qtbot.waitSignal(link.sigResult, check_params_cb=lambda r: r.answers(MoveBy), timeout=10000):
        link.send(MoveBy(30.0))
    qtbot.waitUntil(lambda: link.status.position_pulse and link.status.position_pulse > 40000, timeout=15000)
    type_actuator(window, "FHA-32C-100-US250")  # another actuator: 1 000 000 pulses per output turn
    page = window.show_page("jog")

    def shows_the_new_scale() -> bool:
        pulses = link.status.position_pulse
        return f"{pulses * 360.0 / 1_000_000:.2f} °" in page.position_label.text()

    qtbot.waitUntil(shows_the_new_scale, timeout=10000)


def test_a_recording_carries_the_declared_load_inertia_and_the_supply_voltage(make_window, qtbot, tmp_path):
    window = make_window(connect="sim://FHA-17C-50-US250-A?paced=0")  # option A: AC100V
    assert window.state.actuator_code == "FHA-17C-50-US250-A"  # from the label, through the state
    sizing = window.show_page("sizing")
    sizing.inertia_spin.setValue(0.75)  # declared once, on the sizing page
    view = window.show_page("scope").view
    qtbot.waitUntil(lambda: view.controller.connected, timeout=10000)
    view.start_live()
    qtbot.waitUntil(lambda: view.indicator_text() == "LIVE", timeout=15000)
    view.start_recording(tmp_path / "live.csv")
    qtbot.waitUntil(lambda: view._recorder.rows_written > 20, timeout=15000)
    metadata = read_recording(view.stop_recording()).metadata
    assert metadata.actuator == "FHA-17C-50-US250-A"
    assert metadata.load_inertia_kgm2 == pytest.approx(0.75)
    assert metadata.supply_voltage == 100


def test_the_load_inertia_typed_once_is_what_every_page_uses(make_window, qtbot, tmp_path):
    window = make_window()
    type_actuator(window, "FHA-25C-50-US250")
    sizing = window.show_page("sizing")
    qtbot.waitUntil(lambda: sizing.result is not None, timeout=10000)
    sizing.inertia_spin.setValue(1.25)
    assert window.state.load_inertia_kgm2 == pytest.approx(1.25)
    assert sizing.duty().load_inertia_kgm2 == pytest.approx(1.25)
    scope = window.show_page("scope").view
    assert scope.load_inertia.value() == pytest.approx(1.25)
    assert scope._metadata(None).load_inertia_kgm2 == pytest.approx(1.25)
    check = window.show_page("modelcheck")
    assert check.inertia_spin.value() == pytest.approx(1.25)
    # a recording that declares another load: the model check uses the axis's declaration
    path = tmp_path / "old.csv"
    t_s = np.arange(200) / 1000.0
    write_recording(path, make_recording(RecordingMetadata("FHA-25C-50-US250", 0.0, sample_rate_hz=1000.0),
                                         t=t_s, pos=np.zeros_like(t_s), current=np.zeros_like(t_s)))
    check.load_recording(path)
    assert check.declared_recording().metadata.load_inertia_kgm2 == pytest.approx(1.25)
    assert "axis's declared load inertia, 1.25" in check.source_label.text()
    # edited on the scope page: every page follows at once
    scope.load_inertia.setValue(2.5)
    assert window.state.load_inertia_kgm2 == pytest.approx(2.5)
    assert check.inertia_spin.value() == pytest.approx(2.5)
    assert sizing.inertia_spin.value() == pytest.approx(2.5)
    assert check.declared_recording().metadata.load_inertia_kgm2 == pytest.approx(2.5)
    window.show_page("sizing")
    qtbot.waitUntil(lambda: sizing.result is not None and sizing.result.duty.load_inertia_kgm2 == 2.5,
                    timeout=10000)
    # the simulated drive the GUI builds carries the same load
    dialog = ConnectDialog(window, ports=[], load_inertia_kgm2=window.state.load_inertia_kgm2)
    dialog.sim_radio.setChecked(True)
    assert config_from_url(dialog.url()).load_inertia_kgm2 == 2.5
    dialog.deleteLater()


def test_the_sizing_page_never_shows_the_previous_actuators_result(make_window, qtbot):
    window = make_window(connect="sim://FHA-25C-50-US250?paced=0")
    sizing = window.show_page("sizing")
    qtbot.waitUntil(lambda: sizing.result is not None, timeout=10000)
    assert sizing.result.actuator_code == "FHA-25C-50-US250"
    window.show_page("connection")
    type_actuator(window, "FHA-32C-100-US250")
    assert sizing.result is None or sizing.result.actuator_code == "FHA-32C-100-US250"
    assert "FHA-25C-50-US250" not in sizing.verdict.text()
    window.show_page("sizing")
    qtbot.waitUntil(lambda: sizing.result is not None, timeout=10000)
    assert sizing.result.actuator_code == "FHA-32C-100-US250"
    assert "FHA-32C-100-US250" in sizing.verdict.text()
    assert sizing.actuator_combo.currentText() == "FHA-32C-100-US250"
    # changed while the sizing page is on show (an opened procedure session, say): sized at once
    window.state.set_actuator("FHA-17C-50-US250")
    assert sizing.result.actuator_code == "FHA-17C-50-US250"


def test_the_adapter_signals_changes_made_on_the_model_and_lets_go_when_deleted(qtbot):
    from PySide6.QtCore import QCoreApplication, QEvent

    from fha_studio.gui.state import AxisState
    from fha_studio.logic.commissioning import CommissioningState

    model = CommissioningState()  # e.g. an axis of a machine project, outliving its window
    state = AxisState(model)
    inertia: list[float] = []
    actuators: list[str] = []
    state.sigLoadInertiaChanged.connect(inertia.append)
    state.sigActuatorChanged.connect(actuators.append)
    model.set_load_inertia(1.5)
    model.set_actuator("FHA-40C-160-S248")
    assert inertia == [1.5] and actuators == ["FHA-40C-160-S248"] and state.ratio == 160
    state.deleteLater()
    QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete.value)
    model.set_load_inertia(2.0)  # the deleted adapter is no longer a listener: nothing raises
    assert inertia == [1.5]
