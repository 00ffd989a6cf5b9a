"""Takes the model-check screenshots: a back-and-forth move on a simulated drive with a hidden
Coulomb friction, captured by the scope's trace and handed to the model check page.

    xvfb-run -a -s "-screen 0 1366x768x24" python docs/screenshots/take_modelcheck.py [OUTDIR]

Settings and data go to a temporary directory, never the user's.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
TMP = tempfile.mkdtemp(prefix="fha-shots-")
os.environ["XDG_CONFIG_HOME"] = f"{TMP}/config"
os.environ["XDG_DATA_HOME"] = f"{TMP}/data"

from PySide6.QtCore import QCoreApplication, QEventLoop, QTimer  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "screenshots"
URL = "sim://FHA-25C-50-US250?paced=0&load_inertia=0.5&effects=coulomb_friction:torque_nm=12"
#: Longest a 90° move at 20 r/min may take (it takes about 0.8 s) before the run gives up.
MOVE_DEADLINE_S = 20.0


def wait_for(signal, timeout_ms: int, what: str, failures: list[str] | None = None):
    """Waits for ``signal`` at most ``timeout_ms``; TimeoutError naming ``what`` did not come (and
    why, when the move in the link thread said so in ``failures``)."""
    loop = QEventLoop()
    got = []
    signal.connect(lambda *a: (got.append(a), loop.quit()))
    QTimer.singleShot(timeout_ms, loop.quit)
    loop.exec()
    if not got:
        why = f": {failures[-1]}" if failures else ""
        raise TimeoutError(f"{what} did not come within {timeout_ms / 1000:g} s{why}")
    return got[0]


def back_and_forth(client, deadline_s: float = MOVE_DEADLINE_S) -> None:
    """Moves 90° and back; TimeoutError when a move has not ended within ``deadline_s``."""
    client.servo(True)
    client.set_move_speed(20.0)
    for angle in (90.0, -90.0):
        client.move_by(angle)
        time.sleep(0.05)
        end = time.monotonic() + deadline_s
        while client.io_state().moving:
            if time.monotonic() > end:
                raise TimeoutError(f"the move by {angle:g}° had not ended after {deadline_s:g} s "
                                   "(the drive still says it is moving): no screenshots taken")
            time.sleep(0.02)
        time.sleep(0.15)


def main() -> int:
    app = QApplication(sys.argv[:1])
    QCoreApplication.setOrganizationName("FHA Studio Screenshots")
    QCoreApplication.setApplicationName("fha-studio-screenshots")
    from fha_studio.gui.link import Call
    from fha_studio.gui.main_window import MainWindow
    from fha_studio.hardware import protocol as p

    window = MainWindow()
    window.resize(1366, 740)
    window.show()
    window.connect_to(URL)
    wait_for(window.link.sigConnected, 10000, "the connection to the simulated drive")
    scope = window.show_page("scope").view
    scope.load_inertia.setValue(0.5)
    scope.trace_samples.setValue(p.TRACE_MAX_SAMPLES)
    scope.trace_pre.setValue(2)
    scope.trigger_kind.setCurrentIndex(scope.trigger_kind.findData(p.TriggerKind.IO_BIT_RISES))
    scope.trigger_channel.setCurrentIndex(scope.trigger_channel.findData("moving"))
    scope.arm_trace()
    failures: list[str] = []
    QTimer.singleShot(1000, lambda: window.link.send(
        Call(back_and_forth), lambda r: r.ok or failures.append(str(r.error))))
    wait_for(scope.sigTraceDone, 30000, "the scope's trace of the move", failures)
    app.processEvents()
    window.grab().save(str(OUT / "modelcheck-capture.png"))
    page = window.show_page("modelcheck")
    page.take_scope_capture()
    page.run()
    wait_for(page.sigFinished, 60000, "the model check's result")
    for index, name in ((0, "modelcheck-residual"), (1, "modelcheck-where"), (3, "modelcheck-gap"),
                        (4, "modelcheck-resimulation"), (2, "modelcheck-effects")):
        page.steps.setCurrentIndex(index)
        app.processEvents()
        window.grab().save(str(OUT / f"{name}.png"))
        print("saved", OUT / f"{name}.png")
    window._closing_confirmed = True
    window.close()
    window.shutdown()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
