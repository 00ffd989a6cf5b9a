"""A conflict settled in the register dialog: two laptops' registers that changed the same axis
while apart are synced (a real conflict, as tests/register/test_sync.py makes them), a reviewer
sees each conflict's sides side by side in the manual's words, keeps one and says why; the
settlement is the fact ``register resolve`` records, and travels with the next sync. On a server
the settlement goes through the window's queue (never the GUI thread to the server)."""

from __future__ import annotations

import pytest

from fha_studio.gui.register_dialog import RegisterDialog
from fha_studio.logic.register import Register
from fha_studio.logic.register.conflicts import side_name
from fha_studio.logic.register.sync import sync_registers

M = "Line 3 positioner"
TABLE = f"{M}/table"


def _laptop(path, who, direction, in_position, origin_deg, clock) -> None:
    """What a technician's laptop recorded offline on the shared axis: its parameters read, the
    origin set."""
    with Register(path) as reg:
        reg.ensure_axis(M, "table", who=who, actuator_code="FHA-25C-50-US250", driver_model="HA-655-2-200")
        clock.advance(60)
        reg.record_snapshot(
            TABLE,
            [("system", 8, "rotary_direction", direction), ("tune", 4, "in_position_range", in_position)],
            "link",
            who=who,
        )
        clock.advance(60)
        reg.record_origin(TABLE, f"absolute origin set (OWW), read back at {origin_deg:+.2f}°", who=who)


@pytest.fixture
def synced(tmp_path, fixed_clock):
    """Ana's and Ben's laptops, apart, then synced: three conflicts of the table axis in both
    (rotary direction and in-position range, the origin)."""
    ana, ben = tmp_path / "ana-laptop.sqlite", tmp_path / "ben-laptop.sqlite"
    _laptop(ana, "ana", 1, 10, 0.01, fixed_clock)
    _laptop(ben, "ben", 0, 25, 0.0, fixed_clock)
    fixed_clock.advance(3600)
    assert len(sync_registers(ana, ben, who="ana").conflicts) == 2
    return ana, ben


def _column(table, column):
    return [table.item(r, column).text() for r in range(table.rowCount())]


def _cells(dialog):
    table = dialog.sides_table
    headers = [table.horizontalHeaderItem(c).text() for c in range(table.columnCount())]
    return headers, [
        [table.item(r, c).text() for c in range(table.columnCount())] for r in range(table.rowCount())
    ]


