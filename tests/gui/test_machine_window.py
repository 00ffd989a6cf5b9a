"""A machine of three axes on three simulated drives (two full, one that speaks only the manual's
DGR and OWW): the axis list beside the pages, every page switching with the chosen axis, the
banner naming it, STOP reaching every axis that can be stopped, and the register filled as the
axes are commissioned (history, a diff against the twin, a find)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from fha_studio.gui.link import ClearAlarm, Servo, Stop
from fha_studio.logic.machine import MachineProject
from fha_studio.logic.register import Register
from fha_studio.logic.register.words import value_text
from tests.gui.procedure_answers import answer_by_hand
from tests.support.read_only import ReadOnlyPlace
from tests.support.windows import torn_down

MACHINE = "Line 3 positioner"
TABLE = "FHA-25C-50-US250"
TILT = "FHA-32C-100-S248-B"
#: The rotary direction's write, as the register's history says it.
WRITTEN = "parameter 8 Rotary direction: 0 → 1: FWD turns CCW (reversed), verified"


@pytest.fixture
def make_machine(qtbot):
    """Factory: make_machine(project, register) -> a shown MachineWindow; torn down like
    make_window (every link thread ended, no window left open)."""
    from fha_studio.gui.machine_window import MachineWindow

    def factory(project, register):
        window = MachineWindow(project, register)
        window.show()
        windows.append(window)
        return window

    with torn_down(lambda window: [axis.link for axis in window.axis_windows]) as windows:
        yield factory


def _walk(page, qtbot, procedure_id, limit=80):
    """Answers a procedure's steps as a technician would on the page."""
    page.select_procedure(procedure_id)
    for _ in range(limit):
        step = page.current_step()
        if step is None or page.run.stopped:
            return
        if not answer_by_hand(page, step):
            with qtbot.waitSignal(page.sigLiveDone, timeout=20000):
                page.live_button.click()
    raise AssertionError("procedure did not end")


def _project(tmp_path) -> MachineProject:
    project = MachineProject(MACHINE, site="Plant A, hall 2")
    for name in ("table", "table twin"):
        eeprom = tmp_path / f"{name.replace(' ', '-')}.eeprom.json"
        project.add_axis(
            name, TABLE, port_url=f"sim://{TABLE}?paced=0&eeprom={eeprom}", load_inertia_kgm2=1.5
        )
    eeprom = tmp_path / "tilt.eeprom.json"
    project.add_axis(
        "tilt",
        TILT,
        port_url=f"sim://{TILT}?profile=documented&paced=0&oww_clear_s=0.5&eeprom={eeprom}",
        load_inertia_kgm2=4.0,
    )
    return project


