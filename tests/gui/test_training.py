"""A trainee's session in the GUI: the scenario's drive hides its faults on every page, and
"done" gives a score sheet with one fault found and one missed, printed as the report's PDF."""

from __future__ import annotations

import re

from PySide6.QtWidgets import QWidget

from fha_studio.gui.link import ReadParameters, Servo, WriteParameters
from fha_studio.gui.pages.base import PageId
from fha_studio.gui.training import ScoreSheetDialog, briefing_html
from fha_studio.hardware.parameters import Mode
from fha_studio.logic.training.scenario import find_scenario
from tests.gui.fit import laid_out
from tests.gui.test_plain_words import visible_texts

WAIT_MS = 20000  # generous: a loaded 2-core machine

#: What would give a fault away on screen: the options that make them, and their words.
GIVEAWAYS = re.compile(
    r"preset|brake_supply|system\.6|training=|wiring=|parameter 6 .* too low|brake supply missing",
    re.IGNORECASE,
)


def _send(qtbot, window, request):
    results = []
    window.link.send(request, results.append)
    qtbot.waitUntil(lambda: bool(results), timeout=WAIT_MS)
    return results[0]


def test_a_trainee_finds_one_fault_and_misses_the_other(make_window, qtbot, tmp_path):
    scenario = find_scenario("fault-hunt")
    window = make_window()
    with qtbot.waitSignal(window.link.sigConnected, timeout=WAIT_MS):
        window.training.start(scenario, "Ann", paced=False)
    assert window.training.running
    # once connected, the message line says so instead of "Connecting to the training drive …"
    qtbot.waitUntil(lambda: "Connected to the training drive" in window.message_area.latest().text,
                    timeout=WAIT_MS)
    assert "Connecting" not in window.message_area.text_label.text()

    # nothing on screen gives the faults away: every page, the title, tooltips, messages
    window.show_page("connection")
    qtbot.waitUntil(lambda: "(training)" in window.connection_page.link_label.text(), timeout=WAIT_MS)
    seen = []
    for page in PageId:
        window.show_page(page)
        laid_out(qtbot, window)
        seen += [text for _, text in visible_texts(window)]
    seen += [w.toolTip() for w in window.findChildren(QWidget) if w.toolTip()]
    seen += [window.windowTitle(), window.caps_label.toolTip(), window.link_lamp.toolTip()]
    seen += [m.text for m in window.message_area.messages]
    for text in seen:
        assert not GIVEAWAYS.search(text), text
    assert "FHA-25C-50-US250-B-L" in window.connection_page.link_label.text()
    # the trainee's procedure session is named as the training's, not by its temporary folder
    assert window.procedures_page.session_label.text() == (
        "Session of this training (not kept as a commissioning record) — FHA-25C-50-US250-B-L")
    assert not GIVEAWAYS.search(briefing_html(scenario))

    # the trainee reads parameter 6, sees it is far too low and writes the default back
    read = _send(qtbot, window, ReadParameters(((Mode.SYSTEM, 6),)))
    assert read.ok, read.error
    wrote = _send(qtbot, window, WriteParameters(((Mode.SYSTEM, 6, 500),)))
    assert wrote.ok, wrote.error
    # ... but never checks the brake, and writes a parameter with the servo on (refused)
    assert _send(qtbot, window, Servo(True)).ok
    refused = _send(qtbot, window, WriteParameters(((Mode.SYSTEM, 8, 0),)))
    assert _send(qtbot, window, Servo(False)).ok

    sheet = window.training.finish("Parameter 6 was 1: alarm 60 on any move. Set it to 500.")
    assert not window.training.running
    results = {r.fault.id: r for r in sheet.faults}
    assert results["allowance"].found and not results["brake-supply"].found
    assert any("wrote parameter item 6 = 500" in e.text for e in results["allowance"].evidence)
    assert "Wrote a parameter with the servo on" in {a.what for a in sheet.unsafe}, refused
    steps = {s.step.id: s for s in sheet.steps}
    assert steps["parameters"].done_at_s is not None and steps["wiring"].done_at_s is None

    dialog = ScoreSheetDialog(sheet, window)
    try:
        text = dialog.view.toPlainText()
        assert "TRAINING" in text and "found" in text and "missed" in text
        assert "Brake supply missing" in text  # revealed now the session is over
        pdf = dialog.save_pdf(tmp_path / "sheet.pdf")
        assert pdf.read_bytes().startswith(b"%PDF")
        assert "TRAINING" in dialog.save_html(tmp_path / "sheet.html").read_text()
    finally:
        dialog.close()
        dialog.deleteLater()


def test_the_gui_refuses_an_unknown_training_scenario_in_one_line(qtbot, capsys):
    from fha_studio.gui.app import run

    assert run(["--training", "nonesuch"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("fha-studio: no training scenario 'nonesuch'; scenarios: battery, ")
    assert err.count("\n") == 1
