"""Takes the README's training screenshots: choosing a scenario, a session in progress, the
score sheet.

    xvfb-run -a -s "-screen 0 1366x768x24" python docs/screenshots/take_training.py [OUTDIR]

A scripted trainee on the fault hunt: reads and fixes parameter 6, jogs with the brake applied
(an unsafe act), never checks the brake, writes the findings and says done. Settings and data go
to a temporary directory, never the user's.
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


def wait(app, seconds: float, until=None) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end and not (until and until()):
        app.processEvents()
        time.sleep(0.01)


def main() -> int:
    app = QApplication(sys.argv[:1])
    QCoreApplication.setOrganizationName("FHA Studio Screenshots")
    QCoreApplication.setApplicationName("fha-studio-screenshots")
    from fha_studio.gui.link import ReadParameters, Servo, WriteParameters
    from fha_studio.gui.main_window import MainWindow
    from fha_studio.gui.training import ChooseScenarioDialog, RunningDialog, ScoreSheetDialog

    window = MainWindow()
    window.resize(1366, 740)
    window.show()

    def shot(widget, name: str) -> None:
        app.processEvents()
        path = OUT / f"{name}.png"
        widget.grab().save(str(path))
        print("saved", path)

    chooser = ChooseScenarioDialog(window)
    chooser.resize(1100, 600)
    chooser.show()
    ids = [s.id for s in chooser.scenarios]
    chooser.list.setCurrentRow(ids.index("fault-hunt"))
    chooser.trainee.setText("A. Trainee")
    wait(app, 0.3)
    shot(chooser, "training-choose")
    scenario = chooser.chosen()
    chooser.close()

    window.training.start(scenario, "A. Trainee", paced=False)
    wait(app, 10, lambda: window.link.connected)
    wait(app, 1.0)
    window.show_page("parameters")
    window.link.send(ReadParameters((("system", 6),)))
    wait(app, 1.0)
    window.link.send(WriteParameters((("system", 6, 500),)))
    wait(app, 1.0)
    window.link.send(Servo(True))
    wait(app, 0.5)
    page = window.show_page("jog")
    page.speed_spin.setValue(5.0)
    page._jog(+1)  # as if FWD were held: the brake still holds
    wait(app, 1.5)
    window.jog_page.release_held()
    wait(app, 0.8)
    window.link.send(Servo(False))
    wait(app, 0.5)
    shot(window, "training-session")

    running = RunningDialog(window.training, window)
    running.findings.setPlainText(
        "Alarm 60 on every move: parameter 6 (position error allowance) was 1. Set it to 500 (the default);"
        " the axis then jogs without an alarm. The current looked high while jogging."
    )
    running.show()
    wait(app, 0.3)
    shot(running, "training-running")
    findings = running.findings.toPlainText()
    running.close()

    sheet = window.training.finish(findings)
    dialog = ScoreSheetDialog(sheet, window)
    dialog.resize(1000, 740)
    dialog.show()
    wait(app, 0.5)
    shot(dialog, "training-score-sheet")
    dialog.save_pdf(Path(TMP) / "training-score-sheet.pdf")
    dialog.close()
    window._closing_confirmed = True
    window.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