def test_a_three_axis_machine_is_commissioned_into_the_register(make_machine, qtbot, tmp_path):
    register = Register(tmp_path / "register.sqlite")
    window = make_machine(_project(tmp_path), register)
    window.operator_edit.setText("ana")
    assert window.axis_list.count() == 3
    assert window.connect_all() == ["table", "table twin", "tilt"]
    qtbot.waitUntil(lambda: all(w.link.connected for w in window.axis_windows), timeout=15000)
    table, twin, tilt = window.axis_windows
    assert not tilt.link.info.can_parameters and not tilt.link.info.can_move
    # each full drive's parameters are read on connecting: a snapshot per axis, over the link
    qtbot.waitUntil(
        lambda: all(register.snapshots(f"{MACHINE}/{n}") for n in ("table", "table twin")), timeout=15000
    )
    assert register.snapshots(f"{MACHINE}/tilt") == []
    assert register.snapshots(f"{MACHINE}/table")[0]["who"] == "ana"

    # the pages act on the chosen axis, and the banner says which
    assert window.select_axis("table") is table and window.current_window is table
    assert window.banner.text().startswith(f"Axis table — {TABLE} on HA-655")
    # the embedded drive in words, its address (with its EEPROM file's path) in the tooltip
    banner = window.banner.text()
    assert " — embedded simulated drive — connected" in banner and "sim://" not in banner
    assert window.banner.toolTip().startswith(f"Port: sim://{TABLE}?")
    table.show_page("parameters")
    window.select_axis("tilt")
    assert window.current_window is tilt and tilt.tabs.currentIndex() == table.tabs.currentIndex()
    assert window.banner.text().startswith(f"Axis tilt — {TILT}")
    assert "axis tilt" in window.windowTitle()

    # commission the table: rotary direction reversed (backed up, written, verified), procedures
    window.select_axis("table")
    table.session.write([("system", 8, 1)])
    twin.session.write([("tune", 4, 20)])  # the twin's in-position range, written from its pages
    for axis in ("table", "table twin"):
        qtbot.waitUntil(
            lambda axis=axis: any(e.kind == "write" for e in register.history(f"{MACHINE}/{axis}")),
            timeout=15000,
        )
    page = table.show_page("procedures")
    page.operator_edit.setText("ana")
    page.new_session(tmp_path / "table.fha-session.json")
    _walk(page, qtbot, "receiving-inspection")
    page.write_report(tmp_path / "table-report.html", tmp_path / "table-report.pdf")

    # the register: history, diff against the twin, find
    history = register.history(f"{MACHINE}/table")
    writes = [e for e in history if e.kind == "write"]
    assert [w.text for w in writes] == [WRITTEN]
    assert writes[0].who == "ana"
    checks = [e for e in history if e.kind == "check"]
    assert len(checks) >= 5 and all("pass" in c.text for c in checks)
    assert {r["procedure_id"]: r["status"] for r in register.procedure_status(f"{MACHINE}/table")}[
        "receiving-inspection"
    ] == "completed"
    reports = [e for e in history if e.kind == "report"]
    assert reports and reports[-1].data["file"].endswith("table-report.pdf")
    assert [e.at_utc for e in history] == sorted(e.at_utc for e in history)
    diff = Register.diff(
        register.parameter_set(f"{MACHINE}/table"), register.parameter_set(f"{MACHINE}/table twin")
    )
    assert {d.key: (d.a, d.b) for d in diff} == {"rotary_direction": (1, 0), "in_position_range": (10, 20)}
    assert [f.axis.name for f in register.find("rotary_direction", 1)] == ["table"]
    assert [f.axis.name for f in register.find("in_position_range", 20)] == ["table twin"]
    open_items = {(i.axis.name, i.text) for i in register.open_items(MACHINE)}
    assert ("table", f"report {tmp_path / 'table-report.pdf'} is not signed") in open_items
    assert ("tilt", "no procedure recorded yet") in open_items

    # the tilt's drive has no parameter access: its values are read off the front panel
    tilt.state.enter_front_panel("system", 8, 0, "ana")
    panel = register.snapshots(f"{MACHINE}/tilt")
    assert [(s["source"], s["who"], s["count"]) for s in panel] == [("front_panel", "ana", 1)]
    assert [f.axis.name for f in register.find("rotary_direction", 0)] == ["table twin", "tilt"]

    # the same questions in the GUI, on the axis on show
    dialog = window.show_register()
    history = [dialog.history_table.item(r, 3).text() for r in range(dialog.history_table.rowCount())]
    assert WRITTEN in history
    assert dialog.compare_a.currentText() == "table: latest known values"
    assert dialog.compare_b.currentText() == "table twin: latest known values"  # its twin
    compared = {
        dialog.compare_table.item(r, 0).text(): (
            dialog.compare_table.item(r, 1).text(),
            dialog.compare_table.item(r, 2).text(),
        )
        for r in range(dialog.compare_table.rowCount())
    }
    assert compared == {
        "parameter 8 Rotary direction": (
            value_text("rotary_direction", 1),
            value_text("rotary_direction", 0),
        ),
        "tune 4 In-position range": ("10 pulse", "20 pulse"),
    }
    dialog.tabs.setCurrentIndex(2)
    dialog.find_parameter.setCurrentIndex(dialog.find_parameter.findData("rotary_direction"))
    dialog.find_value.setCurrentIndex(dialog.find_value.findData(1))
    dialog.find_button.click()
    assert [dialog.find_table.item(r, 0).text() for r in range(dialog.find_table.rowCount())] == ["table"]
    opened = {dialog.open_table.item(r, 2).text() for r in range(dialog.open_table.rowCount())}
    assert "no procedure recorded yet" in opened

    # STOP reaches every axis that can be stopped: both tables, not the documented-only tilt
    for w in (table, twin):
        w.link.send(Servo(True))
    qtbot.waitUntil(lambda: table.link.servo_on and twin.link.servo_on, timeout=10000)
    with qtbot.waitSignals(
        [table.link.sigResult, twin.link.sigResult],
        timeout=10000,
        check_params_cbs=[lambda r: r.answers(Stop)] * 2,
    ):
        twin.stop_button.click()  # the STOP of any axis's pages is the machine's STOP
    said = [m.text for m in twin.message_area.messages if m.text.startswith("STOP sent")]
    assert said[-1] == (
        "STOP sent to table, table twin: each decelerates and holds (servo stays on); "
        "tilt: no STOP over the link, the controller stops it."
    )
    assert window.stop_all() == ["table", "table twin"]
    with qtbot.waitSignals(
        [table.link.sigResult, twin.link.sigResult],
        timeout=10000,
        check_params_cbs=[lambda r: r.answers(Stop)] * 2,
    ):
        twin.show_page("scope").jog_panel.stop_button.click()  # the scope's Move panel: the same STOP

    # the tilt's absolute origin, set with OWW on its DGR checks page, is the axis's origin
    window.select_axis("tilt")
    dgr = tilt.show_page("absolute")
    dgr.who_edit.setText("ana")
    qtbot.waitUntil(lambda: dgr.origin_button.isEnabled(), timeout=10000)
    before = len(dgr.records)
    dgr.origin_button.click()
    qtbot.waitUntil(lambda: len(dgr.records) > before, timeout=15000)
    origin = register.latest_origin(f"{MACHINE}/tilt")
    assert origin["text"].startswith("absolute origin set (OWW), read back at") and origin["who"] == "ana"
    assert [e.text.split(": ")[:2] for e in register.history(f"{MACHINE}/tilt") if e.kind == "check"] == [
        ["DGR checks", "Absolute origin (OWW)"]
    ]

    # the machine report: every axis in the summary, then each axis's report
    html, pdf = window.write_machine_report(tmp_path / "machine.html", tmp_path / "machine.pdf")
    text = html.read_text(encoding="utf-8")
    summary = text[: text.index("Axis table</h1>")]
    assert "1: FWD command → REV rotation" in summary  # the table, reversed
    assert "0: FWD command → FWD rotation (default)" in summary  # the twin
    assert TILT in summary and "not signed" in summary
    assert "absolute origin set (OWW), read back at" in summary
    assert pdf.is_file() and pdf.stat().st_size > 1000
    if shutil.which("pdftotext") is not None:  # each axis's report starts a page of its own
        text = subprocess.run(["pdftotext", str(pdf), "-"], capture_output=True, text=True, check=True).stdout
        firsts = [page.strip().splitlines()[0] for page in text.split("\f") if page.strip()]
        assert firsts[0] == f"Machine report — {MACHINE}"
        assert [f for f in firsts if f.startswith("Axis ")] == ["Axis table", "Axis table twin", "Axis tilt"]
    assert register.export(MACHINE)["machines"][0]["machine_reports"][0]["file"] == str(pdf.resolve())
    register.close()


