"""The Procedures page's sign step with the signer's own key: the HTML carries the signature,
the PDF is found in the register by its hash; both verify, and a changed byte fails."""

from __future__ import annotations

import json
import shutil
import subprocess

from fha_studio.cli import main
from fha_studio.logic.procedures import ProcedureRun, ProcedureSession, load_procedure
from fha_studio.logic.procedures.context import build_context
from fha_studio.logic.register import default_register_path
from tests.procedures.walk import walk

CODE = "FHA-25C-50-US250-B-L"
ALL = ["receiving-inspection", "installation", "wiring", "sensor-adjustment", "rotary-direction"]


def _finished_session(path):
    session = ProcedureSession(actuator_code=CODE, operator="A. Reviewer", site="Line 3")
    session.driver = {"model": "HA-655-2-200", "adjusted_for": CODE, "version": "sim 1"}
    session.save(path)
    context = build_context(CODE)
    for procedure_id in ALL:
        walk(ProcedureRun(session, load_procedure(procedure_id, context)))


def _verify(path, capsys):
    capsys.readouterr()
    code = main(["register", "verify", str(path), "--json"])
    return code, json.loads(capsys.readouterr().out)


def test_the_page_signs_with_the_key_and_both_files_verify(make_window, tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("FHA_STUDIO_KEY_PASSPHRASE", "shop floor")
    assert main(["register", "keys", "add", "--name", "A. Reviewer"]) == 0  # the default register
    assert default_register_path().is_file()
    monkeypatch.delenv("FHA_STUDIO_KEY_PASSPHRASE")
    _finished_session(tmp_path / "axis1.json")
    window = make_window()  # no drive: the report is made from the session file
    page = window.show_page("procedures")
    page.open_session(tmp_path / "axis1.json")
    assert not page.sign("A. Reviewer", passphrase="wrong")
    assert "wrong passphrase" in page.message_label.text()
    assert "key_id" not in ProcedureSession.load(tmp_path / "axis1.json").signature
    assert page.sign("A. Reviewer", passphrase="shop floor"), page.message_label.text()
    assert "with key" in page.message_label.text()
    html, pdf = page.write_report(tmp_path / "report.html", tmp_path / "report.pdf")
    assert "fha-studio register verify REPORT" in html.read_text()
    if shutil.which("pdftotext") is not None:  # the PDF says it too (scripts/test installs it)
        text = subprocess.run(["pdftotext", str(pdf), "-"], capture_output=True, text=True, check=True,
                              timeout=60).stdout
        assert "fha-studio register verify REPORT" in " ".join(text.split())
    for path in (html, pdf):
        code, verdict = _verify(path, capsys)
        assert code == 0 and verdict["signer"] == "A. Reviewer", verdict
    data = bytearray(pdf.read_bytes())
    data[len(data) // 2] ^= 0x20
    pdf.write_bytes(bytes(data))
    code, verdict = _verify(pdf, capsys)
    assert code == 5 and "no signature" in verdict["reason"]


def test_an_axis_of_a_machine_signs_with_a_key_of_the_machine_windows_register(qtbot, tmp_path, monkeypatch):
    from fha_studio.gui.machine_window import MachineWindow
    from fha_studio.logic.machine import MachineProject
    from fha_studio.logic.register import Register
    from tests.support.windows import torn_down

    plant = tmp_path / "plant.sqlite"  # not the user's register: the machine window's
    monkeypatch.setenv("FHA_STUDIO_KEY_PASSPHRASE", "")
    assert main(["register", "--register", str(plant), "keys", "add", "--name", "A. Reviewer"]) == 0
    project = MachineProject("Line 3", site="Plant A")
    project.add_axis("table", CODE, port_url=f"sim://{CODE}?paced=0")
    _finished_session(tmp_path / "axis1.json")
    register = Register(plant)
    with torn_down(lambda window: [axis.link for axis in window.axis_windows]) as windows:
        window = MachineWindow(project, register)
        windows.append(window)
        window.show()
        page = window.axis_windows[0].show_page("procedures")
        page.open_session(tmp_path / "axis1.json")
        assert page.sign("A. Reviewer"), page.message_label.text()  # a key without a passphrase
        assert "with key" in page.message_label.text()
        html, _pdf = page.write_report(tmp_path / "report.html")
    register.close()
    assert main(["register", "--register", str(plant), "verify", str(html)]) == 0
