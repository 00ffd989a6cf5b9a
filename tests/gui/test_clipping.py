"""Nothing clipped on the Parameters page and in the file comparison: the power-cycle banner's
button whole and the edited row in view on a small screen, the comparison's columns in view, and
only drive-versus-file differences flagged."""

from __future__ import annotations

import pytest
from PySide6.QtCore import QRect

SIM_URL = "sim://FHA-25C-50-US250?paced=0"


@pytest.fixture
def window(make_window, qtbot):
    w = make_window(connect=SIM_URL)
    qtbot.waitUntil(lambda: len(w.state.drive_values) >= 14, timeout=10000)
    return w


def write_rotary_direction_reversed(window, qtbot):
    page = window.show_page("parameters")
    model = page.model
    row = model.row_of("rotary_direction")
    page.table.selectRow(row)
    model.setData(model.index(row, 3), "1")
    assert page.message.text() == "1 item edited, not written yet."  # not "1 item(s)"
    with qtbot.waitSignal(window.session.sigWritesDone, timeout=10000):
        page.write_changed()
    qtbot.waitUntil(lambda: page.restart_banner.isVisible(), timeout=10000)
    return page, row


def test_the_power_cycle_banner_shows_its_button_whole_and_keeps_the_edited_row_in_view(window, qtbot):
    window.resize(1024, 600)
    page, row = write_rotary_direction_reversed(window, qtbot)
    button = page.power_cycle_button
    qtbot.waitUntil(lambda: button.isVisible(), timeout=10000)
    # the whole text fits the button and the button fits the banner
    assert button.width() >= button.sizeHint().width()
    assert page.restart_banner.rect().contains(QRect(button.pos(), button.size()))
    # the manual's description: in words, and scrolling rather than cut when longer than its room
    details = page.details.text()
    assert "power cycle" in details and "restart_required" not in details
    assert page.details_scroll.widget() is page.details
    viewport = page.table.viewport().rect()
    qtbot.waitUntil(lambda: viewport.contains(page.table.visualRect(page.model.index(row, 3))), timeout=10000)


def test_the_file_comparison_shows_apply_and_differs_and_flags_drive_against_file(window, qtbot, tmp_path):
    page, _row = write_rotary_direction_reversed(window, qtbot)  # the drive now differs from the default
    saved = page.save_file(str(tmp_path / "axis.toml"))
    lines = [ln if not ln.startswith("in_position_range ") else "in_position_range = 33"
             for ln in saved.read_text().splitlines()]
    (tmp_path / "edited.toml").write_text("\n".join(lines) + "\n")
    dialog = page.load_file(str(tmp_path / "edited.toml"), exec_dialog=False)
    dialog.show()
    qtbot.waitExposed(dialog)
    table = dialog.table
    flagged = [table.item(r, 0).text() for r in range(table.rowCount()) if table.item(r, 4).text()]
    assert flagged == ["tune 4: In-position range"]  # not the rotary direction: drive and file agree
    assert dialog.differing == 1
    assert table.horizontalScrollBar().maximum() == 0
    right = table.columnViewportPosition(5) + table.columnWidth(5)
    assert table.columnViewportPosition(4) >= 0 and right <= table.viewport().width()
    dialog.close()
    dialog.deleteLater()


def test_every_page_fits_a_1024_by_600_screen(window, qtbot):
    """No page asks for more room than a 1024 x 600 screen: the window can be made that small on
    every page (what does not fit scrolls inside the page)."""
    from fha_studio.gui.pages.base import PageId

    for page_id in PageId:
        window.show_page(page_id)
        hint = window.minimumSizeHint()
        assert hint.width() <= 1024 and hint.height() <= 600, f"{page_id}: {hint.width()} x {hint.height()}"
        window.resize(1024, 600)
        qtbot.waitUntil(lambda: window.width() <= 1024 and window.height() <= 600, timeout=10000)


@pytest.mark.parametrize("size", [(1280, 720), (1024, 600)], ids=["1280x720", "1024x600"])
def test_every_page_shows_its_controls_and_its_text_whole(window, qtbot, size):
    """At 1280 x 720 (the window on a 1366 x 768 screen) and 1024 x 600 every page's controls
    are in view without a toolbar's chevron or a tab bar's arrows, and no text is cut: not the
    scope's file buttons, not its read-out progress. At 1280 x 720 an empty field's hint is whole
    too (the DGR checks' "your name (goes into every record)" read "your name (goes …")."""
    from PySide6.QtWidgets import QTabWidget

    from fha_studio.gui.pages.base import PageId
    from tests.gui.fit import cut_hints, cut_texts, hidden_actions, laid_out

    window.resize(*size)
    qtbot.waitUntil(lambda: (window.width(), window.height()) == size, timeout=10000)
    problems: set[str] = set()
    for page_id in PageId:
        page = window.show_page(page_id)
        if page_id is PageId.SCOPE:  # a trace being read out: its progress bar says so
            page.view._on_readout_progress(1200, 40000, 12.0)
        # every tab of the page's own tab widgets (the scope's Trigger and Tests, the model
        # check's steps), each as it is shown
        for tabs in [None, *page.findChildren(QTabWidget)]:
            for index in range(tabs.count() if tabs is not None else 1):
                if tabs is not None:
                    if not tabs.isVisible():
                        break
                    tabs.setCurrentIndex(index)
                laid_out(qtbot, window)
                problems |= {f"{page_id}: {p}" for p in hidden_actions(window) + cut_texts(window)}
                problems |= {f"{page_id}: {p}" for p in cut_hints(window)}
    assert not problems, "\n".join(sorted(problems))


