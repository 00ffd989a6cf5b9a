"""Takes the README's pictures of a commissioning report's PDF pages (docs/screenshots/report-page-N.png).

    QT_QPA_PLATFORM=offscreen python docs/screenshots/take_report.py [OUTDIR]

A session on the embedded simulated drive: the receiving, installation and wiring checklists walked
with passing answers, the rotary direction confirmed on its page, a scope plot of a jog captured for
the report, then the report printed to PDF and each page turned into a PNG with pdftoppm. Settings
and data go to a temporary directory, never the user's.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

from shots import OUT, ScreenshotRun, private_folder, reports_show_plausible_paths, users_sim_drive

TMP = private_folder()
CODE = "FHA-25C-50-US250"


def main() -> int:
    run = ScreenshotRun((1366, 740))
    reports_show_plausible_paths()
    window = run.window
    from fha_studio.gui.link import Servo
    from fha_studio.logic.procedures import ProcedureRun, load_procedure
    from tests.procedures.walk import walk

    window.connect_to(users_sim_drive(CODE, paced="0"))
    run.wait_until(lambda: len(window.state.drive_values) >= 14, "the drive's values", 20.0)
    direction = window.show_page("direction")
    direction.answer("cw")  # FWD turned the flange CW, as parameter 8 = 0 says
    scope = window.show_page("scope")
    scope.view.start_live()
    window.link.send(Servo(True))
    run.wait_until(lambda: window.link.servo_on, "servo-ON", 20.0)
    window.link.jog_press(20.0)
    run.settle(2.0)
    window.link.jog_release()
    run.wait_until(lambda: not window.link.moving, "the jog's end", 20.0)
    scope.view.set_paused(True)
    procedures = window.show_page("procedures")
    procedures.new_session(Path(TMP) / "axis1.json", CODE, operator="T. Technician")
    for procedure_id in ("receiving-inspection", "installation", "wiring"):
        walk(ProcedureRun(procedures.session, load_procedure(procedure_id, procedures.context)),
             who="T. Technician")
    procedures.capture_scope_plot("Jog FWD at 20 r/min: output speed and motor current")
    _html, pdf = procedures.write_report(Path(TMP) / "report.html", Path(TMP) / "report.pdf")
    OUT.mkdir(parents=True, exist_ok=True)  # pdftoppm writes into it, it does not make it
    for old in OUT.glob("report-page-*.png"):
        old.unlink()
    subprocess.run(["pdftoppm", "-r", "70", "-png", str(pdf), str(OUT / "report-page")], check=True)
    for page in sorted(OUT.glob("report-page-*.png")):
        number = int(page.stem.rsplit("-", 1)[1])
        page.rename(OUT / f"report-page-{number}.png")
        print("saved", OUT / f"report-page-{number}.png")
    window.link.send(Servo(False))
    run.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
