"""The main window on a drive that answers only its manual's commands (DGR, OWW): the simulated
drive's documented profile, embedded, through the real client and codec, with the servo switched
by the simulated CN2 input as a trainee does in the panel."""

from __future__ import annotations

import itertools
import time

import pytest
from PySide6.QtCore import Qt

from fha_studio.gui.link import PROBE_INTERVAL_MS, SERVO_ON_NOTE, SERVO_ON_PROBE_MS
from fha_studio.hardware import protocol as p
from fha_studio.hardware.transport import pipe_pair
from tests.gui.controller import panel, panel_done
from tests.gui.fit import laid_out
from tests.support.documented import DocumentedDrive
from tests.support.scripted import ScriptedDrive

URL = "sim://FHA-25C-50-S248?paced=0&profile=documented&oww_clear_s=1"


def sim_drive(window):
    return window.link._worker._client.transaction.transport.inner.sim_drive


@pytest.fixture
def window(make_window, qtbot):
    w = make_window(connect=URL)
    qtbot.waitUntil(lambda: w.link.status is not None and w.link.status.absolute_counts is not None,
                    timeout=10000)
    return w


def switch_servo(window, qtbot, on: bool) -> None:
    panel_done(window, qtbot, lambda: window.sim_panel.servo_check.setChecked(on))
    qtbot.waitUntil(lambda: window.link.status is not None and window.link.status.servo_on is on,
                    timeout=10000)


def test_panel_is_shown_and_servo_on_comes_from_cn2_only(window, qtbot):
    info = window.link.info
    assert info.documented_only and info.embedded_sim and not info.can_move
    assert window.sim_panel.isVisible()
    assert not window.servo_action.isEnabled()
    assert "CN2" in window.servo_action.toolTip()
    switch_servo(window, qtbot, True)
    assert window.servo_lamp.state is True
    qtbot.waitUntil(lambda: SERVO_ON_NOTE in window.caps_label.toolTip(), timeout=10000)
    assert window.link_lamp.state is True  # s proves the drive is there
    switch_servo(window, qtbot, False)
    qtbot.waitUntil(lambda: SERVO_ON_NOTE not in window.caps_label.toolTip(), timeout=10000)


def test_the_status_bar_names_the_embedded_drive_in_words_not_by_its_address(window):
    """The documented profile says no model: the status bar names the drive by where it is, the
    embedded simulated drive, not by an address full of options (an EEPROM file's path among
    them); the address stays in the tooltip."""
    assert window.caps_label.text().startswith("embedded simulated drive · ")
    assert "sim://" not in window.caps_label.text()
    assert URL in window.caps_label.toolTip()


def test_idle_probe_is_dgr_about_once_a_second_and_at_most_once_a_second_with_servo_on(window, qtbot):
    sent: list[tuple[float, bytes]] = []
    client = window.link._worker._client
    client.trace_packet = lambda sending, data: sending and sent.append((time.monotonic(), data))
    qtbot.waitUntil(lambda: len(sent) >= 4, timeout=10000)
    assert {data for _, data in sent} == {b"DGR+00000\r"}
    switch_servo(window, qtbot, True)
    sent.clear()
    qtbot.waitUntil(lambda: len(sent) >= 4, timeout=15000)
    gaps = [b[0] - a[0] for a, b in itertools.pairwise(sent)]
    assert min(gaps) >= SERVO_ON_PROBE_MS / 1000 * 0.9, gaps
    assert PROBE_INTERVAL_MS <= SERVO_ON_PROBE_MS
    client.trace_packet = None


def test_stop_says_what_stops_this_axis_and_sends_nothing(window, qtbot):
    button = window.stop_button
    assert not button.can_send and "emergency stop" in button.toolTip()
    assert "servo-OFF" in button.text()
    sent: list[bytes] = []
    window.link._worker._client.trace_packet = lambda sending, data: sending and sent.append(data)
    from fha_studio.gui.pages.registry import PAGES

    for page in (entry.id for entry in PAGES):
        window.show_page(page)
        button.click()
        assert "nothing was sent" in window.message_area.latest().text
        assert "emergency stop" in window.message_area.latest().text
    assert all(data == b"DGR+00000\r" for data in sent)  # only the idle probe went out
    window.link._worker._client.trace_packet = None