def test_a_refused_machine_file_leaves_no_register_behind(qtbot, tmp_path, capsys):
    from fha_studio.gui.app import run

    for name, content, message in (
        ("axes-5.json", '{"format": "fha-machine/1", "name": "Press 9", "axes": 5}',
         "field axes: must be a list of axes, got the number 5"),
        ("inertia.json", '{"format": "fha-machine/1", "name": "Press 9", "axes": [{"name": "feed", '
         '"load_inertia_kgm2": 1e308}]}', "axis 1: field load_inertia_kgm2: 1e+308 is outside"),
    ):
        machine_file = tmp_path / name
        machine_file.write_text(content)
        with pytest.raises(SystemExit) as exit_info:
            run(["--machine-file", str(machine_file), "--register", str(tmp_path / "new.sqlite"),
                 "--no-connect"])
        assert exit_info.value.code == 2
        err = capsys.readouterr().err
        assert err.startswith(f"fha-studio: {machine_file}: {message}") and err.count("\n") == 1
        assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
            p.name for p in tmp_path.iterdir() if p.suffix == ".json")  # no new.sqlite made


def test_the_gui_opens_a_machine_of_the_register_or_says_why_not(qtbot, tmp_path, capsys):
    from fha_studio.gui.app import run

    path = tmp_path / "plant.sqlite"
    with pytest.raises(SystemExit):
        run(["--machine", "Press 7", "--register", str(path), "--no-connect"])
    assert capsys.readouterr().err == f"fha-studio: there is no register at {path}\n"
    with Register(path) as register:
        register.add_machine("Press 7")
    for args, message in (
        (["--machine", "Nope"], "fha-studio: no machine called 'Nope' in the register (machines: Press 7)\n"),
        (
            ["--machine", "Press 7"],
            "fha-studio: machine 'Press 7' has no axes (fha-studio register add-axis ...)\n",
        ),
        (
            ["--machine-file", str(tmp_path / "none.json")],
            f"fha-studio: {tmp_path / 'none.json'}: no such machine file\n",
        ),
    ):
        with pytest.raises(SystemExit) as exit_info:
            run([*args, "--register", str(path), "--no-connect"])
        assert exit_info.value.code == 2
        assert capsys.readouterr().err == message
    with Register(path) as register:
        register.add_axis("Press 7", "feed", "FHA-17C-50-US250", port_url="sim://FHA-17C-50-US250?paced=0")
    assert (
        run(["--machine", "Press 7", "--register", str(path), "--no-connect", "--quit-after-ms", "200"]) == 0
    )