def test_every_status_message_reads_whole(make_window, qtbot):
    """What the status bar says is read whole at 1366 x 740 (a 1366 x 768 screen), 1280 x 720 and
    1024 x 600: the longest message (STOP on a drive without a stop command, the link lost) and the
    link's state (servo on: CN3 silent) wrap onto another line instead of being cut, side by side
    without overlapping, and the window still fits the small screen. The scope's indicator says
    as much as its room holds, never a word cut in two."""
    from fha_studio.gui.link import SERVO_ON_NOTE
    from fha_studio.gui.widgets import StopButton
    from tests.gui.controller import documented_url, panel_done
    from tests.gui.fit import cut_texts

    window = make_window(connect=documented_url("FHA-25C-50-S248"))
    panel_done(window, qtbot, lambda: window.sim_panel.servo_check.setChecked(True))  # servo-ON (CN2)
    qtbot.waitUntil(lambda: SERVO_ON_NOTE in window.caps_label.text(), timeout=10000)
    window.stop_axis()  # nothing can be sent: the message says what stops the axis
    assert StopButton.NO_STOP_TEXT in window.message_area.text_label.text()
    window.state.set_actuator("FHA-25C-50-S248", acknowledged=True)  # its ratio scales DGR's counts
    scope = window.show_page("scope").view  # its indicator says why nothing is live
    scope.start_live()
    qtbot.waitUntil(lambda: "servo on (controller)" in scope.indicator_text(), timeout=10000)

    def problems(size: tuple[int, int]) -> list[str]:
        found = cut_texts(window.statusBar()) + cut_texts(scope.toolbar)
        text, caps = window.message_area.text_label, window.caps_label
        if text.geometry().translated(text.parentWidget().pos()).intersects(caps.geometry()):
            found.append("the message overlaps the link's state")
        if window.height() > size[1]:
            found.append(f"the window is {window.height()} px high")
        return found

    for state in ("servo on", "link lost"):
        if state == "link lost":
            window.link._worker._client.transaction.transport.inner.close()  # the cable is pulled
            qtbot.waitUntil(lambda: "LINK LOST" in window.caps_label.text(), timeout=10000)
            assert "Link lost:" in window.message_area.text_label.text()
        for size in ((1366, 740), (1280, 720), (1024, 600)):
            window.resize(*size)
            qtbot.waitUntil(lambda size=size: window.width() == size[0], timeout=10000)
            try:
                qtbot.waitUntil(lambda size=size: not problems(size), timeout=3000)  # the bar lays out anew
            except qtbot.TimeoutError:
                found = "\n".join(problems(size))
                raise AssertionError(f"{state}, {size[0]} x {size[1]}:\n{found}") from None


def test_the_machine_window_fits_with_every_axis_and_says_it_whole(qtbot, tmp_path):
    """A machine window on a 1366 x 768 screen (1366 x 740, and 1280 x 720) with a full drive and
    one of the manual's commands (its simulated controller's panel shown), both on long ports:
    whichever axis is chosen the window keeps its size, and the banner, the pages' controls and
    the status bar are whole."""
    from fha_studio.gui.machine_window import MachineWindow
    from fha_studio.logic.machine import MachineProject
    from tests.gui.fit import cut_hints, cut_texts, hidden_actions, laid_out
    from tests.support.windows import torn_down

    project = MachineProject("Line 3 positioner", site="Plant A, hall 2")
    project.add_axis("table", "FHA-25C-50-US250",
                     port_url=f"sim://FHA-25C-50-US250?paced=0&eeprom={tmp_path}/table.eeprom.json")
    project.add_axis("tilt", "FHA-32C-100-S248-B",
                     port_url=f"sim://FHA-32C-100-S248-B?profile=documented&paced=0&eeprom={tmp_path}/tilt.json")
    with torn_down(lambda window: [axis.link for axis in window.axis_windows]) as windows:
        window = MachineWindow(project, None)
        windows.append(window)
        window.show()
        window.connect_all()
        qtbot.waitUntil(lambda: all(w.link.connected for w in window.axis_windows), timeout=15000)
        problems = []
        for size in ((1366, 740), (1280, 720)):
            for name in ("table", "tilt"):
                window.resize(*size)
                qtbot.waitUntil(lambda size=size: window.size().toTuple() == size, timeout=3000)
                window.select_axis(name)
                laid_out(qtbot, window)
                hint = window.minimumSizeHint()
                if hint.width() > size[0] or hint.height() > size[1]:
                    problems.append(f"{name}: the window needs {hint.width()} x {hint.height()}")
                    continue
                # the operator's hint too: it was cut at both sizes
                found = hidden_actions(window) + cut_texts(window) + cut_hints(window)
                problems += [f"{name}, {size[0]} x {size[1]}: {p}" for p in found]
        assert not problems, "\n".join(problems)


@pytest.mark.parametrize("size", [(1024, 600), (1280, 720)])
def test_every_parameter_name_and_value_is_whole_on_a_small_screen(window, qtbot, size):
    """At 1024 x 600 (the machine window's page at 1280 x 720 is about as wide) every name and value
    fits its column; only the default, which the tooltip repeats, may be elided."""
    window.resize(*size)
    page = window.show_page("parameters")
    table = page.table
    qtbot.waitUntil(lambda: window.width() <= size[0] and table.isVisible(), timeout=10000)
    assert table.horizontalScrollBar().maximum() == 0
    for column in (2, 3):  # Name, Value
        needed = table.sizeHintForColumn(column)
        assert table.columnWidth(column) >= needed, (column, table.columnWidth(column), needed)
    right = table.columnViewportPosition(7) + table.columnWidth(7)
    assert right <= table.viewport().width()  # the State column in view
