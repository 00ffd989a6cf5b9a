"""Takes the README's pictures of a commissioning report's PDF pages (docs/screenshots/report-page-N.png).

    QT_QPA_PLATFORM=offscreen python docs/screenshots/take_report.py [OUTDIR]

A session on the embedded simulated drive: the receiving, installation and wiring checklists walked
with passing answers, the rotary direction confirmed on its page, a scope plot of a jog captured for
the report, then the report printed to PDF and each page turned into a PNG with pdftoppm. Settings
and data go to a temporary directory, never the user's.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
TMP = tempfile.mkdtemp(prefix="fha-report-")
os.environ["XDG_CONFIG_HOME"] = f"{TMP}/config"
os.environ["XDG_DATA_HOME"] = f"{TMP}/data"

from PySide6.QtCore import QCoreApplication  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "screenshots"
CODE = "FHA-25C-50-US250"


def wait(app, condition, timeout_s: float = 20.0) -> None:
    end = time.monotonic() + timeout_s
    while not condition():
        if time.monotonic() > end:
            raise TimeoutError("the simulated drive did not answer in time")
        app.processEvents()
        time.sleep(0.01)


def main() -> int:
    app = QApplication(sys.argv[:1])
    QCoreApplication.setOrganizationName("FHA Studio Screenshots")
    QCoreApplication.setApplicationName("fha-studio-screenshots")
    from fha_studio.gui.link import Servo
    from fha_studio.gui.main_window import MainWindow
    from fha_studio.logic.procedures import ProcedureRun, load_procedure
    from tests.procedures.walk import walk

    window = MainWindow()
    window.resize(1366, 740)
    window.show()
    window.connect_to(f"sim://{CODE}?paced=0")
    wait(app, lambda: len(window.state.drive_values) >= 14)
    direction = window.show_page("direction")
    direction.answer("cw")  # FWD turned the flange CW, as parameter 8 = 0 says
    scope = window.show_page("scope")
    scope.view.start_live()
    window.link.send(Servo(True))
    wait(app, lambda: window.link.servo_on)
    window.link.jog_press(20.0)
    end = time.monotonic() + 2.0
    while time.monotonic() < end:
        app.processEvents()
        time.sleep(0.01)
    window.link.jog_release()
    wait(app, lambda: not window.link.moving)
    scope.view.set_paused(True)
    procedures = window.show_page("procedures")
    procedures.new_session(Path(TMP) / "axis1.json", CODE, operator="T. Technician")
    for procedure_id in ("receiving-inspection", "installation", "wiring"):
        walk(ProcedureRun(procedures.session, load_procedure(procedure_id, procedures.context)),
             who="T. Technician")
    procedures.capture_scope_plot("Jog FWD at 20 r/min: output speed and motor current")
    _html, pdf = procedures.write_report(Path(TMP) / "report.html", Path(TMP) / "report.pdf")
    for old in OUT.glob("report-page-*.png"):
        old.unlink()
    subprocess.run(["pdftoppm", "-r", "70", "-png", str(pdf), str(OUT / "report-page")], check=True)
    for page in sorted(OUT.glob("report-page-*.png")):
        number = int(page.stem.rsplit("-", 1)[1])
        page.rename(OUT / f"report-page-{number}.png")
        print("saved", OUT / f"report-page-{number}.png")
    window.link.send(Servo(False))
    window._closing_confirmed = True
    window.shutdown()
    window.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
