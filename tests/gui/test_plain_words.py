"""Every page, as a technician sees it after a short session on the simulated drive, speaks the
manual's words: no Python reprs, no snake_case identifiers, no file ids of procedures and steps,
no CN3 wire replies and no ASCII units in visible text. So do the model check's findings (its
text, tables and plots), the register dialog, the machine report and the training score sheet."""

from __future__ import annotations

import re

import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QAbstractButton,
    QAbstractItemView,
    QComboBox,
    QGroupBox,
    QLabel,
    QPlainTextEdit,
    QTabBar,
    QTextEdit,
)

from fha_studio.gui.link import MoveBy
from fha_studio.gui.pages.registry import PAGES
from tests.gui.fit import laid_out

SIM_URL = "sim://FHA-25C-50-US250?paced=0"

#: What a person must never read, with why.
LEAKS = (
    (re.compile(r"[{\[]'[a-z_]+'"), "a Python dict or list"),
    (re.compile(r"\bobject at 0x|<[a-z_.]+\.[A-Z]\w+"), "a Python object repr"),
    (re.compile(r"\b(None|True|False)\b"), "a Python constant"),
    (re.compile(r"Traceback|Error\(|Exception\("), "a Python exception"),
    (re.compile(r"\(not processed\)|\b[A-Z]{3}[+-]\d+\b|\b[A-Z]{3}: (refused|rejected)"), "a CN3 frame"),
    (
        re.compile(r"\bkg m(\^2|²)|\bN m\b|\bm\^2\b|\barcsec\b"),
        "a unit not as the manual writes it (N·m, kg·m², N·m·s/rad, arc-sec)",
    ),
    (re.compile(r" -> "), "an ASCII arrow (the manual's →)"),
    (re.compile(r"\w\^ ?\d"), "an ASCII power (I^2 t: the manual writes I²t, m²)"),
)
#: snake_case words (two or more parts); a path, a URL or a file name may hold them.
SNAKE = re.compile(r"(?<![\w/.:?=&-])[a-z][a-z0-9]*(?:_[a-z0-9]+)+(?![\w/.=-])")


def _procedure_ids() -> frozenset[str]:
    """The file ids of the procedures and their steps that have a hyphen ("receiving-inspection",
    "actuator-type-label"): for files, not for people (a page shows the checklist's words)."""
    from fha_studio.logic.procedures import load_all
    from fha_studio.logic.procedures.context import build_context

    ids = {"dgr-checks"}
    for procedure in load_all(build_context("FHA-25C-50-US250")):
        ids.add(procedure.id)
        ids.update(step.id for step in procedure.steps)
    return frozenset(i for i in ids if "-" in i)


PROCEDURE_IDS = _procedure_ids()
PROCEDURE_ID = re.compile(
    r"(?<![\w/.-])(" + "|".join(sorted(PROCEDURE_IDS, key=len, reverse=True)) + r")(?![\w/.-])"
)


def plot_texts(window) -> list[tuple[str, str]]:
    """(where, text) for what the visible plots write: title, axis labels, legend."""
    import pyqtgraph as pg

    texts: list[tuple[str, str]] = []
    for widget in window.findChildren(pg.PlotWidget):
        if not widget.isVisible():
            continue
        item = widget.getPlotItem()
        if item.titleLabel.isVisible() and item.titleLabel.text:
            texts.append(("plot title", item.titleLabel.text))
        for side in ("left", "bottom", "right", "top"):
            axis = item.getAxis(side)
            if axis.isVisible() and axis.label.isVisible():
                texts.append((f"plot axis {side}", axis.label.toPlainText()))
        if item.legend is not None:
            texts += [("plot legend", label.text) for _sample, label in item.legend.items]
    return texts


def visible_texts(window) -> list[tuple[str, str]]:
    """(where, text) for every visible text a person can read in the window now."""
    texts: list[tuple[str, str]] = []
    for label in window.findChildren(QLabel):
        if label.isVisible() and label.text():
            texts.append((f"label {label.objectName() or type(label.parent()).__name__}", label.text()))
    for button in window.findChildren(QAbstractButton):
        if button.isVisible() and button.text() and not isinstance(button.parent(), QTabBar):
            texts.append(("button", button.text()))
    for box in window.findChildren(QGroupBox):
        if box.isVisible():
            texts.append(("group", box.title()))
    for combo in window.findChildren(QComboBox):
        if combo.isVisible():
            texts += [("choice", combo.itemText(i)) for i in range(combo.count())]
    for edit in window.findChildren(QPlainTextEdit) + window.findChildren(QTextEdit):
        if edit.isVisible():
            texts.append((f"text {edit.objectName()}", edit.toPlainText()))
    for view in window.findChildren(QAbstractItemView):
        model = view.model()
        if not view.isVisible() or model is None:
            continue
        from PySide6.QtCore import QModelIndex

        try:
            columns = model.columnCount(QModelIndex())
        except TypeError:  # Qt's own list models (a combo box's popup): the combo is read above
            continue
        for row in range(min(model.rowCount(QModelIndex()), 200)):
            for col in range(columns):
                value = model.data(model.index(row, col))
                if value is not None:
                    texts.append((f"table {view.objectName() or type(view).__name__}", str(value)))
        for col in range(columns):
            header = model.headerData(col, Qt.Orientation.Horizontal)
            if header is not None:
                texts.append(("table header", str(header)))
    return texts + plot_texts(window)


