"""The simulated controller of a drive on its documented profile, as the GUI tests work it: the sim
panel's servo-ON and command pulses go to the drive's CN2 (CN3 answers only DGR and OWW, and is
silent while the servo is on). Each action waits for the link's answer to the sim-panel request it
sends."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from fha_studio.gui.link import SimPanelAction, SimPanelRequest


def documented_url(code: str) -> str:
    """The embedded simulated drive ``code`` on its documented profile, stepped as fast as it can."""
    return f"sim://{code}?paced=0&profile=documented"


def panel_done(window: Any, qtbot: Any, action: Callable[[], object]) -> Any:
    """Runs ``action`` (a sim panel control: servo-ON, FWD, ...) and waits for the link's answer to
    the sim-panel request it sent; the answer must be ok. Returns its value."""
    with qtbot.waitSignal(window.link.sigResult, check_params_cb=lambda r: r.answers(SimPanelRequest),
                          timeout=10000) as done:
        action()
    assert done.args[0].ok, done.args[0].error
    return done.args[0].value


def panel(window: Any, qtbot: Any, action: str, value: float) -> Any:
    """Sends the sim-panel request ``action`` ("turn", "command", ...) with ``value``; its answer's value."""
    return panel_done(window, qtbot, lambda: window.link.send(SimPanelRequest(SimPanelAction(action), value)))


def bench_streaming(qtbot: Any, bench: Any, *start: Any) -> None:
    """The scope's Bench tab lists the instruments and streams from the first listed (the running
    simulated drive's ``sim-cn2``): ``start`` is what ``bench.start`` takes after the device
    (channels, rate, encoder, command, ...)."""
    with qtbot.waitSignal(bench.sigDevicesListed, timeout=20000):
        bench.scan()
    with qtbot.waitSignal(bench.source.sigStarted, timeout=10000):
        bench.start(bench.device_box.itemText(0), *start)


def bench_standing(qtbot: Any, bench: Any, seconds: float = 0.3) -> None:
    """Waits until the bench's stream holds ``seconds`` more of the axis as it stands now (the
    stream's own time, not the wall clock's): a move's figures start from the rows before it."""
    ring = bench.source.started.ring

    def newest_s() -> float | None:
        rows = ring.window(1, copy=True)
        return float(rows[-1, 0]) if len(rows) else None

    qtbot.waitUntil(lambda: newest_s() is not None, timeout=10000)
    since = newest_s()
    qtbot.waitUntil(lambda: (newest_s() or 0.0) - since >= seconds, timeout=20000)
