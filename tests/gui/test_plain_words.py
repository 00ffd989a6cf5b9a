"""Every page, as a technician sees it after a short session on the simulated drive, speaks the
manual's words: no Python reprs, no snake_case identifiers, no CN3 wire replies in visible text."""

from __future__ import annotations

import re

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

from fha_studio.gui.link import Cmd
from fha_studio.gui.pages.registry import PAGES

SIM_URL = "sim://FHA-25C-50-US250?paced=0"

#: What a person must never read, with why.
LEAKS = (
    (re.compile(r"[{\[]'[a-z_]+'"), "a Python dict or list"),
    (re.compile(r"\bobject at 0x|<[a-z_.]+\.[A-Z]\w+"), "a Python object repr"),
    (re.compile(r"\b(None|True|False)\b"), "a Python constant"),
    (re.compile(r"Traceback|Error\(|Exception\("), "a Python exception"),
    (re.compile(r"\(not processed\)|\b[A-Z]{3}[+-]\d+\b|\b[A-Z]{3}: (refused|rejected)"), "a CN3 frame"),
    (re.compile(r"\bkg m(\^2|²)|\bN m\b|\bm\^2\b"), "a unit not as the manual writes it (N·m, kg·m²)"),
)
#: snake_case words (two or more parts); a path, a URL or a file name may hold them.
SNAKE = re.compile(r"(?<![\w/.:?=&-])[a-z][a-z0-9]*(?:_[a-z0-9]+)+(?![\w/.=-])")


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
    return texts


def leaks(window) -> list[str]:
    found = []
    for where, text in visible_texts(window):
        plain = re.sub(r"<[^>]+>", " ", text)  # rich text: the tags are not read
        for pattern, why in LEAKS:
            if pattern.search(plain):
                found.append(f"{where}: {why}: {plain.strip()[:160]!r}")
        for word in SNAKE.findall(plain):
            found.append(f"{where}: an identifier {word!r}: {plain.strip()[:160]!r}")
    return found


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
    window.link.send(Cmd.MOVE_BY, 10.0)  # servo off: refused
    qtbot.waitUntil(lambda: "failed" in window.message_area.text_label.text(), timeout=15000)
    window.link._worker._client.transaction.transport.inner.sim_drive.raise_alarm(20)
    qtbot.waitUntil(lambda: window.alarm_lamp.state is True, timeout=15000)
    problems = []
    for entry in PAGES:
        window.show_page(entry.id.value if hasattr(entry.id, "value") else entry.id)
        qtbot.wait(100)  # let the page lay out and take its first status
        problems += [f"{entry.title}: {p}" for p in leaks(window)]
    problems = sorted(set(problems))
    assert not problems, "\n".join(problems)
