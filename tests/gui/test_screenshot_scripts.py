"""The screenshot scripts run the real windows: they must not write into the user's settings and
data (the tests' rule, tests/gui/conftest.py), and none may wait for ever."""

from __future__ import annotations

import ast
import importlib.util
import os
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCRIPTS = sorted([*ROOT.joinpath("docs", "screenshots").glob("*.py"), *ROOT.joinpath("scripts").glob("*.py")])


def _environment_set(tree: ast.Module) -> dict[str, int]:
    """Module-level ``os.environ["NAME"] = ...`` from a temporary directory: NAME -> line."""
    temporary = any(isinstance(n, ast.Attribute) and n.attr == "mkdtemp" for n in ast.walk(tree))
    found = {}
    for node in tree.body:
        if isinstance(node, ast.Assign) and temporary:
            for target in node.targets:
                if (isinstance(target, ast.Subscript) and ast.unparse(target.value) == "os.environ"
                        and isinstance(target.slice, ast.Constant)):
                    found[target.slice.value] = node.lineno
    return found


def _first_qt_line(tree: ast.Module) -> int | None:
    """The first line that imports Qt or the GUI at module level (the settings' place is fixed then);
    None for a module that imports Qt only inside its functions (docs/screenshots/shots.py)."""
    for node in tree.body:
        if isinstance(node, ast.Import | ast.ImportFrom):
            names = [node.module or ""] if isinstance(node, ast.ImportFrom) else [a.name for a in node.names]
            if any(n.startswith(("PySide6", "fha_studio.gui")) for n in names):
                return node.lineno
    return None


def _sets_both_in_a_function(tree: ast.Module) -> bool:
    """Whether a function of the module sets both folders to a temporary one (shots.py's
    private_folder, which its scripts call before they start Qt)."""
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            inner = ast.Module(body=node.body, type_ignores=[])
            if {"XDG_CONFIG_HOME", "XDG_DATA_HOME"} <= set(_environment_set(inner)):
                return True
    return False


def test_every_screenshot_script_keeps_the_users_settings_and_data_out_of_it():
    assert any(path.name == "scope_screenshots.py" for path in SCRIPTS)
    wrong = []
    for path in SCRIPTS:
        text = path.read_text(encoding="utf-8")
        if "QApplication(" not in text:
            continue
        tree = ast.parse(text)
        where = _environment_set(tree)
        first_qt = _first_qt_line(tree)
        if first_qt is None:  # Qt started by a function: the folders must be set by one too
            if not _sets_both_in_a_function(tree):
                wrong.append(f"{path.relative_to(ROOT)}: starts Qt without setting both folders first")
            continue
        for name in ("XDG_CONFIG_HOME", "XDG_DATA_HOME"):
            if where.get(name, first_qt) >= first_qt:
                wrong.append(f"{path.relative_to(ROOT)}: {name} is not a temporary directory before Qt")
    assert not wrong, "\n".join(wrong)


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
    for name in ("XDG_CONFIG_HOME", "XDG_DATA_HOME"):  # the script sets them on import: put back after
        monkeypatch.setenv(name, os.environ.get(name, ""))
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    path = ROOT / "docs" / "screenshots" / "take_modelcheck.py"
    spec = importlib.util.spec_from_file_location("take_modelcheck", path)
    assert spec is not None and spec.loader is not None
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    assert script.MOVE_DEADLINE_S >= 10.0
    with pytest.raises(TimeoutError, match=r"the move by 90° had not ended after 0 s .*no screenshots taken"):
        script.back_and_forth(_StuckDrive(), deadline_s=0.0)