def test_a_silent_drive_turns_the_link_lamp_red_at_its_first_unanswered_probe(make_window, qtbot,
                                                                                time_ceiling):
    host, drive_end = pipe_pair("documented")
    alive = {"on": True}
    unanswered: list[str] = []
    handler = DocumentedDrive()

    def answer(request):
        if alive["on"]:
            return handler(request)
        unanswered.append(request.command.value)
        return None

    scripted = ScriptedDrive(drive_end, answer)

    def open_client(url, baud):
        from fha_studio.hardware.client import DriveClient, LinkSettings

        return DriveClient.attach(host, LinkSettings(response_timeout_s=0.25, retries=1))

    try:
        window = make_window(open_client=open_client, connect="documented")
        qtbot.waitUntil(lambda: window.link.status is not None, timeout=10000)
        assert window.link_lamp.state is True
        with qtbot.waitSignal(window.link.sigDisconnected, timeout=30000) as lost:
            alive["on"] = False
            switched_off = time.monotonic()
        took = time.monotonic() - switched_off
        assert lost.args[1] is True
        assert window.link_lamp.state is True and window.link_lamp.toolTip().startswith("Link: LOST")
        assert "Link lost" in window.message_area.latest().text
        # lost at the first probe left unanswered and its one retry, not later: within the probe
        # interval (0.7 s) and two timeouts (0.5 s) by design; the time only catches a hang
        assert unanswered == [p.Command.DGR.value] * 2
        time_ceiling("the link lamp red after the drive fell silent", took, 20.0)
    finally:
        scripted.close()


SENSOR_URL = "sim://FHA-25C-50-S248?paced=0&profile=documented&oww_clear_s=1&sensors=1"


def click_and_record(page, qtbot, button):
    before = len(page.records)
    assert button.isEnabled(), button.toolTip()
    button.click()
    qtbot.waitUntil(lambda: len(page.records) > before, timeout=15000)
    return page.records[-1]