def leaks(window) -> list[str]:
    return text_leaks(visible_texts(window))


def text_leaks(texts: list[tuple[str, str]]) -> list[str]:
    """What a person must not read in ``texts`` ((where, text) pairs), one line each."""
    found = []
    for where, text in texts:
        for line in re.sub(r"<[^>]+>", " ", text).splitlines():  # rich text: the tags are not read
            found += _line_leaks(where, line)
    return found


def _line_leaks(where: str, line: str) -> list[str]:
    shown = repr(line.strip()[:160])
    found = [f"{where}: {why}: {shown}" for pattern, why in LEAKS if pattern.search(line)]
    found += [f"{where}: an identifier {word!r}: {shown}" for word in SNAKE.findall(line)]
    found += [f"{where}: a procedure's file id {word!r}: {shown}" for word in PROCEDURE_ID.findall(line)]
    return found


def html_texts(where: str, html: str) -> list[tuple[str, str]]:
    """(where, line) for each line a reader of the HTML document sees."""
    from PySide6.QtGui import QTextDocument

    document = QTextDocument()
    document.setHtml(html)
    return [(where, line) for line in document.toPlainText().splitlines() if line.strip()]


def test_every_page_speaks_the_manuals_words(make_window, qtbot):
    window = make_window(connect=SIM_URL)
    window.resize(1366, 740)
    qtbot.waitUntil(lambda: len(window.state.drive_values) >= 14, timeout=15000)
    # a short session: an edit written, a refused move, an alarm
    parameters = window.show_page("parameters")
    model = parameters.model
    assert model.setData(model.index(model.row_of("in_position_range"), 3), "20")
    with qtbot.waitSignal(window.session.sigWritesDone, timeout=15000):
        parameters.write_changed()
    window.link.send(MoveBy(10.0))  # servo off: refused
    qtbot.waitUntil(lambda: "failed" in window.message_area.text_label.text(), timeout=15000)
    window.link._worker._client.transaction.transport.inner.sim_drive.raise_alarm(20)
    qtbot.waitUntil(lambda: window.alarm_lamp.state is True, timeout=15000)
    problems = []
    for entry in PAGES:
        with qtbot.waitSignal(window.link.sigStatus, timeout=15000):  # the page takes a status shown
            window.show_page(entry.id.value if hasattr(entry.id, "value") else entry.id)
        laid_out(qtbot, window)
        problems += [f"{entry.title}: {p}" for p in leaks(window)]
    problems = sorted(set(problems))
    assert not problems, "\n".join(problems)


def test_the_model_checks_findings_speak_the_manuals_words(make_window, qtbot, friction_file):
    window = make_window()
    window.resize(1280, 720)
    page = window.show_page("modelcheck")
    window.session.state.set_load_inertia(1.5)
    page.load_recording(friction_file)
    with qtbot.waitSignal(page.sigFinished, timeout=60000):
        page.run()
    problems = []
    for tab in range(page.steps.count()):
        page.steps.setCurrentIndex(tab)
        laid_out(qtbot, page)
        problems += [f"{page.steps.tabText(tab)}: {p}" for p in leaks(page)]
        if page.where_channel.isVisible():  # the residual against each variable, of each channel
            for channel in range(page.where_channel.count()):
                page.where_channel.setCurrentIndex(channel)
                for variable in range(page.where_variable.count()):
                    page.where_variable.setCurrentIndex(variable)
                    problems += [f"{page.steps.tabText(tab)}: {p}" for p in leaks(page)]
    problems = sorted(set(problems))
    assert not problems, "\n".join(problems)


def _wrong_label_session(axis: str):
    """A receiving inspection stopped at the actuator's label (the wrong model given)."""
    from fha_studio.logic.procedures import ProcedureRun, ProcedureSession, load_procedure
    from fha_studio.logic.procedures.context import build_context

    session = ProcedureSession(actuator_code="FHA-25C-50-US250", axis=axis, operator="ana")
    run = ProcedureRun(
        session, load_procedure("receiving-inspection", build_context(session.actuator_code)), autosave=False
    )
    run.submit(True, who="ana")
    run.submit("FHA-17C-50-US250", who="ana")
    return session