def test_a_reviewer_settles_a_conflict_side_by_side(qtbot, synced, fixed_clock):
    from tests.gui.test_plain_words import leaks

    ana, ben = synced
    reg = Register(ben)
    dialog = RegisterDialog(reg, M, "table", operator=lambda: "Carla Reviewer")
    qtbot.addWidget(dialog)
    dialog.resize(1280, 720)
    dialog.show()
    assert dialog.tabs.tabText(dialog.conflicts_index) == "Co&nflicts (2)"
    assert dialog.conflicts_label.text().startswith(
        "2 open conflicts: registers synced after they were apart"
    )
    # the history says where a conflict is settled in this window, not the command line
    history = _column(dialog.history_table, 3)
    assert sum(t.endswith(": open — settle it on the Conflicts tab") for t in history) == 2
    # the origin is named once: "the origin differs between …: open", not "… (origin): open"
    assert not any("(origin)" in t for t in history)
    assert not any("fha-studio register resolve" in t for t in history)
    # the open items lead there
    row = _column(dialog.open_table, 1).index("conflict")
    dialog.open_table.cellDoubleClicked.emit(row, 2)
    assert dialog.tabs.currentIndex() == dialog.conflicts_index
    assert sorted(_column(dialog.conflicts_table, 3)) == [
        "parameters differ: tune 4 In-position range, parameter 8 Rotary direction",
        "the origin differs",  # not "the origin differs: origin"
    ]
    assert _column(dialog.conflicts_table, 4) == ["open", "open"]
    parameters = next(c for c in reg.conflicts() if c.subject == "parameters")
    assert dialog.show_conflict(parameters.short[:6])
    c = dialog.current_conflict()
    assert c is not None and c.uid == parameters.uid
    assert dialog.conflict_title.text().startswith(
        f"<b>{TABLE}</b> — conflict {c.short}, found 2026-11-30 08:04:00 UTC by ana: "
        "parameters differ between "
    )
    headers, rows = _cells(dialog)
    # each side by the register it was recorded in, numbered as `register resolve --keep` takes them
    ana_n = next(n for n, s in enumerate(c.sides, 1) if s.values["rotary_direction"].who == "ana")
    ben_n = 3 - ana_n
    assert headers[0] == "Parameter"
    assert headers[ana_n].startswith(f"{ana_n}: ") and headers[ana_n].endswith(" ana-laptop.sqlite")
    assert headers[ben_n].startswith(f"{ben_n}: ") and headers[ben_n].endswith(" ben-laptop.sqlite")
    assert [r[0] for r in rows] == ["tune 4 In-position range (pulse)", "parameter 8 Rotary direction"]
    in_position, direction = rows
    assert direction[ana_n].splitlines() == [
        "1: FWD turns CCW (reversed)",
        "parameters read — ana, 2026-11-30 07:01:00 UTC",
        f"recorded in {headers[ana_n].split(': ', 1)[1]}",
    ]
    assert direction[ben_n].splitlines()[:2] == [
        "0: FWD turns CW (seen from the flange)",
        "parameters read — ben, 2026-11-30 07:03:00 UTC",
    ]
    assert (in_position[ana_n].splitlines()[0], in_position[ben_n].splitlines()[0]) == (
        "10 pulse",
        "25 pulse",
    )
    assert not leaks(dialog)  # the manual's words: no ids, reprs or wire names

    # nothing is settled until a side is chosen
    assert dialog.settle_box.isEnabled() and not dialog.settle_button.isEnabled()
    assert dialog.settle_who.text() == "Carla Reviewer"
    dialog.keep_group.button(ana_n).click()
    assert dialog.settle_button.isEnabled()
    dialog.settle_note.setText("checked on the machine: reversed")
    fixed_clock.advance(60)
    dialog.settle_button.click()
    assert (
        dialog.settle_label.text()
        == f"Conflict {c.short} settled: kept {ana_n}, {headers[ana_n].split(': ', 1)[1]}."
    )
    assert dialog.tabs.tabText(dialog.conflicts_index) == "Co&nflicts (1)"
    # the fact `register resolve` records: the kept side stands, both sides' facts stay
    assert [x.subject for x in reg.conflicts()] == ["origin"]
    (resolution,) = reg.conflict(c.uid).resolutions
    assert (resolution.kept, resolution.who, resolution.note) == (
        ana_n,
        "Carla Reviewer",
        "checked on the machine: reversed",
    )
    known = reg.current_values(TABLE).values["rotary_direction"]
    assert (known.value, known.source) == (1, "settled")
    newest = _column(dialog.history_table, 3)[0]
    assert newest.startswith(f"conflict {c.short} settled: kept {ana_n}, ")
    assert newest.endswith("(checked on the machine: reversed)")
    # settled ones are shown on asking, with who settled them and the side kept; not settled twice
    dialog.show_settled.setChecked(True)
    assert dialog.show_conflict(c.short)
    assert "<br>Settled by Carla Reviewer at 2026-11-30 08:05:00 UTC: kept" in dialog.conflict_title.text()
    headers, _rows = _cells(dialog)
    assert headers[ana_n].endswith(" — kept") and not headers[ben_n].endswith(" — kept")
    assert not dialog.settle_box.isEnabled() and dialog.keep_group.checkedId() == ana_n
    assert f"settled by Carla Reviewer: kept {ana_n}" in _column(dialog.conflicts_table, 4)
    assert not leaks(dialog)
    reg.close()

    # the settlement is a fact that travels: Ana's laptop has it after the next sync
    sync_registers(ben, ana)
    with Register(ana) as theirs:
        assert [x.subject for x in theirs.conflicts()] == ["origin"]