def test_dgr_checks_encoder_direction_dogs_and_origin(make_window, qtbot, tmp_path):
    window = make_window(connect=SENSOR_URL)
    window.state.set_actuator("FHA-25C-50-S248-L", acknowledged=True)
    page = window.show_page("absolute")
    page.who_edit.setText("A. Tester")
    qtbot.waitUntil(lambda: page.read_button.isEnabled(), timeout=10000)
    summary = page.summary_label.text()
    assert "only the manual's commands" in summary and "ratio 50" in summary

    # encoder check: turn by hand by +10 deg
    page.encoder_angle.setValue(10.0)
    page.encoder_start_button.click()
    qtbot.waitUntil(lambda: page.encoder_end_button.isEnabled(), timeout=10000)
    assert "turned by hand by +10°" in panel(window, qtbot, "turn", 10.0)
    record = click_and_record(page, qtbot, page.encoder_end_button)
    assert record.check == "encoder" and record.passed and record.who == "A. Tester"
    assert abs(record.values["after_counts"] - record.values["before_counts"] - 11378) <= 2

    # rotary direction 1-10: parameter 8 = 0 entered, servo on + FWD at the controller, servo off
    page.direction_param.setCurrentIndex(1)
    page.direction_start_button.click()
    qtbot.waitUntil(lambda: page._direction_start is not None, timeout=10000)
    switch_servo(window, qtbot, True)
    assert not page.direction_end_button.isEnabled()
    assert SERVO_ON_NOTE in page.reason_label.text()
    panel(window, qtbot, "command", 5.0)
    # the controller's 5 deg take their time; over CN3 a documented drive tells nothing of it, so
    # the test gives them 1.5 s of the simulated drive's own time (its moving bit clears while the
    # output still creeps at up to 0.5 r/min, and switched off then, it would coast on)
    commanded_at = sim_drive(window).clock_s
    qtbot.waitUntil(lambda: sim_drive(window).clock_s >= commanded_at + 1.5, timeout=30000)
    assert not sim_drive(window).moving
    switch_servo(window, qtbot, False)
    qtbot.waitUntil(lambda: page.direction_end_button.isEnabled(), timeout=10000)
    record = click_and_record(page, qtbot, page.direction_end_button)
    assert record.passed and record.values["turned"] == "CW" and "as parameter 8 = 0 says" in record.detail

    # sensor dog: limit switch 2 sits at +150 deg in the simulated set; turn there by hand
    angle_now = record.values["after_counts"] * 360 / (8192 * 50)
    text = panel(window, qtbot, "turn", 151.0 - angle_now)
    assert "limit switch 2" in text
    page.dog_sensor.setCurrentIndex(1)
    record = click_and_record(page, qtbot, page.dog_record_button)
    assert record.check == "sensor_dog" and record.passed
    assert abs(record.values["angle_deg"] - 151.0) < 0.1 and "movable range" in record.detail
    # an angle past the movable range of 4-7-3 is refused
    panel(window, qtbot, "turn", 30.0)
    record = click_and_record(page, qtbot, page.dog_record_button)
    assert not record.passed and "outside the movable range" in record.detail

    # absolute origin: OWW, q after the (shortened) acknowledgement time, read back
    page.tabs.setCurrentIndex(3)
    assert "servo off: met" in page.origin_conditions.text()
    record = click_and_record(page, qtbot, page.origin_button)
    assert record.check == "absolute_origin" and record.passed
    assert record.values["position_counts"] == record.values["before_counts"] % 8192
    assert page.history.rowCount() == 5

    # the records go into the commissioning report (as notes with who), each once
    from fha_studio.logic.procedures.report import build_report

    procedures = window.show_page("procedures")
    procedures.new_session(tmp_path / "axis.json", "FHA-25C-50-S248-L")
    procedures._collect_for_report()
    procedures._collect_for_report()
    notes = build_report(procedures.session).notes
    assert len(notes) == 5 and all(n["who"] == "A. Tester" for n in notes)
    assert any(n["text"].startswith("Absolute origin (OWW)") and ": pass:" in n["text"] for n in notes)


def test_dgr_checks_on_an_incremental_encoder_ask_and_record_by_hand(make_window, qtbot):
    window = make_window(connect="sim://FHA-25C-50-US250?paced=0&profile=documented")
    page = window.show_page("absolute")
    qtbot.waitUntil(lambda: page.encoder == "incremental", timeout=10000)
    assert "incremental encoder" in page.reason_label.text()
    assert not page.read_button.isEnabled() and not page.origin_button.isEnabled()
    assert "nothing to clear" in page.origin_button.toolTip()
    page.tabs.setCurrentIndex(1)
    assert page.direction_hand.isVisible()
    page.direction_param.setCurrentIndex(2)  # 1: FWD = CCW
    page.direction_seen.setCurrentText("CCW")
    page.direction_hand_button.click()
    record = page.records[-1]
    assert record.by_hand and record.passed and record.values == {"turned": "CCW", "rotary_direction": 1}
    assert "by hand" in page.history.item(0, 1).text()


def test_alarms_are_typed_from_the_front_panel(window, qtbot):
    page = window.show_page("alarms")
    assert page.panel_box.isVisible()
    assert "front panel" in page.code_label.text() and "not connected" not in page.code_label.text()
    assert not page.refresh_button.isEnabled() and not page.clear_button.isEnabled()
    page.panel_code_edit.setText("60")
    for name in ("B",):
        page.alm_checks[name].setChecked(True)
    page.alm_read_check.setChecked(True)  # D C B A = 0010: alarm 60 in the manual's table
    assert page.enter_from_panel()
    assert page.code_label.text().startswith("Alarm 60")
    assert "Cause:" in page.cause_label.text() and "Remedy:" in page.cause_label.text()
    # the source says what a technician can find: the manual's page, its web copy by its address
    assert "Source: HA-655 manual p.10 (1-9-1); causes and recovery: the manual's web copy at relianca.com" \
        in page.cause_label.text().replace("&#x27;", "'").replace("&#39;", "'")
    assert "recorded" in page.panel_result.text()
    page.panel_code_edit.setText("20")  # the lamps still say 0010: they do not match 20 (0001)
    assert page.enter_from_panel()
    assert "do not match alarm 20" in page.panel_result.text() and "60" in page.panel_result.text()
    assert page.history_table.rowCount() == 2 and page.history_table.item(0, 0).text() == "20"
    assert page.history_table.item(1, 2).text() == "entered from the panel"
    page.panel_code_edit.setText("xx")
    assert not page.enter_from_panel()


