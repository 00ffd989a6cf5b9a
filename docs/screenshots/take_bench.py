"""Takes the README's screenshots of the scope's Bench tab: a real HA-655 seen through its CN2.

    xvfb-run -a -s "-screen 0 1366x768x24" python docs/screenshots/take_bench.py [OUTDIR]

The embedded simulated drive's documented profile (CN3 silent while the servo is on, as a real
HA-655), its CN2 streamed as the ``sim-cn2`` instrument (a logic analyzer on the encoder
outputs, the command pulse inputs and IN-POS, an oscilloscope channel on SPD-MON), the
controller played by the drive's panel: servo-ON and a 10 deg FWD command. Then sigrok-cli's
``demo`` driver, as any of its instruments shows on the tab. Settings and data go to a
temporary directory, never the user's.
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

from PySide6.QtCore import QCoreApplication  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "screenshots"
CODE = "FHA-25C-50-S248"  # absolute: CN3 gives the position (DGR) while the servo is off
URL = f"sim://{CODE}?paced=0&profile=documented"


def main() -> int:
    app = QApplication(sys.argv[:1])
    QCoreApplication.setOrganizationName("FHA Studio Screenshots")
    QCoreApplication.setApplicationName("fha-studio-screenshots")
    from fha_studio.gui.link import SimPanelAction, SimPanelRequest
    from fha_studio.gui.main_window import MainWindow

    window = MainWindow()
    window.resize(1366, 740)
    window.show()

    def wait_until(condition, what: str, timeout_s: float = 30.0) -> None:
        end = time.monotonic() + timeout_s
        while not condition():
            if time.monotonic() > end:
                raise TimeoutError(f"screenshot script: {what} did not come within {timeout_s:g} s")
            app.processEvents()
            time.sleep(0.01)

    def settle(seconds: float = 0.3) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            app.processEvents()
            time.sleep(0.01)

    def shot(name: str) -> None:
        settle(0.3)
        path = OUT / f"{name}.png"
        window.grab().save(str(path))
        print("saved", path)

    def panel(action: SimPanelAction, value) -> None:
        done: list = []
        window.link.send(SimPanelRequest(action, value), done.append)
        wait_until(lambda: done, f"the drive panel's {action.name}")

    window.connect_to(URL)
    wait_until(lambda: window.link.status is not None, "the drive's first status")
    window.state.set_actuator(CODE, acknowledged=True)
    scope = window.show_page("scope")
    bench = scope.bench
    scope.view.plots.setCurrentWidget(bench)
    listed: list[int] = []
    bench.sigDevicesListed.connect(listed.append)
    bench.scan()
    wait_until(lambda: listed, "the instrument list")
    scope.view.start_live()  # CN3 beside: silent while the servo is on
    wait_until(lambda: scope.view.time_plot.live, "the CN3 live view")
    bench.start(bench.device_box.itemText(0), "ENC_A,ENC_B,CMD_A,CMD_B,IN_POS,ALARM,SPD_MON", "250k",
                "ENC_A,ENC_B", "CMD_A,CMD_B", "IN_POS", "ALARM")
    wait_until(lambda: bench.source.started is not None, "the sim-cn2 stream")
    window.sim_panel.servo_check.setChecked(True)
    wait_until(lambda: window.link.status is not None and window.link.status.servo_on, "servo-ON")
    settle(0.5)
    window.sim_panel.command_spin.setValue(10.0)
    window.sim_panel.fwd_button.click()
    wait_until(lambda: bench.move_figures is not None, "the move's figures")
    settle(0.6)
    shot("bench-move")
    scope.view.plots.setCurrentWidget(scope.view.time_plot)  # the same stream beside CN3's channels
    settle(1.0)
    shot("scope-bench-time")
    scope.view.plots.setCurrentWidget(bench)
    bench.start_button.click()
    wait_until(lambda: not bench.source.running, "the stream's end")
    window.sim_panel.servo_check.setChecked(False)
    wait_until(lambda: window.link.status is not None and not window.link.status.servo_on, "servo-OFF")
    scope.view.stop_live()

    # any instrument sigrok-cli drives: its demo at 10 kHz (every sample drawn), D0/D1 counted as an encoder
    bench.start("demo", "D0,D1,D2,D3", "10k", "D0,D1")
    wait_until(lambda: bench.source.started is not None, "the demo's stream")
    settle(2.5)
    shot("bench-demo")
    bench.start_button.click()
    wait_until(lambda: not bench.source.running, "the demo's end")
    del panel
    window._closing_confirmed = True
    window.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
