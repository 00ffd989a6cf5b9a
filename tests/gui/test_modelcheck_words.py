"""The model-check page for a person: the README's flow with the defaults, plain words, one line of
what to do next beside each effect, numbered steps, and the analysis bandwidth set by hand."""

from __future__ import annotations

import re

import numpy as np
import pytest

from fha_studio.gui.link import Call

CODE = "FHA-25C-50-US250"
SNAKE_CASE = re.compile(r"\b[a-z]+(?:_[a-z0-9]+)+\b")
INTERNAL_TERMS = ("ΔBIC", "BIC", "AR(", " cv ", "sigma", "whitened", "jackknife")


def _servo_on(client) -> None:
    client.servo(True)


@pytest.mark.slow
def test_the_readme_flow_with_the_default_capture_is_not_refused(make_window, qtbot):
    # the embedded drive as it starts (no load, no hidden effect), the declared load inertia left at 0,
    # the Scope's move test with its defaults
    window = make_window(connect="sim://FHA-25C-50-US250?paced=0")
    scope = window.show_page("scope").view
    with qtbot.waitSignal(window.link.sigResult, timeout=20000,
                          check_params_cb=lambda r: r.answers(Call)) as on:
        window.link.send(Call(_servo_on))
    assert on.args[0].error is None, on.args[0].error
    assert window.session.state.load_inertia_kgm2 == 0.0
    with qtbot.waitSignal(scope.sigTestDone, timeout=60000) as test:
        scope.run_test("move")
    assert test.args[0].capture is not None, test.args[0].describe()
    page = window.show_page("modelcheck")
    page.take_scope_capture()
    assert page.inertia_spin.value() == 0.0
    failures: list[str] = []
    page.sigFailed.connect(failures.append)
    with qtbot.waitSignal(page.sigFinished, timeout=60000) as done:
        page.run()
    assert not failures
    result = done.args[0]
    text = page.summary.toPlainText()
    assert "looks like noise" not in text
    assert result.channel_status["torque"].status in ("checked", "too little signal")
    assert result.channel_status["position"].status in ("absent", "too little signal", "checked")
    assert [e.id for e in result.effects if not e.alternatives] in ([], ["inertia_error"]), text


def test_the_effects_tab_speaks_plain_words_and_says_what_to_do_next(make_window, qtbot, friction_file):
    window = make_window()
    page = window.show_page("modelcheck")
    window.session.state.set_load_inertia(1.5)
    page.load_recording(friction_file)
    with qtbot.waitSignal(page.sigFinished, timeout=60000) as done:
        page.run()
    result = done.args[0]
    assert [e.id for e in result.effects] == ["coulomb_friction"]
    # numbered steps, each number once
    tabs = [page.steps.tabText(i) for i in range(page.steps.count())]
    numbers = [t.split()[0] for t in tabs]
    assert numbers == ["1", "2", "3", "4", "5"], tabs
    # the effects table: the effect, its size in words, what it could also be, what to do next
    table = page.effects_table
    headers = [table.horizontalHeaderItem(c).text() for c in range(table.columnCount())]
    assert headers[-1] == "What to do next"
    row = [table.item(0, c).text() for c in range(table.columnCount())]
    assert row[0] == "Coulomb friction" and row[1].startswith("torque 8") and row[1].endswith("N·m")
    assert row[3].startswith("add 8") and "Coulomb friction to the model" in row[3] and "brake" in row[3]
    # nothing a person reads uses the criterion's jargon or the program's identifiers
    shown = "\n".join([page.findings.toPlainText(), page.summary.toPlainText(), *row, *tabs])
    for term in INTERNAL_TERMS:
        assert term not in shown, term
    assert not SNAKE_CASE.findall(shown), SNAKE_CASE.findall(shown)
    assert "explains held-out data" in page.findings.toPlainText()
    assert f"Analysis bandwidth {result.bandwidth_hz:.3g} Hz" in page.summary.toPlainText()


def test_the_bandwidth_can_be_set_within_what_the_recording_supports(make_window, qtbot, friction_file):
    from fha_studio.logic.modelcheck.signals import window_bounds, window_for_bandwidth

    window = make_window()
    page = window.show_page("modelcheck")
    window.session.state.set_load_inertia(1.5)
    recording = page.load_recording(friction_file)
    n, dt = len(recording), float(np.median(np.diff(recording.t_s)))
    assert page.bandwidth_spin.value() == 0.0 and page.bandwidth_spin.text() == "from the data"
    assert page.analysis_window() is None
    page.bandwidth_spin.setValue(4.0)
    expected = window_for_bandwidth(4.0, n, dt)
    assert page.analysis_window() == expected
    with qtbot.waitSignal(page.sigFinished, timeout=60000) as done:
        page.run()
    result = done.args[0]
    assert result.window_samples == expected and result.window_reason == "given by the user"
    # the spin box cannot go past what the recording supports; below it, the longest window is used
    lo, hi = window_bounds(n)
    page.bandwidth_spin.setValue(1e6)
    assert page.analysis_window() == lo
    page.bandwidth_spin.setValue(0.01)
    assert page.analysis_window() == hi
