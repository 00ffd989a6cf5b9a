"""The Bench tab when its instrument goes away mid-stream: a hung one (alive, silent, as a USB
analyzer that stops answering) and one pulled out (its sigrok-cli gone) are said on the tab as
NOT LIVE in one line, within the 1 s the acquisition allows a silence, and the trace drawn so far
stays on the plot and in the ring."""

from __future__ import annotations

import os
import shutil
import signal

import pytest

from fha_studio.hardware.bench import sigrok

pytestmark = pytest.mark.skipif(shutil.which("sigrok-cli") is None, reason="sigrok-cli is not installed")


@pytest.fixture
def panel(qtbot):
    from fha_studio.gui.pages.scope.bench_panel import BenchPanel

    made = BenchPanel()
    qtbot.addWidget(made)
    yield made
    made.shutdown()


def _streaming(qtbot, panel):
    with qtbot.waitSignal(panel.source.sigStarted, timeout=10000):
        panel.start("demo", "D0,D1", "1m")

    def plotted() -> int:
        x, _y = panel._curves[0].getData()
        return 0 if x is None else len(x)

    qtbot.waitUntil(lambda: plotted() > 100, timeout=10000)
    acquisition = panel.source.worker._acquisition
    assert acquisition is not None and acquisition._process is not None
    return acquisition._process, plotted


@pytest.mark.parametrize("how", ["hung", "pulled out"])
def test_an_instrument_gone_mid_stream_is_said_and_the_trace_stays(qtbot, panel, how):
    process, plotted = _streaming(qtbot, panel)
    with qtbot.waitSignal(panel.source.sigStopped, timeout=10000) as stopped:
        os.kill(process.pid, signal.SIGSTOP if how == "hung" else signal.SIGKILL)
    why = stopped.args[0]
    text = panel.status_label.text()
    assert text == f"NOT LIVE: {why}" and "\n" not in text
    if how == "hung":  # said after the acquisition's allowance for a silence, which is under 1 s
        assert f"no samples for {sigrok.STALL_S:g} s" in why and sigrok.STALL_S < 1.0
    else:
        assert "stopped sending" in why
    assert plotted() > 100 and panel.source.started is not None and len(panel.source.started.ring) > 100
    assert not panel.start_button.isChecked() and not panel.source.running
