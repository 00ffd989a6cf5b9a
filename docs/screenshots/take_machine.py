"""Takes the README's machine screenshots: the axis list beside the pages, and a machine report.

    xvfb-run -a -s "-screen 0 1366x768x24" python docs/screenshots/take_machine.py [OUTDIR]

A three-axis positioner on three simulated drives (two full, one that speaks only the manual's
DGR and OWW): all connected, the table's rotary direction reversed and its receiving inspection
walked, the twin's parameters on show. The register, settings and data go to a temporary
directory, never the user's.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
TMP = Path(tempfile.mkdtemp(prefix="fha-machine-shots-"))
os.environ["XDG_CONFIG_HOME"] = str(TMP / "config")
os.environ["XDG_DATA_HOME"] = str(TMP / "data")
os.environ.pop("FHA_STUDIO_REGISTER", None)

from PySide6.QtCore import QCoreApplication, QEventLoop, QTimer  # noqa: E402
from PySide6.QtGui import QColor, QImage, QPainter  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "screenshots"


def settle(ms: int) -> None:
    """Runs the event loop for ``ms`` milliseconds."""
    loop = QEventLoop()
    QTimer.singleShot(ms, loop.quit)
    loop.exec()


def wait_until(condition, timeout_s: float = 20.0) -> None:
    left_ms = int(timeout_s * 1000)
    while not condition():
        if left_ms <= 0:
            raise TimeoutError("the GUI did not get there in time")
        settle(50)
        left_ms -= 50


def main() -> int:
    app = QApplication(sys.argv[:1])  # noqa: F841 - kept alive for the whole run
    QCoreApplication.setOrganizationName("FHA Studio Screenshots")
    QCoreApplication.setApplicationName("fha-studio-screenshots")
    from fha_studio.gui.machine_window import MachineWindow
    from fha_studio.logic.machine import MachineProject
    from fha_studio.logic.register import Register
    from tests.procedures.walk import good_answer

    project = MachineProject("Line 3 positioner", site="Plant A, hall 2")
    project.add_axis(
        "table", "FHA-25C-50-US250", port_url="sim://FHA-25C-50-US250?paced=0", load_inertia_kgm2=1.5
    )
    project.add_axis(
        "table twin", "FHA-25C-50-US250", port_url="sim://FHA-25C-50-US250?paced=0", load_inertia_kgm2=1.5
    )
    tilt = "sim://FHA-32C-100-S248-B?paced=0&profile=documented&oww_clear_s=1"
    project.add_axis("tilt", "FHA-32C-100-S248-B", port_url=tilt, load_inertia_kgm2=4.0)
    register = Register(TMP / "register.sqlite")
    window = MachineWindow(project, register)
    window.operator_edit.setText("A. Technician")
    window.resize(1366, 740)
    window.show()
    window.connect_all()
    wait_until(lambda: all(w.link.connected for w in window.axis_windows))
    table, twin, _ = window.axis_windows
    wait_until(lambda: len(table.state.drive_values) >= 14 and len(twin.state.drive_values) >= 14)
    table.session.write([("system", 8, 1)])
    wait_until(lambda: any(e.kind == "write" for e in register.history("Line 3 positioner/table")))
    page = table.show_page("procedures")
    page.operator_edit.setText("A. Technician")
    page.new_session(TMP / "table.fha-session.json")
    page.select_procedure("receiving-inspection")
    while (step := page.current_step()) is not None and not page.run.stopped:
        page.answer(good_answer(step))
    page.write_report(TMP / "table.html", TMP / "table.pdf")

    # the tilt's drive speaks only DGR and OWW: its direction read off the front panel, its
    # absolute origin set with OWW on the DGR checks page
    tilt_window = window.axis_windows[2]
    tilt_window.state.enter_front_panel("system", 8, 0, "A. Technician")
    dgr = tilt_window.show_page("absolute")
    dgr.who_edit.setText("A. Technician")
    wait_until(lambda: dgr.origin_button.isEnabled())
    dgr.origin_button.click()
    wait_until(lambda: bool(dgr.records))

    window.select_axis("table twin")
    twin.show_page("parameters")
    settle(800)
    OUT.mkdir(parents=True, exist_ok=True)
    path = OUT / "machine-axes.png"
    window.grab().save(str(path))
    print("saved", path)

    window.select_axis("table")
    dialog = window.show_register()
    dialog.tabs.setCurrentIndex(1)  # compare: the table against its twin
    settle(500)
    path = OUT / "machine-register.png"
    dialog.grab().save(str(path))
    print("saved", path)
    dialog.close()

    _html, pdf = window.write_machine_report(TMP / "machine.html", TMP / "machine.pdf")
    # the PDF's first two pages (the summary, the first axis's report) side by side, as the
    # person receiving it sees them
    first_pages = ["pdftoppm", "-png", "-r", "90", "-f", "1", "-l", "2", str(pdf), str(TMP / "page")]
    subprocess.run(first_pages, check=True)
    pages = [QImage(str(p)) for p in sorted(TMP.glob("page*.png"))]
    sheet = QImage(
        sum(p.width() for p in pages) + 30 * (len(pages) + 1),
        pages[0].height() + 60,
        QImage.Format.Format_RGB32,
    )
    sheet.fill(QColor("#808080"))
    painter = QPainter(sheet)
    x = 30
    for p in pages:
        painter.drawImage(x, 30, p)
        x += p.width() + 30
    painter.end()
    target = OUT / "machine-report.png"
    sheet.save(str(target))
    print("saved", target)
    window.shutdown()
    window.close()
    register.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
