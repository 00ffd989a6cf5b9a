"""Move and watch on the Scope page: the jog panel beside the plot, one plot per unit with a
shared time axis, and the cursor table (the main window on the embedded simulated drive)."""

from __future__ import annotations

import numpy as np
import pytest
from PySide6.QtCore import Qt

from fha_studio.gui.link import Servo

SIM_URL = "sim://FHA-25C-50-US250?paced=0"


def latest(view, key):
    live = view._live
    j = [c.key for c in live.channels].index(key) + 1
    return live.ring.window()[:, j]


@pytest.fixture
def scope_window(make_window, qtbot):
    window = make_window(connect=SIM_URL)
    page = window.show_page("scope")
    qtbot.waitUntil(lambda: page.view.controller.connected, timeout=10000)
    return window, page


def test_jog_from_the_scope_panel_moves_the_axis_the_plot_shows_it_and_release_stops(scope_window, qtbot):
    window, page = scope_window
    panel, view = page.jog_panel, page.view
    assert not panel.fwd_button.isEnabled()  # servo off: nothing moves, and the panel says why
    assert "Servo OFF" in panel.message.text()
    view.start_live()
    qtbot.waitUntil(lambda: view.indicator_text() == "LIVE", timeout=10000)
    with qtbot.waitSignal(window.link.sigResult, check_params_cb=lambda r: r.answers(Servo), timeout=10000):
        panel.servo_on_button.click()
    qtbot.waitUntil(lambda: panel.fwd_button.isEnabled(), timeout=10000)
    start = float(latest(view, "feedback_position")[-1])
    panel.speed_spin.setValue(20.0)
    qtbot.mousePress(panel.fwd_button, Qt.MouseButton.LeftButton)
    try:
        qtbot.waitUntil(lambda: abs(latest(view, "output_speed")[-1] - 20.0) < 0.5, timeout=10000)
    finally:
        qtbot.mouseRelease(panel.fwd_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: abs(latest(view, "output_speed")[-1]) < 0.01, timeout=10000)
    assert latest(view, "feedback_position")[-1] > start + 1.0  # the plot's data moved FWD
    assert window.link.servo_on  # release stops and holds
    # the curve on show has the motion in it
    curve = view.time_plot.curve("output_speed")
    assert curve is not None and max(curve.getData()[1]) > 19.0


def test_hiding_the_scope_lets_go_of_a_held_jog(scope_window, qtbot):
    window, page = scope_window
    panel = page.jog_panel
    window.link.send(Servo(True))
    qtbot.waitUntil(lambda: panel.fwd_button.isEnabled(), timeout=10000)
    panel.speed_spin.setValue(10.0)
    qtbot.mousePress(panel.fwd_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: (window.link.status.speed_rpm or 0) > 5.0, timeout=10000)
    window.show_page("jog")  # the scope hidden with the button still down
    assert not panel.fwd_button.held
    qtbot.waitUntil(lambda: abs(window.link.status.speed_rpm or 0) < 0.01, timeout=10000)


def test_stop_on_the_scope_panel_stops_a_move(scope_window, qtbot):
    window, page = scope_window
    panel = page.jog_panel
    window.link.send(Servo(True))
    qtbot.waitUntil(lambda: panel.move_button.isEnabled(), timeout=10000)
    panel.angle_spin.setValue(900.0)
    panel.speed_spin.setValue(20.0)
    panel.move_button.click()
    qtbot.waitUntil(lambda: (window.link.status.speed_rpm or 0) > 1.0, timeout=10000)
    panel.stop_button.click()
    qtbot.waitUntil(lambda: abs(window.link.status.speed_rpm or 0) < 0.01, timeout=10000)
    assert any(m.text.startswith("STOP") for m in window.message_area.messages)


def test_on_a_documented_only_drive_the_panel_is_disabled_and_says_why(make_window, qtbot):
    window = make_window(connect="sim://FHA-25C-50-S248?paced=0&profile=documented")
    page = window.show_page("scope")
    panel = page.jog_panel
    qtbot.waitUntil(lambda: "documented CN3 commands" in panel.message.text(), timeout=10000)
    buttons = (panel.servo_on_button, panel.servo_off_button, panel.fwd_button, panel.rev_button,
               panel.move_button)
    assert not any(b.isEnabled() for b in buttons)


