"""The real window against the embedded simulated drive (sim://, unpaced), through the real
DriveClient and the CN3 codec: what a newcomer does in the README, driven by the tests."""

from __future__ import annotations

import pytest
from PySide6.QtCore import Qt

from fha_studio.gui.link import (
    ClearAlarm,
    MoveBy,
    PowerCycle,
    ReadParameters,
    Servo,
    SetInputs,
    Stop,
    WriteParameters,
)

SIM_URL = "sim://FHA-25C-50-US250?paced=0"


def sim_drive(window):
    """The SimDrive behind the link (for injecting what a technician would do at the machine)."""
    return window.link._worker._client.transaction.transport.inner.sim_drive


@pytest.fixture
def window(make_window, qtbot):
    w = make_window(connect=SIM_URL)
    qtbot.waitUntil(lambda: len(w.state.drive_values) >= 14, timeout=10000)
    return w


def servo_on(window, qtbot):
    with qtbot.waitSignal(window.link.sigResult, check_params_cb=lambda r: r.answers(Servo), timeout=10000):
        window.jog_page.motion.servo_on_button.click()
    qtbot.waitUntil(lambda: window.link.servo_on, timeout=10000)


def test_connects_identifies_and_status_bar_says_what_the_drive_supports(window, qtbot):
    info = window.link.info
    assert info.driver_model == "HA-655-2-200"
    assert info.adjusted_for == "FHA-25C-50-US250"
    assert info.is_simulated
    assert "HA-655-2-200" in window.caps_label.text() and "traces" in window.caps_label.toolTip()
    assert window.connection_page.adjusted_label.text() == "FHA-25C-50-US250"
    qtbot.waitUntil(lambda: window.alarm_lamp.state is False, timeout=10000)
    assert window.servo_lamp.state is False


def test_rotary_direction_written_power_cycled_and_read_back(window, qtbot):
    page = window.show_page("direction")
    assert page.drive_value() == 0
    page.ccw_radio.setChecked(True)
    with qtbot.waitSignal(window.session.sigWritesDone, timeout=10000) as done:
        page.write_button.click()
    assert done.args[0][-1]["verified"]
    assert "power cycle" in page.status_label.text()
    assert page.power_cycle_button.isVisible()
    with qtbot.waitSignal(
        window.link.sigResult, check_params_cb=lambda r: r.answers(PowerCycle), timeout=10000
    ):
        page.power_cycle_button.click()
    # read back from the drive after the power cycle: the value is still there (EEPROM)
    window.state.forget_drive()  # what was read before is forgotten: the value must come from the drive
    with qtbot.waitSignal(window.link.sigResult, check_params_cb=lambda r: r.answers(ReadParameters)):
        window.session.read_all()
    assert page.drive_value() == 1
    assert "counter-clockwise" in page.drive_label.text()
    log = window.state.writes
    assert log[-1].key == "rotary_direction" and log[-1].old == 0 and log[-1].new == 1 and log[-1].verified


def test_refuses_a_bad_value_at_the_field(window, qtbot):
    model = window.parameters_page.model
    index = model.index(model.row_of("speed_loop_gain"), 3)
    with qtbot.waitSignal(model.sigRefused):
        assert not model.setData(index, "5000")
    assert "1 … 500" in window.parameters_page.message.text()
    assert not model.edits


def test_save_load_and_diff_a_parameter_file(window, qtbot, tmp_path):
    page = window.show_page("parameters")
    saved = page.save_file(str(tmp_path / "axis.toml"))
    text = saved.read_text()
    assert 'actuator = "FHA-25C-50-US250"' in text and 'driver_model = "HA-655-2-200"' in text
    edited = text.replace("in_position_range", "in_position_range_x", 0)
    edited = edited.replace("speed_loop_gain", "speed_loop_gain", 1)
    lines = [
        ln if not ln.startswith("in_position_range ") else "in_position_range = 33"
        for ln in edited.splitlines()
    ]
    lines.append("notch_filter = 2")  # [system] is last: an item this driver does not have
    (tmp_path / "edited.toml").write_text("\n".join(lines) + "\n")
    dialog = page.load_file(str(tmp_path / "edited.toml"), exec_dialog=False)
    assert dialog.differing >= 1
    assert "notch_filter" in dialog.not_mapped_view.toPlainText()
    assert dialog.chosen_values() == {("tune", 4): 33}
    dialog.set_choice("in_position_range", "default")
    assert dialog.chosen_values() == {}  # the default (10) is what the drive holds
    dialog.set_choice("in_position_range", "file")
    with qtbot.waitSignal(window.session.sigWritesDone, timeout=10000):
        dialog.accept()
    assert window.state.drive_values[("tune", 4)] == 33
    assert window.state.backup_path.exists()
    dialog.deleteLater()


