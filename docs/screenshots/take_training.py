"""Takes the README's training screenshots: choosing a scenario, a session in progress, the
score sheet.

    xvfb-run -a -s "-screen 0 1366x768x24" python docs/screenshots/take_training.py [OUTDIR]

A scripted trainee on the fault hunt: reads and fixes parameter 6, jogs with the brake applied
(an unsafe act), never checks the brake, writes the findings and says done. Settings and data go
to a temporary directory, never the user's.
"""

from __future__ import annotations

import time
from pathlib import Path

from shots import ScreenshotRun, private_folder

TMP = private_folder()


def wait(app, seconds: float, until=None) -> None:
    """Runs the event loop for ``seconds``, or until ``until()`` says it is there."""
    end = time.monotonic() + seconds
    while time.monotonic() < end and not (until and until()):
        app.processEvents()
        time.sleep(0.01)


def main() -> int:
    run = ScreenshotRun((1366, 740), settle_before_shot_s=0.0)
    app, window = run.app, run.window
    from fha_studio.gui.link import ReadParameters, Servo, WriteParameters
    from fha_studio.gui.training import ChooseScenarioDialog, RunningDialog, ScoreSheetDialog

    def shot(widget, name: str) -> None:
        run.shot(name, widget)

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
    page.motion.speed_spin.setValue(5.0)
    page.motion._jog(+1)  # as if FWD were held: the brake still holds
    wait(app, 1.5)
    window.link.jog_release()  # _jog pressed no button: releasing the buttons would not end it
    wait(app, 10, lambda: not window.link.moving)
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
    run.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