def test_the_gui_and_the_command_line_open_the_same_register(qtbot, tmp_path, monkeypatch, capsys):
    """One rule: --register FILE (the same option for both), else $FHA_STUDIO_REGISTER, else the user
    data directory's register.sqlite; a GUI setting of old (register/path) does not make it differ."""
    from PySide6.QtCore import QSettings

    from fha_studio.cli import main as cli_main
    from fha_studio.gui.app import run
    from fha_studio.logic.register.guard import shown_path
    from fha_studio.paths import user_data_dir

    QSettings().setValue("register/path", str(tmp_path / "setting.sqlite"))
    monkeypatch.chdir(tmp_path)  # short relative paths: the refusals show them whole
    monkeypatch.setenv("XDG_DATA_HOME", "data")

    def opened(option: list[str]) -> tuple[str, str]:
        """The file each one looked for (none is there, so each says which)."""
        assert cli_main(["register", *option, "machines"]) == 2
        said_by_cli = capsys.readouterr().err
        with pytest.raises(SystemExit):
            run(["--machine", "Press 7", *option, "--no-connect"])
        said_by_gui = capsys.readouterr().err
        return (said_by_cli.split("there is no register at ")[1].split(" (start one")[0],
                said_by_gui.removeprefix("fha-studio: there is no register at ").rstrip("\n"))

    default = user_data_dir() / "register.sqlite"
    assert default == Path("data/FHA Studio/fha-studio/register.sqlite")
    assert opened([]) == (shown_path(default),) * 2
    monkeypatch.setenv("FHA_STUDIO_REGISTER", "site.sqlite")
    assert opened([]) == (shown_path(Path("site.sqlite")),) * 2
    assert opened(["--register", "chosen.sqlite"]) == (shown_path(Path("chosen.sqlite")),) * 2
    # the register command's old name of the option still works, and says its new name
    assert cli_main(["register", "--db", "chosen.sqlite", "machines"]) == 2
    assert capsys.readouterr().err.startswith("fha-studio register: note: --db is now called --register\n")