def test_on_a_documented_only_drive_the_panels_stop_says_and_does_what_the_toolbars_does(make_window, qtbot):
    window = make_window(connect="sim://FHA-25C-50-S248?paced=0&profile=documented")
    page = window.show_page("scope")
    stop, toolbar_stop = page.jog_panel.stop_button, window.stop_button
    qtbot.waitUntil(lambda: not toolbar_stop.can_send, timeout=10000)
    assert "servo-OFF" in toolbar_stop.text()
    assert not stop.can_send
    assert (stop.text(), stop.toolTip(), stop.styleSheet()) == (
        toolbar_stop.text(), toolbar_stop.toolTip(), toolbar_stop.styleSheet())
    sent: list[bytes] = []
    window.link._worker._client.trace_packet = lambda sending, data: sending and sent.append(bytes(data))
    try:
        stop.click()
        latest = window.message_area.latest().text
        assert "nothing was sent" in latest and "emergency stop" in latest
    finally:
        window.link._worker._client.trace_packet = None
    assert all(data == b"DGR+00000\r" for data in sent)  # no STOP went out, only the idle probe
    window.link.close_link()
    qtbot.waitUntil(lambda: not window.link.connected, timeout=10000)
    assert stop.can_send and stop.text() == toolbar_stop.text()  # not connected: a live STOP again


def test_channels_of_different_units_are_in_different_plots_on_one_linked_time_axis(scope_window, qtbot):
    _window, page = scope_window
    view = page.view
    view.start_live()
    qtbot.waitUntil(lambda: view.indicator_text() == "LIVE", timeout=10000)
    plot = view.time_plot
    position = plot.plot_of("feedback_position")
    assert position is not None and plot.plot_of("command_position") is position  # both in degrees
    speed, current = plot.plot_of("output_speed"), plot.plot_of("motor_current")
    assert len({id(position), id(speed), id(current)}) == 3 and len(plot.plot_items()) == 3
    position.vb.setXRange(-4.0, -1.0, padding=0)
    for item in (speed, current):
        x0, x1 = item.vb.viewRange()[0]
        assert abs(x0 + 4.0) < 1e-6 and abs(x1 + 1.0) < 1e-6
    # an unticked channel stays in the table, to be ticked again, and the legend says what is polled
    table = view.channel_table
    names = [table.item(r, 0).text() for r in range(table.rowCount())]
    assert "Error pulses" in names and "Overload rate" in names
    assert "4 ticked channels" in plot.legend.text()


def test_the_cursor_table_has_a_row_per_channel_with_the_values_at_a_and_b(scope_window, qtbot):
    _window, page = scope_window
    view = page.view
    by_key = {c.key: c for c in view.all_channels}
    channels = [by_key["feedback_position"], by_key["output_speed"], by_key["motor_current"]]
    t = np.linspace(0.0, 4.0, 401)
    rows = np.column_stack([t, 100.0 * t, 10.0 + 0 * t, 0.5 * t])
    view.show_static(channels, rows, "a test capture", 100.0)
    view.set_cursors(1.0, 3.0)
    table = view.time_plot.cursor_table
    assert table.isVisible() and table.rowCount() == 1 + len(channels)
    assert table.cell_text(0, 3) == "2000.0 ms"
    got = {table.cell_text(r, 0): [table.cell_text(r, c) for c in range(1, 5)] for r in range(1, 4)}
    assert got["Feedback position (output)"] == ["100.0000°", "300.0000°", "200.0000°", "100.0000 °/s"]
    assert got["Output speed"] == ["10.00 r/min", "10.00 r/min", "0.00 r/min", "0.00 r/min/s"]
    assert got["Motor current"] == ["0.500 A", "1.500 A", "1.000 A", "0.500 A/s"]
    # each unit its own plot, time axes linked for still data too
    assert len(view.time_plot.plot_items()) == 3


