"""The screenshot scripts run the real windows: they take one set-up (docs/screenshots/shots.py),
which keeps the user's settings and data out of them (the tests' rule, tests/gui/conftest.py) and
removes its temporary folder when a script ends, also when it fails or is killed; none may wait
for ever."""

from __future__ import annotations

import ast
import importlib.util
import inspect
import json
import os
import signal
import tempfile
from pathlib import Path

import pytest

from tests.support.processes import Child

ROOT = Path(__file__).resolve().parents[2]
SHOTS = ROOT / "docs" / "screenshots"
SCRIPTS = sorted(SHOTS.glob("take*.py"))
#: What shots.py does for every script, and no script does on its own.
OWN_SET_UP = ("mkdtemp", "TemporaryDirectory", "QApplication(", "XDG_CONFIG_HOME", "XDG_DATA_HOME",
              "setOrganizationName")


def _first_line_importing(tree: ast.Module, prefixes: tuple[str, ...]) -> int | None:
    for node in tree.body:
        if isinstance(node, ast.Import | ast.ImportFrom):
            names = [node.module or ""] if isinstance(node, ast.ImportFrom) else [a.name for a in node.names]
            if any(n.startswith(prefixes) for n in names):
                return node.lineno
    return None


def _private_folder_call(tree: ast.Module) -> ast.Call | None:
    """The module-level call of ``private_folder``."""
    for node in tree.body:
        value = getattr(node, "value", None)
        calls = [c for c in ast.walk(value) if isinstance(c, ast.Call)] if value is not None else []
        for call in calls:
            if ast.unparse(call.func).endswith("private_folder"):
                return call
    return None


def test_every_screenshot_script_takes_the_one_set_up(monkeypatch):
    """Each script's folder, application and window come from shots.py: private_folder() at module
    level before anything of Qt or FHA Studio is imported, nothing of that set-up of its own."""
    assert len(SCRIPTS) >= 10 and not list(ROOT.joinpath("scripts").glob("*screenshot*"))
    monkeypatch.syspath_prepend(str(SHOTS))
    from shots import private_folder

    signature = inspect.signature(private_folder)
    wrong = []
    for path in SCRIPTS:
        text = path.read_text(encoding="utf-8")
        tree = ast.parse(text)
        name = path.relative_to(ROOT)
        own = [what for what in OWN_SET_UP if what in text]
        if own:
            wrong.append(f"{name}: its own {', '.join(own)} (shots.py has it)")
        call = _private_folder_call(tree)
        first = _first_line_importing(tree, ("PySide6", "fha_studio", "tests"))
        if call is None:
            wrong.append(f"{name}: no private_folder() at module level")
            continue
        if first is not None and first < call.lineno:
            wrong.append(f"{name}: line {first} imports Qt or FHA Studio before private_folder()")
        try:  # called as shots.py defines it
            signature.bind(*(ast.literal_eval(a) for a in call.args),
                           **{k.arg: ast.literal_eval(k.value) for k in call.keywords if k.arg})
        except (TypeError, ValueError) as exc:
            wrong.append(f"{name}: line {call.lineno}: {ast.unparse(call)}: {exc}")
    assert not wrong, "\n".join(wrong)


#: A screenshot script in short: its folder, then a step that fails or a wait that is killed.
SCRIPT = """
import os, sys, time
sys.path.insert(0, sys.argv[1])
from shots import private_folder
folder = private_folder()
print(folder, flush=True)
env = os.environ
print(env["XDG_CONFIG_HOME"], env["XDG_DATA_HOME"], "FHA_STUDIO_REGISTER" in env, flush=True)
if sys.argv[2] == "fails":
    raise RuntimeError("a step failed")
time.sleep(120)
"""


def _script(tmp_path: Path, how: str) -> Child:
    env = {"TMPDIR": str(tmp_path), "FHA_STUDIO_REGISTER": str(tmp_path / "the-users.sqlite")}
    return Child.python("-c", SCRIPT, SHOTS, how, text=True, env=env)


def test_a_screenshot_scripts_folder_goes_when_the_script_fails_or_is_terminated(tmp_path):
    with _script(tmp_path, "fails") as failing:
        folder = Path(failing.first_line("a failing screenshot script", expect=str(tmp_path)))
        # the settings and the data in it, no register of the user's
        assert failing.first_line("its folders").split() == [f"{folder}/config", f"{folder}/data", "False"]
        assert failing.proc.wait(timeout=60) == 1
    assert not folder.exists()
    with _script(tmp_path, "waits") as terminated:
        folder = Path(terminated.first_line("a waiting screenshot script", expect=str(tmp_path)))
        assert (folder / "owner.json").exists()
        terminated.proc.send_signal(signal.SIGTERM)
        assert terminated.proc.wait(timeout=60) == 128 + signal.SIGTERM
    assert not folder.exists()
    assert not list(tmp_path.glob("fha-shots-*"))


