"""The Procedures page's history beside the step: every value whole at 1366 x 768 and 1280 x 720
(wrapped, its row as tall as it needs), who and when in view without scrolling sideways, the step
area as wide as before, and the selected record in full below the table (the newest as it comes)."""

from __future__ import annotations

import pytest
from PySide6.QtCore import QRect, Qt
from PySide6.QtGui import QFontMetrics

from fha_studio.logic.procedures import Observation

CODE = "FHA-25C-50-S248"
LONG_VALUE = "FWD (+11378 counts for +11378 commanded)"
WHERE_FROM = "from CN2: a FWD command (+11378 counts) turned the axis FWD as the encoder outputs count it"
CELL_MARGIN_PX = 6  # the style's padding around a cell's text, both sides together


def _text_fits(table, row: int, column: int) -> bool:
    item = table.item(row, column)
    room = table.columnWidth(column) - CELL_MARGIN_PX
    need = QFontMetrics(table.font()).boundingRect(QRect(0, 0, room, 10_000), Qt.TextFlag.TextWordWrap,
                                                   item.text())
    return need.width() <= room and need.height() <= table.rowHeight(row)


@pytest.mark.parametrize("size", [(1366, 768), (1280, 720)], ids=["1366x768", "1280x720"])
def test_every_value_is_whole_and_the_selected_record_is_in_full_below(make_window, qtbot, tmp_path, size):
    window = make_window()
    window.resize(*size)
    qtbot.waitUntil(lambda: (window.width(), window.height()) == size, timeout=10000)
    window.state.set_actuator(CODE, acknowledged=True)
    page = window.show_page("procedures")
    step_width = page.step_box.width()
    page.operator_edit.setText("A. Technician")
    page.new_session(tmp_path / "axis.json", CODE)
    page.select_procedure("rotary-direction")
    page.choice_combo.setCurrentText("CW")
    page.choice_button.click()
    assert page.answer(True, detail="parameter 8 from the drive's front panel: 0")
    assert page.answer(Observation(LONG_VALUE, True, WHERE_FROM))
    table = page.history
    qtbot.waitUntil(lambda: table.rowCount() == 3 and _text_fits(table, 2, 1), timeout=10000)
    assert table.item(2, 1).text() == LONG_VALUE
    for row in range(table.rowCount()):
        for column in (1, 2, 3):  # value, result, who and when: whole
            assert _text_fits(table, row, column), (row, column, table.item(row, column).text())
    # every column in view, nothing behind a sideways scroll
    header = table.horizontalHeader()
    assert header.sectionViewportPosition(3) + header.sectionSize(3) <= table.viewport().width()
    assert table.horizontalScrollBar().maximum() == 0
    assert page.step_box.width() >= step_width  # the step area not squeezed
    # the newest record in full below the table, with where its value came from
    details = page.record_history.details.text()
    assert LONG_VALUE in details and WHERE_FROM in details and "A. Technician" in details
    # an older one is one click away
    table.selectRow(0)
    assert "Viewing the output flange" in page.record_history.details.text()
    assert "CW — pass" in page.record_history.details.text()