def test_procedures_ask_for_what_the_drive_cannot_tell_and_record_the_value(window, qtbot, tmp_path):
    page = window.show_page("procedures")
    page.operator_edit.setText("T. Trainee")
    page.new_session(tmp_path / "axis.json", "FHA-25C-50-S248")
    page.select_procedure("rotary-direction")
    page.choice_combo.setCurrentText("CW")
    page.choice_button.click()
    assert page.current_step().id == "parameter"
    with qtbot.waitSignal(page.sigLiveDone, timeout=20000) as live:
        page.live_button.click()
    assert live.args[0].available is False
    assert page.by_hand_box.isVisibleTo(page)
    assert "parameter 8" in page.by_hand_edit.placeholderText()
    assert not page.answer_by_hand()  # nothing typed: nothing recorded
    page.by_hand_edit.setText("0")
    assert page.answer_by_hand()
    record = page.run.state.records[-1]
    assert record.step_id == "parameter" and record.value == "0" and record.value is not True
    assert "entered by hand" in record.detail and record.who == "T. Trainee"
    # the FWD jog: the drive takes no motion commands; the technician says which way it turned
    with qtbot.waitSignal(page.sigLiveDone, timeout=20000):
        page.live_button.click()
    assert "controller" in page.by_hand_edit.placeholderText()
    page.by_hand_edit.setText("CW")
    assert page.answer_by_hand()
    assert page.run.state.records[-1].value == "CW"


def test_the_sensor_dog_wizard_does_not_claim_to_watch_and_reads_dgr(make_window, qtbot, tmp_path):
    window = make_window(connect=SENSOR_URL)
    page = window.show_page("procedures")
    page.new_session(tmp_path / "axis.json", "FHA-25C-50-S248-L")
    page.select_procedure("sensor-adjustment")
    for _ in range(20):
        step = page.current_step()
        if step is None or step.kind == "sensor_angle":
            break
        _answer(page, step)
    panel_widget = page.dog_panel
    assert panel_widget.sensor and not panel_widget.watching
    assert "Watching" not in panel_widget.found_label.text()
    assert "does not report its inputs" in panel_widget.found_label.text()
    assert not panel_widget.jog_cw_button.isEnabled() and not panel_widget.move_button.isEnabled()
    assert "by hand" in panel_widget.motion_reason.text()
    angle = {"limit_switch_1": -150.5, "limit_switch_2": 150.5, "origin_sensor": 0.2}[panel_widget.sensor]
    panel(window, qtbot, "turn", angle)
    before = len(page.run.state.records)
    panel_widget.record_button.click()
    qtbot.waitUntil(lambda: len(page.run.state.records) > before, timeout=10000)
    assert abs(page.run.state.records[-1].value - angle) < 0.05


def _answer(page, step):
    from tests.gui.procedure_answers import answer_by_hand

    if not answer_by_hand(page, step):
        raise AssertionError(step.kind)


