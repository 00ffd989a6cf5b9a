"""The Bench tab keeps the channels and roles typed for an instrument, in the user's settings
(a temporary directory in tests), and offers them again when the same instrument is chosen."""

from __future__ import annotations

import shutil

import pytest
from PySide6.QtCore import QSettings

from fha_studio.gui.pages.scope import bench_mappings

pytestmark = pytest.mark.skipif(shutil.which("sigrok-cli") is None, reason="sigrok-cli is not installed")


def _panel(qtbot):
    from fha_studio.gui.pages.scope.bench_panel import BenchPanel

    panel = BenchPanel()
    qtbot.addWidget(panel)
    return panel


def test_a_mapping_is_kept_per_instrument_and_offered_again(qtbot):
    assert QSettings().value(bench_mappings.SETTINGS_KEY) is None  # the tests' own settings
    panel = _panel(qtbot)
    try:
        with qtbot.waitSignal(panel.source.sigStarted, timeout=10000):
            panel.start("demo", "D0,D1,D2,D5", "1m", "D0,D1", "D2", "D5")
        with qtbot.waitSignal(panel.source.sigStopped, timeout=10000):
            panel.start_button.click()
    finally:
        panel.shutdown()
    assert bench_mappings.saved("demo") == {"channels": "D0,D1,D2,D5", "rate": "1m", "encoder": "D0,D1",
                                            "command": "D2", "in_position": "D5"}

    again = _panel(qtbot)
    try:
        with qtbot.waitSignal(again.sigDevicesListed, timeout=10000):
            again.scan()  # the demo comes first in the list: its mapping is offered
        assert again.device_box.currentText().startswith("demo")
        assert (again.channels_edit.text(), again.rate_edit.text(), again.encoder_edit.text(),
                again.command_edit.text(), again.in_position_edit.text()) == ("D0,D1,D2,D5", "1m", "D0,D1",
                                                                              "D2", "D5")
        again.channels_edit.setText("D7")
        again.device_box.setEditText("demo:logic_channels=4")  # another instrument: nothing offered
        assert again.channels_edit.text() == "D7"
        again.device_box.setEditText("demo")
        assert again.channels_edit.text() == "D0,D1,D2,D5"
        assert again.status_label.text() == "Channels and roles as last used with demo."
    finally:
        again.shutdown()


def test_a_damaged_entry_is_forgotten_and_the_list_is_bounded(qtbot):
    QSettings().setValue(bench_mappings.SETTINGS_KEY, "{not json")
    assert bench_mappings.saved("demo") is None
    for i in range(bench_mappings.MAX_INSTRUMENTS + 5):
        bench_mappings.save(f"fx2lafw:conn=1.{i}", {"channels": "D0"})
    assert bench_mappings.saved("fx2lafw:conn=1.0") is None
    assert bench_mappings.saved(f"fx2lafw:conn=1.{bench_mappings.MAX_INSTRUMENTS + 4}")["channels"] == "D0"
