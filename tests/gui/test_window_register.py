"""The single-axis window records into the register as a machine window's axes do: under this
computer's bench and an axis named after its actuator or connection, or under the machine and
axis a person names (the toolbar's Register line and its dialog, --machine/--axis); the line
always says where; an unusable register is said and the window works on."""

from __future__ import annotations

import pytest

from fha_studio.logic.register import Register
from fha_studio.logic.register.window_axis import default_machine_name
from tests.gui.fit import cut_texts, hidden_actions, laid_out

FULL = "sim://FHA-25C-50-US250?paced=0"
#: As a real HA-655: DGR and OWW only; the drive names no actuator.
DOCUMENTED = "sim://FHA-32C-100-S248?profile=documented&paced=0"
ROTARY_DIRECTION_WRITTEN = "parameter 8 Rotary direction: 0 → 1: FWD turns CCW (reversed), verified"


@pytest.fixture
def make_window(make_cli_window):
    """Factory: make_window(*options) -> the window ``fha-studio OPTIONS`` makes (conftest)."""
    return make_cli_window


def _connect(window, qtbot, url: str) -> None:
    with qtbot.waitSignal(window.link.sigConnected, timeout=30000):
        window.connect_to(url)


def _history(path, axis: str) -> list[str]:
    with Register(path) as register:
        return [e.text for e in register.history(axis)]


def test_the_window_records_under_this_computers_bench_and_the_actuator(make_window, qtbot, tmp_path):
    path = tmp_path / "register.sqlite"
    window = make_window("--register", str(path))
    line = window.window_register.button
    assert line.text() == f"Register: {default_machine_name()} › unnamed axis"
    _connect(window, qtbot, FULL)
    axis = f"{default_machine_name()}/FHA-25C-50-US250 (simulated)"
    assert line.text() == f"Register: {axis.replace('/', ' › ')}"
    assert str(path) in line.toolTip() and "default name" in line.toolTip()
    recorder = window.window_register.recorder
    qtbot.waitUntil(lambda: axis in recorder.recorded_axes(), timeout=30000)
    window.session.write([("system", 8, 1)])
    qtbot.waitUntil(lambda: ROTARY_DIRECTION_WRITTEN in _history(path, axis), timeout=30000)
    history = _history(path, axis)
    assert history[:2] == ["axis added: FHA-25C-50-US250", "driver: not given → HA-655-2-200"]
    assert history[2].startswith("parameters read over the link: 14 values")


def test_a_drive_that_names_no_actuator_keeps_its_axis_when_the_actuator_is_declared(
    make_window, qtbot, tmp_path
):
    """A real HA-655 names no actuator: the axis is named after the connection, and stays so for
    the connection when the technician declares the actuator afterwards (its record says it)."""
    path = tmp_path / "register.sqlite"
    window = make_window("--register", str(path))
    _connect(window, qtbot, DOCUMENTED)
    window.state.enter_front_panel("system", 8, 1, "ana")  # a value read off the front panel
    axis = f"{default_machine_name()}/simulated drive"
    qtbot.waitUntil(lambda: axis in window.window_register.recorder.recorded_axes(), timeout=30000)
    page = window.show_page("connection")
    page.actuator_combo.setCurrentText("FHA-32C-100-S248")
    page.check_pairing()
    assert window.state.actuator_code == "FHA-32C-100-S248"
    assert window.window_register.axis.ref == axis  # not split in two
    window.state.enter_front_panel("tune", 4, 20, "ana")
    history = _history(path, axis)
    assert "axis added" in history
    assert "actuator: not given → FHA-32C-100-S248" in history
    with Register(path) as register:
        assert [(s["source"], s["count"]) for s in register.snapshots(axis)] == [("front_panel", 1)] * 2