def test_corrupt_file_is_refused_with_the_line(window, tmp_path):
    page = window.parameters_page
    bad = tmp_path / "bad.toml"
    bad.write_text('format = "fha-parameters/1"\n[tune]\nspeed_loop_gain = fast\n')
    assert page.load_file(str(bad), exec_dialog=False) is None
    assert "line 3" in page.message.text() and "nothing loaded" in page.message.text()


def test_jog_moves_the_axis_and_release_stops_it(window, qtbot):
    page = window.show_page("jog")
    servo_on(window, qtbot)
    start = window.link.status.position_pulse
    page.motion.speed_spin.setValue(10.0)
    qtbot.mousePress(page.motion.fwd_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: (window.link.status.speed_rpm or 0) > 5.0, timeout=10000)
    qtbot.mouseRelease(page.motion.fwd_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: abs(window.link.status.speed_rpm or 0) < 0.01, timeout=10000)
    assert window.link.status.position_pulse > start  # FWD counts up
    assert window.link.servo_on  # release stops and holds; the servo stays on


def test_stop_key_stops_a_move(window, qtbot):
    page = window.show_page("jog")
    servo_on(window, qtbot)
    page.motion.angle_spin.setValue(900.0)
    page.motion.move_speed_spin.setValue(20.0)
    page.motion.move_button.click()
    qtbot.waitUntil(lambda: (window.link.status.speed_rpm or 0) > 1.0, timeout=10000)
    qtbot.keyClick(window, Qt.Key.Key_Escape)
    qtbot.waitUntil(lambda: abs(window.link.status.speed_rpm or 0) < 0.01, timeout=10000)
    assert not window.link.status.moving


def test_inputs_shown_live(window, qtbot):
    page = window.show_page("jog")
    with qtbot.waitSignal(window.link.sigResult, check_params_cb=lambda r: r.answers(SetInputs)):
        window.link.send(SetInputs({"fwd_inhibit": True}))
    from fha_studio.hardware.protocol import IoBit

    qtbot.waitUntil(lambda: page.signal_lamps[IoBit.FWD_INHIBIT].state is True, timeout=10000)


def test_alarm_raised_highlighted_acknowledged_cleared(window, qtbot):
    page = window.show_page("alarms")
    sim_drive(window).raise_alarm(20)
    qtbot.waitUntil(lambda: page.current_code == 20, timeout=10000)
    qtbot.waitUntil(window.alarm_banner.isVisible, timeout=10000)
    assert "Overload" in page.code_label.text()
    assert "Remedy" in page.cause_label.text()
    qtbot.waitUntil(lambda: page.history_table.rowCount() >= 1, timeout=10000)
    assert page.history_table.item(0, 0).text() == "20"
    window.show_page("jog")
    window.alarm_banner.click()  # the red banner takes the technician to the alarm
    assert window.tabs.currentWidget() is page
    page.ack_button.click()
    qtbot.waitUntil(lambda: not window.alarm_banner.isVisible(), timeout=10000)
    assert window.alarm_lamp.state is True  # acknowledged is not cleared
    page.clear_button.click()
    qtbot.waitUntil(lambda: page.current_code == 0, timeout=10000)
    assert window.alarm_lamp.state is False


def test_alarm_that_needs_a_power_cycle_says_so(window, qtbot):
    page = window.show_page("alarms")
    sim_drive(window).raise_alarm(50)
    qtbot.waitUntil(lambda: page.current_code == 50, timeout=10000)
    with qtbot.waitSignal(window.link.sigResult, check_params_cb=lambda r: r.answers(ClearAlarm)):
        page.clear_button.click()
    assert "power cycle" in page.result_label.text()
    assert page.current_code == 50


def test_lost_link_shown_within_a_second(window, qtbot):
    window.link._worker._client.transaction.transport.inner.close()  # the cable is pulled
    with qtbot.waitSignal(window.link.sigDisconnected, timeout=10000) as lost:
        pass
    assert lost.args[1] is True
    assert "LINK LOST" in window.caps_label.text()
    assert window.link_lamp.state is True  # red lamp: lost, not merely disconnected
    assert not window.jog_page.motion.fwd_button.isEnabled()


