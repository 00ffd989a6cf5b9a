"""The layer contracts: the core imports no Qt, and each layer talks only to the ones below it."""

from __future__ import annotations

import os
import pkgutil
import shutil
import subprocess
import sys
from pathlib import Path

import fha_studio

ROOT = Path(__file__).resolve().parent.parent
CORE_PACKAGES = ("catalog", "physics", "hardware", "logic", "cli")


def core_modules() -> list[str]:
    names = ["fha_studio", "fha_studio.paths", "fha_studio.recording"]
    for info in pkgutil.walk_packages(fha_studio.__path__, "fha_studio."):
        top = info.name.split(".")[1]
        if top in CORE_PACKAGES:
            names.append(info.name)
    return names


def test_core_imports_and_runs_with_qt_unavailable():
    # Block the Qt bindings outright, as on a machine without them, then import every core
    # module and run the CLI's help: any Qt import anywhere in the core fails here.
    script = f"""
import sys, importlib, importlib.abc
class NoQt(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] in ('PySide6', 'pyqtgraph', 'shiboken6', 'PyQt5', 'PyQt6'):
            raise ImportError(f'Qt is blocked in the core: {{name}}')
        return None
sys.meta_path.insert(0, NoQt())
for name in {core_modules()!r}:
    importlib.import_module(name)
from fha_studio.cli import build_parser
build_parser().format_help()
leaked = [m for m in sys.modules if m.split('.')[0] in ('PySide6', 'pyqtgraph', 'shiboken6')]
assert not leaked, leaked
print('core ok', len({core_modules()!r}))
"""
    result = subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert "core ok" in result.stdout


def test_import_linter_contracts_hold():
    lint_imports = shutil.which("lint-imports") or str(Path(sys.executable).parent / "lint-imports")
    # PYTHONPATH makes the contracts judge this checkout, whatever the environment has installed.
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    result = subprocess.run([lint_imports, "--no-cache"], cwd=ROOT, capture_output=True, text=True, env=env)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Contracts: " in result.stdout and " broken" in result.stdout
    assert "0 broken" in result.stdout


def test_the_window_starts_without_the_heavy_modules_of_pages_not_shown(tmp_path):
    """Start-up stays short: scipy, pyqtgraph, numpy's users and the model check load with the
    page that needs them, not with the first window (the scope, sizing or model-check page)."""
    script = """
import sys
from PySide6.QtCore import QCoreApplication
from PySide6.QtWidgets import QApplication
app = QApplication([])
QCoreApplication.setOrganizationName("FHA Studio Tests")
from fha_studio.gui.app import parse_arguments, single_axis_window
window = single_axis_window(parse_arguments(["--no-connect"]))  # as fha-studio makes it
window.show()
app.processEvents()
heavy = sorted({m.split('.')[0] if not m.startswith('fha_studio') else m for m in sys.modules
                if m.split('.')[0] in ('scipy', 'pyqtgraph')
                or m.startswith(('fha_studio.logic.modelcheck', 'fha_studio.gui.pages.scope',
                                 'fha_studio.gui.pages.modelcheck'))})
print('heavy:', heavy)
window._closing_confirmed = True
window.shutdown()
window.deleteLater()  # before the QApplication, as the app does: not in the exit's arbitrary order
from PySide6.QtCore import QEvent
QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete.value)
del window
"""
    env = {**os.environ, "QT_QPA_PLATFORM": "offscreen", "XDG_CONFIG_HOME": str(tmp_path / "config"),
           "XDG_DATA_HOME": str(tmp_path / "data"), "PYTHONPATH": str(ROOT)}
    result = subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True, text=True,
                            env=env, timeout=120)
    assert result.returncode == 0, result.stderr
    assert "heavy: []" in result.stdout, result.stdout


def test_a_command_on_the_simulated_drive_starts_without_scipy(tmp_path):
    """The simulated drive samples its CN2 outputs (scipy.signal, a second of CPU to import) only
    for a bench instrument: ``drive params read`` on it does without."""
    url = f"sim://FHA-25C-50-US250?eeprom={tmp_path / 'e.json'}&paced=0"
    script = f"""
import sys
from fha_studio.cli import main
code = main(["drive", "params", "read", "--url", {url!r}])
assert code == 0, code
print('heavy:', sorted({{m.split('.')[0] for m in sys.modules if m.split('.')[0] in ('scipy', 'control')}}))
"""
    env = {**os.environ, "XDG_DATA_HOME": str(tmp_path / "data"), "PYTHONPATH": str(ROOT)}
    result = subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True, text=True,
                            env=env, timeout=120)
    assert result.returncode == 0, result.stderr
    assert "heavy: []" in result.stdout, result.stdout[-500:]


def test_the_command_line_starts_without_the_register_and_a_register_command_without_signing(tmp_path):
    """Every command's parser is built at each start: the register's words for its help do not
    load the register (its stores, a second of modules) nor the signing library; a register
    question that signs nothing does not load the signing library either."""
    register = tmp_path / "r.sqlite"
    script = f"""
import sys
from fha_studio.cli import build_parser, main
build_parser()
print('help:', sorted(m for m in sys.modules if m.split('.')[0] == 'cryptography'
                      or m.startswith(('fha_studio.logic.register.store', 'fha_studio.logic.register.keys'))))
assert main(["register", "--register", {str(register)!r}, "add-machine", "Line 3"]) == 0
assert main(["register", "--register", {str(register)!r}, "machines"]) == 0
print('question:', sorted({{m.split('.')[0] for m in sys.modules if m.split('.')[0] == 'cryptography'}}))
"""
    env = {**os.environ, "XDG_DATA_HOME": str(tmp_path / "data"), "PYTHONPATH": str(ROOT)}
    result = subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True, text=True,
                            env=env, timeout=120)
    assert result.returncode == 0, result.stderr
    assert "help: []" in result.stdout and "question: []" in result.stdout, result.stdout[-500:]
