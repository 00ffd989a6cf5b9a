"""Takes the README's screenshot of the Tuning page on the embedded simulated drive: an
FHA-25C-50 with a load of its own inertia on the gear's spring, measured, the resonance marked,
gains proposed.

    xvfb-run -a -s "-screen 0 1366x768x24" python docs/screenshots/take_tuning.py [OUTDIR]

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
URL = "sim://FHA-25C-50-US250?paced=0&load_inertia=0.81&effects=torsional_compliance"


def main() -> int:
    app = QApplication(sys.argv[:1])
    QCoreApplication.setOrganizationName("FHA Studio Screenshots")
    QCoreApplication.setApplicationName("fha-studio-screenshots")
    from fha_studio.gui.link import Servo
    from fha_studio.gui.main_window import MainWindow

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

    print("connecting", flush=True)
    until(lambda: window.link.connected, 20)
    print("connected", flush=True)
    window.link.send(Servo(True))
    until(lambda: window.link.status is not None and window.link.status.servo_on, 20)
    page = window.show_page("tuning")
    page.load_spin.setValue(0.81)
    page.show_plan()
    until(page.start_button.isEnabled, 30)
    done = []
    page.sigMeasured.connect(done.append)
    print("measuring", flush=True)
    page.measure()
    until(lambda: bool(done), 120)
    proposed = []
    page.sigProposed.connect(proposed.append)
    page.propose()
    until(lambda: bool(proposed), 120)
    app.processEvents()
    path = OUT / "tuning.png"
    window.grab().save(str(path))
    print("saved", path)
    window.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
