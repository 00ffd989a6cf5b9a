"""Takes the README's screenshot of the Tuning page on a drive of the manual's commands (the
documented profile: CN3 silent while the servo is on), tuned from the bench: the excitation file
written, played into the simulated drive's SPD-CMD in speed mode (an FHA-25C-50 with a load of its
own inertia on the gear's spring), the capture of CN2 analysed, gains proposed for the worksheet.

    xvfb-run -a -s "-screen 0 1366x768x24" python docs/screenshots/take_tuning_bench.py [OUTDIR]

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

from PySide6.QtCore import QCoreApplication  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "screenshots"
CODE = "FHA-25C-50-US250"
URL = f"sim://{CODE}?paced=0&profile=documented"
LOAD = 0.81


def main() -> int:
    app = QApplication(sys.argv[:1])
    QCoreApplication.setOrganizationName("FHA Studio Screenshots")
    QCoreApplication.setApplicationName("fha-studio-screenshots")
    from fha_studio.gui.main_window import MainWindow
    from fha_studio.hardware.sim.cn2 import record_playback
    from fha_studio.hardware.sim.drive import SimDrive

    window = MainWindow()
    window.resize(int(os.environ.get("FHA_SHOT_WIDTH", 1366)), int(os.environ.get("FHA_SHOT_HEIGHT", 740)))
    window.show()
    window.connect_to(URL)

    def until(condition, seconds: float) -> None:
        end = time.monotonic() + seconds
        while not condition():
            if time.monotonic() > end:
                raise SystemExit("the Tuning page did not get there in time")
            app.processEvents()
            time.sleep(0.02)

    until(lambda: window.link.connected, 20)
    page = window.show_page("tuning")
    page.actuator_edit.setText(CODE)
    page.load_spin.setValue(LOAD)
    window.session.state.enter_front_panel("system", 0, 1, "T. Technician")  # speed mode, from the panel
    bench = page.bench
    excitation = bench.write_excitation(f"{TMP}/excitation.csv")
    print("playing the excitation on the simulated bench", flush=True)
    with SimDrive(CODE, load_inertia_kgm2=LOAD, effects={"torsional_compliance": {}},
                  preset=(("system", 0, 1),)) as drive:
        drive.set_servo(True)
        drive.advance(0.05)
        capture = record_playback(drive, excitation, 25000.0).write(f"{TMP}/capture.sr", "sr")
    bench.load_capture(str(capture))
    analysed: list[object] = []
    bench.sigAnalysed.connect(analysed.append)
    bench.analyse()
    until(lambda: bool(analysed), 120)
    proposed: list[object] = []
    page.sigProposed.connect(proposed.append)
    page.propose()
    until(lambda: bool(proposed), 120)
    app.processEvents()
    path = OUT / "tuning-bench.png"
    window.grab().save(str(path))
    print("saved", path)
    window.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
