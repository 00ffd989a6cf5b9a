"""Takes the README's screenshots of every page on the embedded simulated drive.

    xvfb-run -a -s "-screen 0 1366x768x24" python docs/screenshots/take.py [OUTDIR]

A scripted commissioning session: connect, read, set the rotary direction to reversed (not
written), servo on and jog, raise alarm 20 on the simulated drive, a sizing duty, a procedures
session. Settings and data go to a temporary directory, never the user's.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
TMP = tempfile.mkdtemp(prefix="fha-shots-")
os.environ["XDG_CONFIG_HOME"] = f"{TMP}/config"
os.environ["XDG_DATA_HOME"] = f"{TMP}/data"

from PySide6.QtCore import QCoreApplication, QTimer  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "screenshots"


def main() -> int:
    app = QApplication(sys.argv[:1])
    QCoreApplication.setOrganizationName("FHA Studio Screenshots")
    QCoreApplication.setApplicationName("fha-studio-screenshots")
    from fha_studio.gui.app import parse_arguments, single_axis_window
    from fha_studio.gui.link import Servo

    window = single_axis_window(parse_arguments(["--no-connect"]))  # as fha-studio makes it
    window.resize(1366, 740)
    window.show()
    window.connect_to("sim://FHA-25C-50-US250?paced=0")
    steps = []

    def step(delay_ms: int):
        def wrap(fn):
            steps.append((delay_ms, fn))
            return fn

        return wrap

    def shot(name: str):
        app.processEvents()
        path = OUT / f"{name}.png"
        window.grab().save(str(path))
        print("saved", path)

    @step(1500)
    def connection():
        window.show_page("connection")
        shot("connection")

    @step(300)
    def parameters():
        page = window.show_page("parameters")
        model = page.model
        model.setData(model.index(model.row_of("position_loop_gain"), 3), "60")
        shot("parameters")

    @step(100)
    def direction():
        page = window.show_page("direction")
        page.ccw_radio.setChecked(True)
        shot("rotary-direction")
        page.cw_radio.setChecked(True)
        window.link.send(Servo(True))

    @step(600)
    def jog():
        page = window.show_page("jog")
        page.motion.speed_spin.setValue(8.0)
        page.motion._jog(+1)  # as if FWD were held

    @step(700)
    def jog_shot():
        shot("jog")
        window.link.jog_release()  # _jog pressed no button: releasing the buttons would not end it

    @step(500)
    def alarm():
        window.link._worker._client.transaction.transport.inner.sim_drive.raise_alarm(20)

    @step(800)
    def alarms():
        window.show_page("alarms")
        shot("alarms")

    @step(300)
    def sizing():
        page = window.show_page("sizing")
        page.inertia_spin.setValue(1.2)
        page.speed_spin.setValue(40.0)
        page.angle_spin.setValue(120.0)
        page.cycle_spin.setValue(1.5)
        page.calculate()

    @step(500)
    def sizing_shot():
        shot("sizing")

    @step(300)
    def procedures():
        # the actuator is typed once, on the Connection page; the procedures take it from there
        window.connection_page.actuator_combo.setCurrentText("FHA-25C-50-US250-B-L")
        window.connection_page.check_pairing()
        page = window.show_page("procedures")
        page.operator_edit.setText("T. Trainee")
        page.new_session(Path(TMP) / "axis1.json")
        page.select_procedure("receiving-inspection")
        shot("procedures")

    @step(100)
    def connect_dialog():
        from fha_studio.gui.connect_dialog import ConnectDialog

        dialog = ConnectDialog(window, ports=[("/dev/ttyUSB0", "FT232R USB UART"), ("/dev/ttyS0", "")])
        dialog.show()
        app.processEvents()
        dialog.grab().save(str(OUT / "connect-dialog.png"))
        print("saved", OUT / "connect-dialog.png")
        dialog.close()
        from fha_studio.gui.window_register import WindowAxisDialog

        naming = WindowAxisDialog(window.window_register, window)  # the toolbar's Register line
        naming.machine_combo.setCurrentText("Line 3 positioner")
        naming.axis_combo.setCurrentText("table")
        naming.show()
        app.processEvents()
        naming.grab().save(str(OUT / "register-axis.png"))
        print("saved", OUT / "register-axis.png")
        naming.close()
        window._closing_confirmed = True
        window.close()
        app.quit()

    def run(index: int = 0):
        if index < len(steps):
            delay, fn = steps[index]

            def go():
                try:
                    fn()
                except Exception:
                    app.exit(1)  # a step that fails ends the script (it waited for ever)
                    raise
                run(index + 1)

            QTimer.singleShot(delay, go)

    def when_read(waited_ms: int = 0):
        """The steps start once the drive's values are read (a loaded machine takes seconds)."""
        if len(window.state.drive_values) >= 14:
            run()
        elif waited_ms > 60000:
            print("the simulated drive did not answer within 60 s", file=sys.stderr)
            app.exit(1)
        else:
            QTimer.singleShot(100, lambda: when_read(waited_ms + 100))

    when_read()
    app.exec()
    window.shutdown()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