def test_the_machine_and_axis_named_on_the_command_line_and_in_the_dialog(make_window, qtbot, tmp_path):
    from fha_studio.gui.window_register import WindowAxisDialog

    path = tmp_path / "register.sqlite"
    with Register(path) as register:  # an axis of a machine the register has
        register.add_machine("Line 3", site="Plant A")
        register.add_axis("Line 3", "tilt", "FHA-32C-100-S248-B", port_url="/dev/ttyUSB1")
    window = make_window("--register", str(path), "--machine", "Line 3", "--axis", "tilt")
    recording = window.window_register
    assert recording.button.text() == "Register: Line 3 › tilt"
    assert "default name" not in recording.button.toolTip()
    window.state.enter_front_panel("system", 8, 0, "ana")
    with Register(path) as register:  # found, not added again; the fact is its
        assert [s["source"] for s in register.snapshots("Line 3/tilt")] == ["front_panel"]
        assert len(register.axes("Line 3")) == 1

    dialog = WindowAxisDialog(recording, window)
    assert dialog.machine_combo.currentText() == "Line 3" and dialog.axis_combo.currentText() == "tilt"
    assert [dialog.axis_combo.itemText(i) for i in range(dialog.axis_combo.count())] == ["tilt"]
    dialog.axis_combo.setCurrentText("bad\tname")
    dialog.accept()
    assert dialog.error_label.text() == "axis name 'bad\\tname' holds characters that are not text " \
        "(line breaks, tabs, terminal escape sequences)"
    assert recording.axis.ref == "Line 3/tilt"  # nothing changed
    dialog.axis_combo.setCurrentText("table")
    dialog.operator_edit.setText("B. Fitter")
    dialog.accept()
    assert dialog.result() == dialog.DialogCode.Accepted
    assert recording.button.text() == "Register: Line 3 › table"
    said = window.message_area.latest().text
    assert said == "Register: from now on recorded as machine Line 3, axis table."
    window.state.enter_front_panel("tune", 4, 20, "ana")
    with Register(path) as register:
        assert register.axis("Line 3/table").actuator_code == ""
        assert [s["who"] for s in register.snapshots("Line 3/tilt")] == ["ana"]
        assert [s["who"] for s in register.snapshots("Line 3/table")] == ["ana"]
        assert [e.who for e in register.history("Line 3/table") if e.text == "axis added"] == ["B. Fitter"]

    # back to the default names; a new dialog offers the axes named before
    dialog = WindowAxisDialog(recording, window)
    assert "Line 3" in [dialog.machine_combo.itemText(i) for i in range(dialog.machine_combo.count())]
    dialog.default_button.click()
    dialog.accept()
    assert recording.axis.ref == f"{default_machine_name()}/unnamed axis"


def test_names_the_register_refuses_are_one_line_before_a_window_opens(qtbot, tmp_path, capsys):
    from fha_studio.gui.app import run

    for options, said in (
        (["--axis", "x\x1b[2J"], "fha-studio: axis name 'x\\x1b[2J' holds characters that are not text"),
        (["--machine", "a/b", "--axis", "c"],
         "fha-studio: machine name 'a/b': '/' separates machine and axis"),
        (["--machine-file", "m.json", "--axis", "c"],
         "fha-studio: --axis names the single-axis window's axis"),
    ):
        with pytest.raises(SystemExit) as exit_info:
            run([*options, "--register", str(tmp_path / "r.sqlite"), "--no-connect"])
        assert exit_info.value.code == 2
        err = capsys.readouterr().err
        assert err.startswith(said) and err.count("\n") == 1, err
    assert not (tmp_path / "r.sqlite").exists()


def test_a_register_that_cannot_be_opened_is_said_and_the_window_works(make_window, qtbot, tmp_path):
    folder = tmp_path / "a-folder"
    folder.mkdir()
    window = make_window("--register", str(folder))
    line = window.window_register.button
    assert line.text() == "Register: not recording"
    assert window.message_area.latest().text.startswith("Register: nothing is recorded: ")
    assert str(folder) in line.toolTip()
    _connect(window, qtbot, FULL)  # the commissioning goes on
    window.state.enter_front_panel("system", 8, 0, "ana")
    assert window.message_area.latest().text.startswith("Register: nothing is recorded: ")


@pytest.mark.parametrize("size", [(1280, 720), (1024, 600)], ids=["1280x720", "1024x600"])
def test_the_register_line_fits_beside_the_toolbar(make_window, qtbot, tmp_path, size):
    window = make_window("--register", str(tmp_path / "r.sqlite"), "--machine",
                         "Line 3 positioner of the north hall, beside the press", "--axis",
                         "FHA-25C-50-US250 tilt of the left-hand fixture")
    window.resize(*size)
    qtbot.waitUntil(lambda: (window.width(), window.height()) == size, timeout=30000)
    window.alarm_banner_action.setVisible(True)
    window.alarm_banner.setText("NEW ALARM 82 — show it")
    laid_out(qtbot, window)
    assert not hidden_actions(window) and not cut_texts(window)
    text = window.window_register.button.text()
    assert text.startswith("Register: ") and "…" in text


def test_a_fact_the_register_refuses_is_said_in_the_axis_message_line(make_window, tmp_path):
    from fha_studio.gui.axis_recorder import AxisRecorder

    path = tmp_path / "line3.sqlite"
    with Register(path) as register:
        register.add_machine("Line 3")
        register.add_axis("Line 3", "tilt")
    window = make_window("--register", str(tmp_path / "r.sqlite"))
    with Register(path, read_only=True) as refusing:
        AxisRecorder(refusing, "Line 3/tilt", window, lambda: "ana")
        window.state.enter_front_panel("system", 8, 1, "ana")
        said = [m.text for m in window.message_area.messages]
        assert said == [f"Register: the front-panel value was not recorded (the register {path} is "
                        "read-only: nothing was changed (it needs write access to the file and its "
                        "folder))."], said