@pytest.fixture
def filled_register(tmp_path):
    """A register with one of everything an axis's history holds, as the GUI records it."""
    from fha_studio.logic.procedures.session import CheckRecord
    from fha_studio.logic.register import Register
    from fha_studio.logic.register.importers import record_session
    from fha_studio.logic.register.store import utc_stamp

    reg = Register(tmp_path / "r.sqlite")
    reg.add_machine("Cell 2", site="Hall 1")
    reg.add_axis("Cell 2", "x", "FHA-25C-50-US250", "HA-655-2-200", "sim://a", 1.5, who="ana")
    reg.add_axis("Cell 2", "y", "FHA-25C-50-US250", "HA-655-2-200", "sim://b", who="ana")
    reg.update_axis("Cell 2/x", who="ana", load_inertia_kgm2=2.0, serial_number="S123")
    values = [("system", 8, "rotary_direction", 0), ("tune", 4, "in_position_range", 10)]
    for name in ("x", "y"):
        reg.record_snapshot(f"Cell 2/{name}", values, "link", who="ana")
    reg.record_write("Cell 2/x", "tune", 4, "in_position_range", 25, 10, 25, True, who="ana")
    reg.record_write("Cell 2/x", "system", 8, "rotary_direction", 1, 0, 0, False, "read-back differs")
    reg.record_alarm("Cell 2/x", 20, "Overload", who="ana", note="while jogging")
    reg.add_axis_note("Cell 2/x", "brake released by hand", who="ana")
    # a receiving inspection with the wrong label given (it fails), recorded as the GUI does
    record_session(reg, "Cell 2/x", _wrong_label_session("x"))
    # the DGR checks page's origin, with its readings and no sentence of its own
    at = utc_stamp()
    reg.record_checks(
        "Cell 2/x",
        [CheckRecord("dgr-checks", "absolute_origin", "dgr", "", "Absolute origin", {"position_deg": 0.01},
                     "", "", True, "ana", at, "")],
    )
    reg.record_origin("Cell 2/x", "absolute origin set (OWW), read back at +0.01°", who="ana")
    recording = tmp_path / "move.csv"
    recording.write_text("t_s\n0\n")
    reg.record_recording("Cell 2/x", recording, "move test, 2 s", who="ana")
    reg.record_model_check("Cell 2/x", "Coulomb friction: 8.0 N·m", recording_file=recording, who="ana")
    yield reg
    reg.close()


def test_the_register_dialog_speaks_the_manuals_words(qtbot, filled_register):
    from fha_studio.gui.register_dialog import RegisterDialog

    dialog = RegisterDialog(filled_register, "Cell 2", "x")
    qtbot.addWidget(dialog)
    dialog.resize(1280, 720)
    dialog.show()
    qtbot.waitExposed(dialog)
    problems = []
    for tab in range(dialog.tabs.count()):
        dialog.tabs.setCurrentIndex(tab)
        if tab == 1:  # compare a snapshot too
            dialog.compare_b.setCurrentIndex(dialog.compare_b.count() - 1)
        if tab == 2:  # find, with a value and without
            for key, value in (("in_position_range", "25"), ("rotary_direction", None)):
                dialog.find_parameter.setCurrentIndex(dialog.find_parameter.findData(key))
                if value is not None:
                    dialog.find_value.setEditText(value)
                dialog.find_button.click()
                problems += [f"{dialog.tabs.tabText(tab)}: {p}" for p in leaks(dialog)]
        problems += [f"{dialog.tabs.tabText(tab)}: {p}" for p in leaks(dialog)]
    problems = sorted(set(problems))
    assert not problems, "\n".join(problems)


def test_the_machine_report_speaks_the_manuals_words(filled_register, tmp_path):
    from fha_studio.logic.machine import MachineProject
    from fha_studio.logic.machine_report import build_machine_report, render_machine_html
    from tests.register.test_machine import _finished_session

    project = MachineProject.from_register(filled_register, "Cell 2")
    x = _finished_session("FHA-25C-50-US250", "x", tmp_path / "x.json")
    sessions = {"x": x, "y": _wrong_label_session("y")}
    report = build_machine_report(project, sessions, register=filled_register)
    problems = sorted(set(text_leaks(html_texts("machine report", render_machine_html(report)))))
    assert not problems, "\n".join(problems)


def test_the_training_score_sheet_speaks_the_manuals_words():
    from fha_studio.logic.training.scenario import find_scenario
    from fha_studio.logic.training.score import TraineeRecord, score
    from fha_studio.logic.training.sheet import render_sheet_html
    from tests.training.test_scenarios import _entry

    t0 = 1_796_000_000.0  # 2026-11-30, a session of ten minutes
    journal = [
        _entry(t0 + 10, "JOG", 500, servo_on=True, brake_holding=True),
        _entry(t0 + 20, "PRD", item=("system", 6)),
        _entry(t0 + 30, "PWR", 500, item=("system", 6), servo_on=True, terminal="s"),
        _entry(t0 + 40, "PWR", 500, item=("system", 6)),
    ]
    for scenario_id in ("fault-hunt", "first-day"):
        record = TraineeRecord(
            started_s=t0, ended_s=t0 + 300, journal=journal, findings="P6 was wrong", trainee="Ann"
        )
        html = render_sheet_html(score(find_scenario(scenario_id), record))
        problems = sorted(set(text_leaks(html_texts(f"score sheet {scenario_id}", html))))
        assert not problems, "\n".join(problems)
