"""The register dialog on a register filled by hand: history newest first, the twin compared by
default, find with a value typed (a wrong one is said, nothing searched), open items."""

from __future__ import annotations

import pytest

from fha_studio.gui.register_dialog import RegisterDialog
from fha_studio.logic.register import Register


@pytest.fixture
def filled(tmp_path, fixed_clock):
    # the axes are added at the clock's 07:00, before the stamped snapshots and the write
    reg = Register(tmp_path / "r.sqlite")
    reg.add_machine("Cell 2")
    for name in ("x", "x twin", "z"):
        reg.add_axis("Cell 2", name, "FHA-17C-50-US250" if name != "z" else "FHA-32C-100-S248")
    values = [("system", 8, "rotary_direction", 0), ("tune", 4, "in_position_range", 10)]
    for name in ("x", "x twin"):
        reg.record_snapshot(f"Cell 2/{name}", values, "link", who="ana", at_utc="2026-11-30T08:00:00Z")
    reg.record_write(
        "Cell 2/x twin",
        "tune",
        4,
        "in_position_range",
        25,
        10,
        25,
        True,
        who="ana",
        at_utc="2026-11-30T09:00:00Z",
    )
    yield reg
    reg.close()


def _column(table, column):
    return [table.item(r, column).text() for r in range(table.rowCount())]


def test_history_compare_find_and_open(qtbot, filled):
    dialog = RegisterDialog(filled, "Cell 2", "x twin")
    qtbot.addWidget(dialog)
    assert dialog.history_axis.currentText().startswith("x twin")
    newest = _column(dialog.history_table, 3)[0]
    assert newest == "tune 4 In-position range: 10 → 25 pulse, verified"
    # the axis chosen against its twin (the next axis with the same actuator, here the first)
    assert (dialog.compare_a.currentText(), dialog.compare_b.currentText()) == (
        "x twin: latest known values",
        "x: latest known values",
    )
    assert _column(dialog.compare_table, 0) == ["tune 4 In-position range"]
    assert (dialog.compare_table.item(0, 1).text(), dialog.compare_table.item(0, 2).text()) == (
        "25 pulse",
        "10 pulse",
    )
    assert dialog.compare_label.text() == "1 of the 2 parameters they hold differ."
    # a snapshot can be chosen instead of an axis's latest values
    dialog.compare_b.setCurrentIndex(dialog.compare_b.findData("2"))
    assert "snapshot 2" in dialog.compare_b.currentText()

    dialog.tabs.setCurrentIndex(2)
    dialog.find_parameter.setCurrentIndex(dialog.find_parameter.findData("in_position_range"))
    for typed, said in (("abc", "'abc' is not a whole number"), ("99999", "99999 pulse is outside 0 pulse")):
        dialog.find_value.setEditText(typed)
        dialog.find_button.click()
        assert dialog.find_label.text().startswith("Nothing searched: ") and said in dialog.find_label.text()
        assert dialog.find_table.rowCount() == 0
    dialog.find_value.setEditText("25")
    dialog.find_button.click()
    assert _column(dialog.find_table, 0) == ["x twin"] and _column(dialog.find_table, 2) == ["verified write"]
    dialog.find_value.setEditText("")
    dialog.find_button.click()
    assert _column(dialog.find_table, 0) == ["x", "x twin"]  # every axis with a value for it

    assert ("z", "check", "no procedure recorded yet") in list(
        zip(
            _column(dialog.open_table, 0),
            _column(dialog.open_table, 1),
            _column(dialog.open_table, 2),
            strict=True,
        )
    )