@pytest.mark.slow
def test_alarms_recordings_and_model_checks_go_into_the_register(make_machine, qtbot, tmp_path):
    from tests.gui.test_modelcheck_page import URL, capture_a_move

    register = Register(tmp_path / "register.sqlite")
    project = MachineProject("Press 7")
    project.add_axis("feed", TABLE, port_url=URL, load_inertia_kgm2=0.5)
    window = make_machine(project, register)
    window.operator_edit.setText("ben")
    window.connect_all()
    feed = window.axis_windows[0]
    qtbot.waitUntil(lambda: feed.link.connected, timeout=15000)
    ref = "Press 7/feed"

    # an alarm on the drive
    feed.link._worker._client.transaction.transport.inner.sim_drive.raise_alarm(20)
    qtbot.waitUntil(lambda: any(e.kind == "alarm" for e in register.history(ref)), timeout=15000)
    alarm = next(e for e in register.history(ref) if e.kind == "alarm")
    assert alarm.text.startswith("alarm 20: ") and alarm.who == "ben"
    feed.link.send(ClearAlarm())
    qtbot.waitUntil(lambda: feed.link.status is not None and feed.link.status.alarm_code == 0, timeout=15000)

    # a move captured in the scope, handed to the model check
    capture_a_move(feed, qtbot)
    page = feed.show_page("modelcheck")
    path = page.take_scope_capture()
    recordings = [e for e in register.history(ref) if e.kind == "recording"]
    assert [e.data["file"] for e in recordings] == [str(path.resolve())]
    with qtbot.waitSignal(page.sigFinished, timeout=60000):
        page.run_button.click()
    checks = [e for e in register.history(ref) if e.kind == "model_check"]
    assert len(checks) == 1 and "Coulomb friction" in checks[0].text and checks[0].who == "ben"
    assert checks[0].data["recording_file"] == str(path)
    register.close()


def test_an_axis_added_in_the_window_gets_its_pages_and_goes_into_the_register(make_machine, qtbot, tmp_path):
    from fha_studio.catalog import ModelCodeError
    from fha_studio.gui.machine_window import AxisDialog
    from fha_studio.logic.machine import MachineError

    register = Register(tmp_path / "register.sqlite")
    project = MachineProject("Wrist")
    project.add_axis("pitch", TABLE, port_url=f"sim://{TABLE}?paced=0")
    window = make_machine(project, register)
    dialog = AxisDialog(window)
    dialog.name_edit.setText(" roll ")
    dialog.actuator_edit.setText("FHA-17C-50-US250")
    dialog.port_edit.setText("sim://FHA-17C-50-US250?paced=0")
    dialog.inertia_spin.setValue(0.25)
    values = dialog.values()
    assert (values["name"], values["load_inertia_kgm2"]) == ("roll", 0.25)
    dialog.deleteLater()
    roll = window.add_axis(**values)
    assert window.current_window is roll and window.axis_list.count() == 2
    assert window.banner.text().startswith("Axis roll — FHA-17C-50-US250")
    assert register.axis("Wrist/roll").load_inertia_kgm2 == 0.25
    assert window.connect_all() == ["pitch", "roll"]
    qtbot.waitUntil(lambda: roll.link.connected, timeout=15000)
    assert roll.link is not window.axis_window("pitch").link  # a link of its own
    with pytest.raises(ModelCodeError):
        window.add_axis("yaw", "FHA-18C-50-US250")
    with pytest.raises(MachineError, match="already has an axis called 'roll'"):
        window.add_axis("roll", "FHA-17C-50-US250")
    assert window.axis_list.count() == 2 and [a.name for a in register.axes("Wrist")] == ["pitch", "roll"]
    register.close()