def _page_facts(window, page_id: str, page, servo_on: bool) -> None:
    """What each page must show on a drive of the manual's commands (servo as given)."""
    if page_id == "connection":
        assert "only the commands of its manual" in window.caps_label.toolTip() or servo_on
        # the order of the work as this drive allows it: the panel, the DGR checks, CN2
        order = page.order_hint.text()
        assert "read all" not in order and "Jog" not in order
        assert "front panel" in order and "DGR checks" in order and "Bench" in order
    elif page_id == "parameters":
        assert "front panel" in page.message.text()
    elif page_id == "direction":
        assert page.documented_box.isVisible()
        assert not page.write_button.isEnabled() and "front panel" in page.write_button.toolTip()
        assert not page.check_button.isEnabled() and "DGR checks" in page.check_button.toolTip()
        assert "front panel" in page.drive_label.text()
    elif page_id == "jog":
        assert "CN2" in page.motion.message.text()
        assert page.cn2_hint.isVisible() and "Bench" in page.cn2_hint.text()  # where the signals are
        assert not page.motion.servo_on_button.isEnabled()
    elif page_id == "absolute":
        if servo_on:
            assert not page.read_button.isEnabled() and SERVO_ON_NOTE in page.reason_label.text()
            assert not page.origin_button.isEnabled() and "servo on: NOT met" in page.origin_conditions.text()
        else:
            assert page.read_button.isEnabled() and page.origin_button.isEnabled()
    elif page_id == "alarms":
        assert page.panel_box.isVisible() and "front panel" in page.code_label.text()
    elif page_id == "scope":
        view = page.view
        if not view._live:
            view.start_live()
    assert "servo-OFF" in window.stop_button.text()


def test_walk_every_page_with_the_servo_off_and_on(window, qtbot):
    """Every page on the documented-only profile, servo off then on; nothing but DGR goes out."""
    from fha_studio.gui.pages.registry import PAGES

    window.state.set_actuator("FHA-25C-50-S248", acknowledged=True)
    sent: list[bytes] = []
    client = window.link._worker._client
    client.trace_packet = lambda sending, data: sending and sent.append(bytes(data))
    try:
        for servo_on in (False, True):
            if servo_on:
                switch_servo(window, qtbot, True)
            for entry in PAGES:
                page = window.show_page(entry.id)
                laid_out(qtbot, window)
                _page_facts(window, entry.id, page, servo_on)
            scope = window.show_page("scope").view
            label = "NOT LIVE: servo on (controller)" if servo_on else "LIVE: position only (DGR, servo off)"
            qtbot.waitUntil(lambda lab=label, v=scope: v.indicator_text().startswith(lab), timeout=15000)
            window.stop_button.click()
            assert "nothing was sent" in window.message_area.latest().text
        switch_servo(window, qtbot, False)
        scope.stop_live()
    finally:
        client.trace_packet = None
    frames = {bytes(data) for data in sent}
    assert frames <= {b"DGR+00000\r", b"OWW+00000\r"}, frames


def test_the_front_panel_worksheet_shows_every_cell_whole_on_a_small_screen(window, qtbot):
    """At 1366 x 740 and 1280 x 720 the worksheet's names, values and states are whole (the
    names were cut to "Speed loop integral compensa…" beside the long "not entered" states), and
    who enters the values is asked beside the buttons, not inside the note's wrapped sentence."""
    from tests.gui.fit import cut_texts, elided_cells

    window.state.set_actuator("FHA-25C-50-S248", acknowledged=True)
    page = window.show_page("parameters")
    page.who_edit.setText("J. Field")
    model = page.model
    for key, text in (("position_loop_gain", "60"), ("rotary_direction", "0"), ("in_position_range", "20")):
        assert model.setData(model.index(model.row_of(key), 3), text)  # "0: FWD turns CW (seen …)"
    assert page.who_box.isVisible() and not page.panel_bar.isAncestorOf(page.who_edit)
    assert "Nothing written yet" in page.log_view.placeholderText()
    for size in ((1366, 740), (1280, 720)):
        window.resize(*size)
        qtbot.waitUntil(lambda size=size: window.size().toTuple() == size, timeout=10000)
        laid_out(qtbot, window)
        assert not elided_cells(page.table) and not cut_texts(page), size