def test_the_toolbar_does_not_shift_when_the_indicator_text_changes(scope_window, qtbot):
    _window, page = scope_window
    bar = page.view.toolbar
    bar.set_indicator("live", "LIVE")
    qtbot.waitUntil(lambda: bar.indicator.text() == "LIVE", timeout=10000)
    width, next_x = bar.indicator.width(), bar.live_button.x()
    bar.set_indicator("not", "NOT LIVE: no new sample for 12.3 s, the line is quiet and the drive may be off")
    assert bar.indicator.width() == width and bar.live_button.x() == next_x
    assert bar.indicator.toolTip().endswith("may be off")  # the whole text, when it is elided


def test_space_on_the_scope_page_acts_only_on_the_jog_buttons(scope_window, qtbot):
    window, page = scope_window
    panel = page.jog_panel
    window.link.send(Servo(True))
    qtbot.waitUntil(lambda: panel.move_button.isEnabled(), timeout=10000)
    pressed = []
    for button in (panel.move_button, panel.servo_off_button, page.view.live_button):
        button.clicked.connect(lambda *_a, b=button: pressed.append(b.text()))
        button.setFocus()
        qtbot.keyClick(button, Qt.Key.Key_Space)
    assert pressed == []  # Space does not move, switch the servo off or start the live view
    panel.fwd_button.setFocus()
    qtbot.keyPress(panel.fwd_button, Qt.Key.Key_Space)
    assert panel.fwd_button.held  # but it holds a jog button
    qtbot.keyRelease(panel.fwd_button, Qt.Key.Key_Space)
    assert not panel.fwd_button.held


def test_an_empty_live_view_shows_its_time_base_before_now(make_window, qtbot):
    """Before any sample the time axis reads the time base (10 s before now to now), not 0 to 1 s;
    another time base is shown at once, and still data still gets its own range."""
    window = make_window()
    view = window.show_page("scope").view
    plot = view.time_plot
    assert plot.live and "time before now" in plot.plot_items()[-1].getAxis("bottom").labelText
    assert plot.view_box.viewRange()[0] == pytest.approx([-10.0, 0.0])
    view.time_base.setCurrentIndex(view.time_base.findData(2.0))
    assert plot.view_box.viewRange()[0] == pytest.approx([-2.0, 0.0])
    by_key = {c.key: c for c in view.all_channels}
    t = np.linspace(3.0, 7.0, 41)
    view.show_static([by_key["output_speed"]], np.column_stack([t, t]), "a test capture", 10.0)
    view.time_base.setCurrentIndex(view.time_base.findData(30.0))  # not live: the data's range stays
    x0, x1 = plot.view_box.viewRange()[0]
    assert 2.8 < x0 < 3.0 and 7.0 < x1 < 7.2


def _values_shown(plot) -> bool:
    return plot.getAxis("left").style["showValues"]


def test_an_empty_plot_shows_no_value_range_until_its_data_arrives(make_window, qtbot):
    """Without a sample each plot's value axis has no numbers (its 0 to 1 would read as a channel
    measuring 0 to 1): the numbers come with the data, plot by plot, and go when it goes."""
    window = make_window()
    view = window.show_page("scope").view
    plot = view.time_plot
    items = plot.plot_items()
    assert len(items) >= 2  # one plot per unit of the ticked channels
    assert not any(_values_shown(item) for item in items)
    by_key = {c.key: c for c in view.all_channels}
    speed, position = by_key["output_speed"], by_key["feedback_position"]
    t = np.linspace(3.0, 7.0, 41)
    view.show_static([speed, position], np.column_stack([t, 10 * t, t + 90]), "a test capture", 10.0)
    shown = plot.plot_items()
    assert [plot.plot_of(c.key) is not None for c in (speed, position)] == [True, True]
    assert all(_values_shown(item) for item in shown)
    y0, y1 = plot.plot_of("output_speed").vb.viewRange()[1]
    assert y0 < 30.0 and y1 > 70.0  # the data's range, not 0 to 1
    view.back_to_live()  # no link: nothing arrives
    assert not any(_values_shown(item) for item in plot.plot_items())


def test_live_samples_give_each_plot_its_numbers(scope_window, qtbot):
    _window, page = scope_window
    view = page.view
    view.start_live()
    qtbot.waitUntil(lambda: all(_values_shown(item) for item in view.time_plot.plot_items()), timeout=20000)
    view.stop_live()
