"""GUI fixtures: the user's settings and data are never read or written by a test, and every
window is built by a factory that tears it down without leaking widgets or threads."""

from __future__ import annotations

import pytest
from PySide6.QtCore import QCoreApplication, QSettings, QStandardPaths

from tests.support.windows import torn_down


@pytest.fixture(autouse=True)
def _isolated_settings(tmp_path, monkeypatch):
    """QSettings go to a temporary directory, under a test organisation name; so do backups and
    session logs (XDG_DATA_HOME)."""
    for fmt in (QSettings.Format.NativeFormat, QSettings.Format.IniFormat):
        QSettings.setPath(fmt, QSettings.Scope.UserScope, str(tmp_path / "settings"))
    QCoreApplication.setOrganizationName("FHA Studio Tests")
    QCoreApplication.setApplicationName("fha-studio-tests")
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    assert str(tmp_path) in QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation)
    yield
    QSettings().clear()


@pytest.fixture
def make_window(qtbot):
    """Factory: make_window(open_client=None, connect=url or None) -> a shown MainWindow.

    `open_client(url, baud)` replaces the real DriveClient.open (a fake drive); by default the
    real client (and the embedded simulated drive for sim:// URLs) is used. On teardown the link
    thread is ended, the window closed and deleted, and no top-level widget may be left
    (tests/support/windows.py).
    """
    from fha_studio.gui.link import LinkController
    from fha_studio.gui.main_window import MainWindow

    def factory(open_client=None, connect: str | None = None, show: bool = True):
        link = LinkController(open_client=open_client)
        window = MainWindow(link)
        link.setParent(window)
        # not qtbot.addWidget: its teardown closes the window before ours can end the link
        if show:
            window.show()
        windows.append(window)
        if connect:
            with qtbot.waitSignal(link.sigConnected, timeout=10000):
                window.connect_to(connect)
        return window

    with torn_down(lambda window: [window.link]) as windows:
        yield factory


@pytest.fixture
def make_cli_window(qtbot):
    """Factory: make_cli_window(*options) -> the single-axis window ``fha-studio OPTIONS`` makes
    (the register line included), shown, not connected; torn down as every window of the tests."""
    from fha_studio.gui.app import parse_arguments, single_axis_window

    def factory(*options: str):
        window = single_axis_window(parse_arguments([*options, "--no-connect"]))
        window.show()
        windows.append(window)
        return window

    with torn_down(lambda window: [window.link]) as windows:
        yield factory


@pytest.fixture
def documented_window(make_window):
    """Factory: documented_window(code) -> a shown window on the simulated drive ``code``'s documented
    profile (tests/gui/controller.py), its actuator acknowledged."""
    from tests.gui.controller import documented_url

    def factory(code: str = "FHA-25C-50-US250"):
        window = make_window(connect=documented_url(code))
        window.state.set_actuator(code, acknowledged=True)
        return window

    return factory


@pytest.fixture(scope="session")
def friction_file(tmp_path_factory):
    """A recording of FHA-25C-50 moves (1.5 kg·m² load) with 8 N·m of Coulomb friction the
    model lacks: what the model check finds and words."""
    import sys
    from pathlib import Path

    from fha_studio.physics import AxisModel, Effects
    from fha_studio.recording import write_recording

    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "modelcheck"))
    from modelcheck_gen import moves_for, record, trapezoid_moves

    code = "FHA-25C-50-US250"
    model = AxisModel.from_code(code, load_inertia_kgm2=1.5)
    t, cmd = trapezoid_moves(moves_for(model, n_moves=5), 1000.0)
    rec = record(model, Effects().with_effect("coulomb_friction", torque_nm=8.0), t, cmd, actuator_code=code)
    path = tmp_path_factory.mktemp("rec") / "friction.csv"
    write_recording(path, rec.recording)
    return path
