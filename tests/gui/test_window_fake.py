"""The main window against a fake in-memory drive (fast; independent of the simulated drive).

The same behaviour is driven against the embedded simulated drive in test_window_sim.py."""

from __future__ import annotations

import re

import pytest
from PySide6.QtCore import Qt

from fha_studio.gui.link import Servo
from fha_studio.hardware.protocol import Command
from tests.gui.fake_drive import FakeDriveClient


@pytest.fixture
def fake():
    return FakeDriveClient()


@pytest.fixture
def window(make_window, fake, qtbot):
    w = make_window(open_client=lambda url, baud: fake, connect="fake://drive")
    qtbot.waitUntil(lambda: bool(w.state.drive_values), timeout=10000)
    return w


def test_connects_and_reads_parameters(window):
    assert window.link_lamp.state is True
    assert "HA-655-2-200" in window.connection_page.driver_label.text()
    assert window.parameters_page.model.rowCount() > 5
    assert window.state.drive_values[("system", 8)] == 0


def test_out_of_range_value_is_refused_at_the_field(window, qtbot):
    model = window.parameters_page.model
    row = model.row_of("in_position_range")
    index = model.index(row, 3)
    with qtbot.waitSignal(model.sigRefused) as refused:
        assert not model.setData(index, "123456")
    assert "0 … 9999" in refused.args[0]
    assert "0 … 9999" in window.parameters_page.message.text()
    assert not model.edits


def test_edit_write_changed_verifies_and_logs_with_backup_first(window, fake, qtbot):
    page = window.parameters_page
    model = page.model
    index = model.index(model.row_of("in_position_range"), 3)
    assert model.setData(index, "25")
    assert "edited, not written" in model.state_text(index.row())
    with qtbot.waitSignal(window.session.sigWritesDone, timeout=10000) as done:
        page.write_changed_button.click()
    assert done.args[0][0]["verified"]
    assert fake.values[("tune", 4)] == 25
    assert window.state.backup_path is not None and window.state.backup_path.exists()
    assert re.search(r"^in_position_range\s*= 10\b", window.state.backup_path.read_text(), re.M)  # before
    assert not model.edits
    assert "tune 4, in-position range: 10 pulse → 25 pulse, verified" in page.log_view.toPlainText()


def test_rotary_direction_written_read_back_and_power_cycle_offered(window, fake, qtbot):
    page = window.show_page("direction")
    page.ccw_radio.setChecked(True)
    assert page.write_button.isEnabled()
    with qtbot.waitSignal(window.session.sigWritesDone, timeout=10000):
        page.write_button.click()
    assert fake.values[("system", 8)] == 1
    assert page.drive_value() == 1
    assert "power cycle" in page.status_label.text()


def test_jog_hold_runs_release_stops_and_stop_key(window, fake, qtbot):
    page = window.show_page("jog")
    with qtbot.waitSignal(window.link.sigResult, check_params_cb=lambda r: r.answers(Servo)):
        page.motion.servo_on_button.click()
    qtbot.waitUntil(lambda: page.motion.fwd_button.isEnabled(), timeout=10000)
    qtbot.mousePress(page.motion.fwd_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: sum(1 for c in fake.calls if c[0] == "jog") >= 3, timeout=10000)  # keep-alive
    qtbot.mouseRelease(page.motion.fwd_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: fake.calls[-1] == ("stop",), timeout=10000)
    n = len(fake.calls)
    qtbot.keyClick(window, Qt.Key.Key_Escape)
    qtbot.waitUntil(lambda: len(fake.calls) > n and fake.calls[-1] == ("stop",), timeout=10000)


def test_alarm_shown_highlighted_acknowledged_and_cleared(window, fake, qtbot):
    page = window.show_page("alarms")
    fake.raise_alarm(20)
    qtbot.waitUntil(lambda: page.current_code == 20, timeout=10000)
    qtbot.waitUntil(window.alarm_banner.isVisible, timeout=10000)
    assert "Overload" in page.code_label.text()
    assert window.alarm_lamp.state is True
    page.ack_button.click()
    qtbot.waitUntil(lambda: not window.alarm_banner.isVisible(), timeout=10000)
    page.clear_button.click()
    qtbot.waitUntil(lambda: page.current_code == 0, timeout=10000)
    qtbot.waitUntil(lambda: page.history_table.rowCount() == 1, timeout=10000)
    assert page.history_table.item(0, 0).text() == "20"


def test_lost_link_is_shown_within_a_second(window, fake, qtbot):
    fake.close()
    with qtbot.waitSignal(window.link.sigDisconnected, timeout=10000) as lost:
        pass
    assert lost.args[1] is True
    assert "LINK LOST" in window.caps_label.text()
    assert "LINK LOST" in window.connection_page.link_label.text()


def test_closing_with_the_servo_on_asks_and_cancel_keeps_the_window(window, fake, qtbot, monkeypatch):
    from PySide6.QtWidgets import QMessageBox

    with qtbot.waitSignal(window.link.sigResult, check_params_cb=lambda r: r.answers(Servo)):
        window.jog_page.motion.servo_on_button.click()
    qtbot.waitUntil(lambda: window.link.servo_on, timeout=10000)
    asked = []

    def answer(parent, title, text, *args):
        asked.append(text)
        return QMessageBox.StandardButton.Cancel

    monkeypatch.setattr(QMessageBox, "warning", answer)
    assert not window.close()
    assert window.isVisible() and window.link.connected
    assert "STOP" in asked[0] and "stays ON" in asked[0]
    window.disconnect_drive()  # asks too; Cancel keeps the link
    assert len(asked) == 2 and window.link.connected


def test_drive_without_parameter_access_says_so(make_window, qtbot):
    fake = FakeDriveClient().without(Command.PRD, Command.PWR)
    window = make_window(open_client=lambda url, baud: fake, connect="fake://")
    page = window.parameters_page
    assert "front panel" in page.message.text()
    assert not page.read_button.isEnabled()


def test_a_port_that_does_not_open_is_said_once_where_the_link_is_shown(make_window, qtbot):
    """Before any link the Connection page says "not connected" once; a port that does not open
    is named there and in the message line with why, in words (not pyserial's errno text twice)."""
    window = make_window()
    page = window.connection_page
    assert page.link_label.text() == "not connected"
    window.connect_to("/dev/ttyNOPE0")
    why = ("cannot open /dev/ttyNOPE0: no such port "
           "(is the USB-serial adapter plugged in, and is this its name?)")
    qtbot.waitUntil(lambda: page.link_label.text() != "not connected", timeout=10000)
    assert page.link_label.text() == f"not connected: {why}"
    assert window.message_area.messages[-1].text == f"Could not connect: {why}"


def test_a_bad_sim_option_is_one_line_naming_it_and_where_the_options_are(make_window, qtbot):
    """The address once (where the link is shown), the option no simulated drive has, a close
    known name, and where the options are documented; not the address twice nor every option."""
    window = make_window()
    url = "sim://FHA-25C-50-US250?colour=red&inertia=1"
    window.connect_to(url)
    qtbot.waitUntil(lambda: window.message_area.latest() is not None
                    and window.message_area.latest().text.startswith("Could not connect"), timeout=10000)
    text = window.message_area.latest().text
    assert text == (f"Could not connect: cannot open {url}: the simulated drive has no options 'colour', "
                    "'inertia' (did you mean 'load_inertia'?); its options are listed in docs/sim.md")