def test_stop_and_failures_are_seen_in_the_message_area_and_kept_in_its_log(window, qtbot):
    """A technician presses STOP and sees what happened; a refused command says so in red. The
    message area is not covered by the status bar's other widgets, and every message is kept."""
    window.resize(1366, 740)
    area = window.message_area
    with qtbot.waitSignal(window.link.sigResult, check_params_cb=lambda r: r.answers(Stop), timeout=10000):
        qtbot.keyClick(window, Qt.Key.Key_Escape)
    qtbot.waitUntil(lambda: "STOP done" in area.text_label.text(), timeout=10000)
    assert area.isVisible() and not area.text_label.visibleRegion().isEmpty()
    text_rect = area.text_label.geometry().translated(area.mapTo(window, area.rect().topLeft()))
    caps_rect = window.caps_label.geometry().translated(
        window.caps_label.parentWidget().mapTo(window, window.caps_label.parentWidget().rect().topLeft())
    )
    assert not text_rect.intersects(caps_rect)
    window.link.send(MoveBy(10.0))  # servo off: the drive refuses to move
    refused = "Move failed: the drive refused to move by an angle"
    qtbot.waitUntil(lambda: refused in area.text_label.text(), timeout=10000)
    assert "#b00020" in area.text_label.styleSheet()
    texts = [m.text for m in area.messages]
    assert any(t.startswith("STOP sent") for t in texts) and any(t.startswith("STOP done") for t in texts)
    assert area.log_button.text() == f"Messages ({len(texts)})"


def test_parameter_mode_writes_are_prevented_up_front_while_the_servo_is_on(window, qtbot):
    page = window.show_page("parameters")
    model = page.model
    servo_on(window, qtbot)
    assert model.setData(model.index(model.row_of("position_error_allowance"), 3), "200")
    qtbot.waitUntil(lambda: page.servo_note.isVisible(), timeout=10000)
    assert not page.write_changed_button.isEnabled() and not page.write_all_button.isEnabled()
    assert "servo off" in page.servo_note.text()
    sent = []
    window.link.sigCommand.connect(lambda command: sent.append(type(command.request)))
    page.write_changed()  # e.g. a keyboard shortcut: still refused, nothing sent
    assert WriteParameters not in sent and "Nothing written" in page.message.text()
    with qtbot.waitSignal(window.link.sigResult, check_params_cb=lambda r: r.answers(Servo), timeout=10000):
        window.jog_page.motion.servo_off_button.click()
    qtbot.waitUntil(page.write_changed_button.isEnabled, timeout=10000)
    assert not page.servo_note.isVisible()


def test_after_the_power_cycle_nothing_is_pending(window, qtbot):
    page = window.show_page("parameters")
    model = page.model
    row = model.row_of("rotary_direction")
    assert model.setData(model.index(row, 3), "1")
    with qtbot.waitSignal(window.session.sigWritesDone, timeout=10000):
        page.write_changed()
    from fha_studio.gui.pages.parameters import COLUMNS

    def state() -> str:
        return model.data(model.index(row, COLUMNS.index("State")))

    assert "power cycle needed" in state()
    cycled = lambda r: r.answers(PowerCycle)  # noqa: E731
    with qtbot.waitSignal(window.link.sigResult, check_params_cb=cycled, timeout=10000):
        page.power_cycle_button.click()
    qtbot.waitUntil(lambda: "power cycle" not in state() and "restart" not in state(), timeout=10000)


def test_a_direction_confirmed_on_its_page_is_done_in_the_report(window, qtbot, tmp_path):
    from fha_studio.logic.procedures.report import build_report

    direction = window.show_page("direction")
    assert direction.answer("cw") is True  # parameter 8 = 0: FWD turns CW, and CW was seen
    procedures = window.show_page("procedures")
    procedures.new_session(tmp_path / "axis.json", "FHA-25C-50-US250")
    procedures._collect_for_report()
    report = build_report(procedures.session)
    done = next(r for r in report.procedures if r.id == "rotary-direction")
    assert done.status == "completed" and done.records[-1].value == "CW"
    assert "Rotary direction (1-10) — done" in procedures.procedure_list.item(
        [p.id for p in procedures.procedures].index("rotary-direction")
    ).text()


def test_the_message_line_keeps_room_on_a_1024_pixel_screen(window, qtbot):
    window.resize(1024, 600)
    qtbot.waitUntil(lambda: window.width() <= 1024, timeout=10000)
    window.show_message("STOP done: the drive decelerated the axis and holds it (servo stays on).")
    qtbot.waitUntil(lambda: window.message_area.text_label.width() >= 200, timeout=10000)
    assert window.caps_label.width() <= 1024 * 0.25 + 1
    assert not window.message_area.text_label.visibleRegion().isEmpty()


@pytest.mark.parametrize("friction", [True, False])
def test_the_connection_page_names_the_embedded_drive_in_words(make_window, qtbot, friction):
    # the address full of options is the tooltip's; the words say whether the catalogue's friction is on
    url = f"sim://FHA-25C-50-US250?paced=0&catalogue_friction={int(friction)}"
    window = make_window(connect=url)
    page = window.show_page("connection")
    text = page.link_label.text()
    assert text == ("embedded simulated drive FHA-25C-50-US250, "
                    f"{'with' if friction else 'without'} the catalogue's friction (TF, 2-4-4)")
    assert url in page.link_label.toolTip()
    assert window.caps_label.text().split(" · ")[1] == "embedded simulated drive"  # the status bar's words
