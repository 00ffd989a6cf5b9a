"""Takes the README's machine screenshots: the axis list beside the pages, and a machine report.

    xvfb-run -a -s "-screen 0 1366x768x24" python docs/screenshots/take_machine.py [OUTDIR]

A three-axis positioner on three simulated drives (two full, one that speaks only the manual's
DGR and OWW): all connected, the table's rotary direction reversed and its receiving inspection
walked, the twin's parameters on show. The register, settings and data go to a temporary
directory, never the user's.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

from shots import OUT, ScreenshotRun, private_folder, reports_show_plausible_paths

TMP = Path(private_folder())


def main() -> int:
    reports_show_plausible_paths()
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
    run = ScreenshotRun((1366, 740), make_window=lambda: MachineWindow(project, register))
    window, wait_until, settle, shot = run.window, run.wait_until, run.settle, run.shot
    from PySide6.QtGui import QColor, QImage, QPainter

    window.operator_edit.setText("A. Technician")
    window.connect_all()
    wait_until(lambda: all(w.link.connected for w in window.axis_windows), "every axis connected")
    table, twin, _ = window.axis_windows
    wait_until(lambda: len(table.state.drive_values) >= 14 and len(twin.state.drive_values) >= 14,
               "the two full drives' values")
    table.session.write([("system", 8, 1)])
    wait_until(lambda: any(e.kind == "write" for e in register.history("Line 3 positioner/table")),
               "the table's write in the register")
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
    wait_until(lambda: dgr.origin_button.isEnabled(), "the tilt's OWW button")
    dgr.origin_button.click()
    wait_until(lambda: bool(dgr.records), "the tilt's origin recorded")

    window.select_axis("table twin")
    twin.show_page("parameters")
    settle(0.8)
    shot("machine-axes")

    window.select_axis("table")
    dialog = window.show_register()
    dialog.tabs.setCurrentIndex(1)  # compare: the table against its twin
    settle(0.5)
    shot("machine-register", dialog)
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
    run.close()
    register.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