def test_front_panel_worksheet_parameters_direction_file_and_report(window, qtbot, tmp_path):
    from fha_studio.logic.paramfile import FRONT_PANEL_SOURCE, read_parameter_file
    from fha_studio.logic.procedures.report import build_report

    window.state.set_actuator("FHA-25C-50-S248", acknowledged=True)
    page = window.show_page("parameters")
    model = page.model
    assert page.panel_bar.isVisible() and model.panel_mode
    assert model.headerData(3, Qt.Orientation.Horizontal) == "Value on the drive's panel"
    row = model.row_of("position_loop_gain")
    assert model.state_text(row) == "not entered: tune 2 on the panel"
    refused = []
    model.sigRefused.connect(lambda why, _index: refused.append(why))
    assert not model.setData(model.index(row, 3), "60")  # nobody named: nothing recorded
    assert "Entered by" in refused[-1] and not window.state.front_panel
    page.who_edit.setText("J. Field")
    assert model.setData(model.index(row, 3), "60")
    item = window.session.parameter_model.by_key("position_loop_gain")
    entry = window.state.front_panel[(item.mode, item.number)]
    assert (entry.value, entry.who) == (60, "J. Field")
    assert "from the panel: J. Field" in model.state_text(row)
    assert "≠ default" in model.state_text(row) or item.default == 60
    assert page.save_button.isEnabled()
    path = page.save_file(str(tmp_path / "panel.toml"))
    text = path.read_text()
    assert FRONT_PANEL_SOURCE in text and "(front panel: J. Field," in text
    loaded = read_parameter_file(text, window.session.parameter_model)
    assert loaded.source == FRONT_PANEL_SOURCE and loaded.values[(item.mode, item.number)] == 60
    # a file with another value: nothing can be written; the page lists what to set on the panel
    page.apply_choices({(item.mode, item.number): 70})
    assert "Set on the drive's front panel" in page.message.text() and "= 70" in page.message.text()

    # rotary direction: item 8 entered on the page; the DGR check compares with it
    direction = window.show_page("direction")
    direction.panel_combo.setCurrentIndex(1)
    assert not direction.enter_from_panel()  # no name yet
    direction.panel_who.setText("J. Field")
    assert direction.enter_from_panel()
    assert "On the drive's panel: <b>1</b>" in direction.drive_label.text()
    assert window.show_page("absolute").parameter_8() == 1

    # the report: the values entered from the panel, marked so
    procedures = window.show_page("procedures")
    procedures.new_session(tmp_path / "axis.json", "FHA-25C-50-S248")
    procedures._collect_for_report()
    report = build_report(procedures.session)
    rows = {r.key: r for r in report.parameters}
    assert "entered from the front panel by J. Field" in rows["position_loop_gain"].value
    assert rows["rotary_direction"].value.startswith("1")


def test_the_encoder_phase_check_uses_dgr_and_a_turn_by_hand(make_window, qtbot, tmp_path):
    window = make_window(connect=SENSOR_URL)
    page = window.show_page("procedures")
    page.operator_edit.setText("T. Trainee")
    page.new_session(tmp_path / "axis.json", "FHA-25C-50-S248-L")
    page.select_procedure("wiring")
    for _ in range(40):
        step = page.current_step()
        assert step is not None, "the wiring procedure ended before the encoder-phase check"
        if step.id == "encoder-phases":
            break
        if step.kind == "live":
            with qtbot.waitSignal(page.sigLiveDone, timeout=20000) as live:
                page.live_button.click()
            if live.args[0] is not None and live.args[0].available:
                continue
            page.by_hand_edit.setText("as expected")
            assert page.answer_by_hand()
        else:
            _answer(page, step)
    with qtbot.waitSignal(page.sigLiveDone, timeout=20000) as first:
        page.live_button.click()
    assert not first.args[0].available and "turn the output by hand by +10°" in first.args[0].detail
    panel(window, qtbot, "turn", 10.0)
    with qtbot.waitSignal(page.sigLiveDone, timeout=20000) as second:
        page.live_button.click()
    observation = second.args[0]
    assert observation.available and observation.passed
    record = page.run.state.records[-1]
    assert record.step_id == "encoder-phases" and abs(record.value - 11378) <= 2