def test_the_next_screenshot_script_removes_what_a_killed_one_left(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(SHOTS))
    from shots import UNOWNED_STALE_S, sweep_left_folders

    with _script(tmp_path, "waits") as killed:
        left = Path(killed.first_line("a screenshot script", expect=str(tmp_path)))
        killed.proc.kill()
        killed.proc.wait(timeout=60)
    running = tmp_path / "fha-shots-running"  # a script running now: this process
    running.mkdir()
    running.joinpath("owner.json").write_text(json.dumps({"pid": os.getpid(), "pid_started_ticks": None}))
    old, young = tmp_path / "fha-shots-old", tmp_path / "fha-shots-young"  # before the owner's note
    for folder in (old, young):
        folder.mkdir()
    then = old.stat().st_mtime - UNOWNED_STALE_S - 60
    os.utime(old, (then, then))
    other = tmp_path / "fha-bench-1"  # not a screenshot script's
    other.mkdir()
    assert sorted(sweep_left_folders(str(tmp_path))) == sorted([left, old])
    assert running.exists() and young.exists() and other.exists()


class _StuckDrive:
    """A drive whose move never ends."""

    class _Io:
        moving = True

    def servo(self, on: bool) -> None:
        pass

    def set_move_speed(self, rpm: float) -> None:
        pass

    def move_by(self, angle_deg: float) -> None:
        pass

    def io_state(self):
        return self._Io()


def test_the_model_check_screenshots_give_up_on_a_move_that_does_not_end(monkeypatch, tmp_path):
    # the script's set-up on import changes the environment, the signals and sys.path: put back after
    for name in ("XDG_CONFIG_HOME", "XDG_DATA_HOME", "FHA_STUDIO_REGISTER"):
        if name in os.environ:
            monkeypatch.setenv(name, os.environ[name])
        else:
            monkeypatch.delenv(name, raising=False)
    handlers = {number: signal.getsignal(number) for number in (signal.SIGTERM, signal.SIGHUP)}
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    monkeypatch.syspath_prepend(str(SHOTS))
    try:
        spec = importlib.util.spec_from_file_location("take_modelcheck", SHOTS / "take_modelcheck.py")
        assert spec is not None and spec.loader is not None
        script = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(script)
    finally:
        for number, handler in handlers.items():
            signal.signal(number, handler)
    assert script.MOVE_DEADLINE_S >= 10.0
    with pytest.raises(TimeoutError, match=r"the move by 90° had not ended after 0 s .*no screenshots taken"):
        script.back_and_forth(_StuckDrive(), deadline_s=0.0)


def test_the_pictures_show_a_technicians_folders_not_the_temporary_one(qtbot, monkeypatch):
    """A path into the run's temporary folder is shown as a technician's (the register in the
    user's data, a session in their commissioning folder) in every text of the grabbed widget,
    without a signal to the page behind it; the widgets get their own text back."""
    from PySide6.QtWidgets import QLabel, QLineEdit, QPlainTextEdit, QVBoxLayout, QWidget

    monkeypatch.syspath_prepend(str(SHOTS))
    import shots

    folder = "/tmp/fha-shots-x1y2"
    monkeypatch.setattr(shots, "_folder", folder)
    data = f"{folder}/data/FHA Studio Screenshots/fha-studio-screenshots"
    assert shots.shown_paths(f"Register file: {data}/register.sqlite") == (
        "Register file: /home/technician/.local/share/FHA Studio/fha-studio/register.sqlite")
    assert shots.shown_paths(f"Session {folder}/axis1.json — FHA-25C-50-US250") == (
        "Session /home/technician/commissioning/axis1.json — FHA-25C-50-US250")
    assert shots.shown_paths("/tmp/fha-shots-other/axis1.json") == "/tmp/fha-shots-other/axis1.json"

    page = QWidget()
    qtbot.addWidget(page)
    label = QLabel(f"Session {folder}/axis1.json")
    field = QLineEdit(f"{folder}/capture.sr")
    log = QPlainTextEdit(f"Backup saved: {folder}/config/backup.toml")
    plain = QLabel("no path here")
    layout = QVBoxLayout(page)
    for w in (label, field, log, plain):
        layout.addWidget(w)
    edits: list[str] = []
    field.textChanged.connect(edits.append)
    put_back = shots._paths_shown_plausibly(page)
    assert label.text() == "Session /home/technician/commissioning/axis1.json"
    assert field.text() == "/home/technician/commissioning/capture.sr"
    assert log.toPlainText() == "Backup saved: /home/technician/.config/backup.toml"
    assert plain.text() == "no path here"
    put_back()
    assert (label.text(), field.text(), log.toPlainText()) == (
        f"Session {folder}/axis1.json", f"{folder}/capture.sr", f"Backup saved: {folder}/config/backup.toml")
    assert edits == []  # the page behind a field never saw the picture's text

    # a report's parameter file, beside the session in the temporary folder
    from fha_studio.logic.procedures import report_inputs

    beside_the_session = {"file": f"{folder}/axis1.params"}
    monkeypatch.setattr(report_inputs, "_parameters", lambda _session, _inputs: dict(beside_the_session))
    shots.reports_show_plausible_paths()
    assert report_inputs._parameters(None, None) == {"file": "/home/technician/commissioning/axis1.params"}