def test_closing_with_a_servo_on_asks_and_cancel_keeps_every_link(make_machine, qtbot, tmp_path, monkeypatch):
    from PySide6.QtWidgets import QMessageBox

    project = MachineProject("Cell 4")
    project.add_axis("x", TABLE, port_url=f"sim://{TABLE}?paced=0")
    project.add_axis("y", TABLE, port_url=f"sim://{TABLE}?paced=0")
    window = make_machine(project, None)
    window.connect_all()
    x, y = window.axis_windows
    qtbot.waitUntil(lambda: x.link.connected and y.link.connected, timeout=15000)
    y.link.send(Servo(True))
    qtbot.waitUntil(lambda: y.link.servo_on, timeout=10000)
    asked = []

    def answer(parent, title, text, buttons, default):
        asked.append(text)
        return QMessageBox.StandardButton.Cancel

    monkeypatch.setattr(QMessageBox, "warning", answer)
    assert not window.close()
    assert asked and "The servo is on at y." in asked[0]
    assert window.isVisible() and x.link.connected and y.link.connected
    monkeypatch.setattr(QMessageBox, "warning", lambda *args: QMessageBox.StandardButton.Ok)
    assert window.close()
    assert not x.link._thread.isRunning() and not y.link._thread.isRunning()


#: The machine window on a register, as the program shows it: built, shown, its message read,
#: closed (run as a user that cannot write the register: see tests/support/read_only.py).
MACHINE_WINDOW_ON = """
import sys
from PySide6.QtWidgets import QApplication
from fha_studio.gui.machine_window import MachineWindow
from fha_studio.logic.machine import MachineProject
from fha_studio.logic.register import Register

app = QApplication([])
project = MachineProject("Press 9")
project.add_axis("feed", "FHA-17C-50-US250", port_url="sim://FHA-17C-50-US250?paced=0")
window = MachineWindow(project, Register(sys.argv[1]))
window.show()
print(window.current_window.message_area.text_label.text())
window._closing_confirmed = True
window.shutdown()
window.register.close()
window.close()
"""


def _register_the_program_cannot_write(place):
    path = place.folder / "plant.sqlite"
    with Register(path) as register:
        register.add_machine("Press 7")
    place.seal()
    return path, path.read_bytes()


def test_a_read_only_register_is_a_message_in_the_machine_window():
    with ReadOnlyPlace() as place:
        path, before = _register_the_program_cannot_write(place)
        done = place.run("-c", MACHINE_WINDOW_ON, str(path))
        assert done.returncode == 0, done.stderr
        assert "Traceback" not in done.stderr
        assert done.stdout.rstrip("\n").endswith(
            f"  Register: the machine was not recorded (the register {path} is read-only: nothing "
            "was changed (it needs write access to the file and its folder)).")
        assert path.read_bytes() == before
        assert sorted(p.name for p in place.folder.iterdir()) == ["plant.sqlite"]


def test_the_gui_on_a_read_only_register_opens_a_new_machine_file():
    with ReadOnlyPlace() as place:
        path, before = _register_the_program_cannot_write(place)
        project = MachineProject("Press 9")
        project.add_axis("feed", "FHA-17C-50-US250", port_url="sim://FHA-17C-50-US250?paced=0")
        machine_file = project.save(place.folder / "press9.json")
        place.seal()
        done = place.run("-m", "fha_studio", "gui", "--machine-file", str(machine_file), "--register",
                         str(path), "--no-connect", "--quit-after-ms", "200")
        assert done.returncode == 0, done.stderr  # it aborted (134) with the thread running
        assert "Traceback" not in done.stderr and "QThread: Destroyed" not in done.stderr
        assert path.read_bytes() == before