def test_a_settlement_the_register_refuses_is_said_and_nothing_changes(qtbot, synced):
    _ana, ben = synced
    reg = Register(ben)
    dialog = RegisterDialog(reg, M, "table")
    qtbot.addWidget(dialog)
    dialog.show()
    c = dialog.current_conflict()
    assert c is not None
    reg.resolve_conflict(c.uid, 1, who="dora")  # settled meanwhile, from another window
    dialog.keep_group.button(2).click()
    dialog.settle_who.setText("Carla Reviewer")
    assert dialog.settle() is False
    assert dialog.settle_label.text() == (
        f"Not settled ({TABLE}): conflict {c.short} was settled by dora at 2026-11-30 08:04:00 UTC (kept 1)"
    )
    assert [r.kept for r in reg.conflict(c.uid).resolutions] == [1]
    reg.close()


def test_on_a_server_the_settlement_goes_through_this_computers_queue(
    qtbot, postgres_cluster, tmp_path, fixed_clock
):
    """The machine window's dialog on the plant's server: a settlement is written into this
    computer's register for the server (its queue, which holds only what this computer records:
    the conflict goes with it) and reaches the server by the delivery, never from the GUI thread;
    the dialog says it waits, then shows it settled."""
    from fha_studio.gui.register_questions import ServerQuestions
    from fha_studio.gui.register_worker import ServerWriter

    url = postgres_cluster.new_database()
    ana, ben = tmp_path / "ana-laptop.sqlite", tmp_path / "ben-laptop.sqlite"
    _laptop(ana, "ana", 1, 10, 0.01, fixed_clock)
    _laptop(ben, "ben", 0, 25, 0.0, fixed_clock)
    sync_registers(ana, url)
    sync_registers(ben, url)
    server = Register(url)  # the test's own look at the server
    writer, questions = ServerWriter(url), ServerQuestions(url)
    try:
        dialog = RegisterDialog(questions, M, "table", writer=writer, operator=lambda: "Carla Reviewer")
        qtbot.addWidget(dialog)
        dialog.show()
        c = next(x for x in server.conflicts() if x.subject == "parameters")
        qtbot.waitUntil(lambda: dialog.show_conflict(c.short), timeout=30000)  # asked from another thread
        dialog.keep_group.button(2).click()
        dialog.settle_note.setText("checked on the machine")
        assert dialog.settle() is True
        assert c.uid in {x.uid for x in server.conflicts()}  # not from this thread: still open there
        assert dialog.settle_label.text() == (
            f"Conflict {c.short}: kept 2, {side_name(c.sides[1])}. Recorded on this computer; it "
            "reaches the server with the next delivery (the message line says when the server does not "
            "answer)."
        )
        states = _column(dialog.conflicts_table, 4)
        assert sorted(states) == ["open", "settled here (kept 2): waits to reach the server"]
        assert dialog.tabs.tabText(dialog.conflicts_index) == "Co&nflicts (1)"
        assert not dialog.settle_box.isEnabled()
        # the delivery brings it to the server; the dialog shows it settled there
        qtbot.waitUntil(lambda: _column(dialog.conflicts_table, 4) == ["open"], timeout=30000)
        (resolution,) = server.conflict(c.uid).resolutions
        assert (resolution.kept, resolution.who, resolution.note) == (
            2,
            "Carla Reviewer",
            "checked on the machine",
        )
        assert _column(dialog.conflicts_table, 4) == ["open"]
        assert len(server.conflicts(open_only=False)) == 2  # the delivery found nothing new
        known = server.current_values(TABLE).values["rotary_direction"]
        assert (known.value, known.source) == (c.sides[1].values["rotary_direction"].value, "settled")
        with Register(writer.queue) as queue:  # this computer holds what it recorded, the conflict with it
            assert [x.uid for x in queue.conflicts(open_only=False)] == [c.uid]
            assert [e.kind.value for e in queue.history(TABLE)] == ["axis", "conflict", "settled"]
    finally:
        questions.shutdown()
        writer.shutdown()
        server.close()
