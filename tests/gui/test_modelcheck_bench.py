"""The Model check page takes a recording made from a bench capture (``fha-studio bench import``
of the simulated drive's CN2): it says which columns it has (no current: no probe on the bench)
and where its position came from."""

from __future__ import annotations

import math

from fha_studio.catalog import get_actuator
from fha_studio.gui.pages.base import PageId
from fha_studio.hardware.sim.cn2 import Cn2Settings, VirtualBenchInstrument
from fha_studio.logic.bench.importer import AxisFacts, DriveSettings, SignalSpec, import_bench
from fha_studio.physics import AxisModel, Effects, ServoAxis
from fha_studio.recording import write_recording

CODE = "FHA-25C-50-US250"
RPM = 2 * math.pi / 60


def bench_recording(tmp_path):
    """A controller's move captured on the simulated drive's CN2 and imported: (capture, recording)."""
    axis = ServoAxis(AxisModel.from_actuator(get_actuator(CODE), load_inertia_kgm2=0.3))
    axis.servo_on()
    instrument = VirtualBenchInstrument(axis, 200e3, Cn2Settings(pulse_form=0))
    instrument.record(0.03)
    axis.move_by_pulses(9000, speed_rad_s=8 * RPM)
    instrument.record(0.4)
    return _imported(instrument, tmp_path, "capture", "bench",
                     {"speed_monitor": "SPD_MON", "in_position": "IN_POS"})


def _imported(instrument, tmp_path, capture_name: str, recording_name: str, more_roles: dict[str, str]):
    """The instrument's capture written as ``capture_name``.sr, the encoder and the command
    pulses with ``more_roles`` imported, the recording written as ``recording_name``.csv:
    (capture, recording's path)."""
    capture = tmp_path / f"{capture_name}.sr"
    instrument.write(capture, "sr")
    roles = {"encoder_a": "ENC_A", "encoder_b": "ENC_B", "command_a": "CMD_A", "command_b": "CMD_B",
             **more_roles}
    result = import_bench([SignalSpec(r, str(capture), c) for r, c in roles.items()],
                          AxisFacts.for_actuator(CODE), DriveSettings(0, 4, 1, 1, 3000.0))
    path = tmp_path / f"{recording_name}.csv"
    write_recording(path, result.recording)
    return capture, path


def test_a_bench_recording_opens_on_the_model_check_page_with_its_source(make_window, tmp_path):
    capture, path = bench_recording(tmp_path)
    window = make_window()
    page = window.page(PageId.MODELCHECK)
    recording = page.load_recording(path)
    assert not recording.has_current
    text = page.source_label.text()
    assert "columns t, pos, cmd_pos, vel." in text and "current" not in text.split("columns")[1].split(".")[0]
    assert f"Position from {capture}#ENC_A and {capture}#ENC_B, x4" in text
    assert "No current column (no current probe on the bench)." in text


def test_a_bench_recordings_check_says_where_its_torque_comes_from_and_why_no_effect_is_named(
        make_window, qtbot, tmp_path):
    """Without a current the torque plot says the torque is read through the speed loop (not
    "measured (Kt x current)"), so do the channel's name on the other tabs (not "Torque (motor
    current)"), the re-simulation names its command in words (not "cmd_pos"), and an empty
    effects table says that no effect was named."""
    from fha_studio.gui.pages.modelcheck.page import (
        NO_CURRENT_TORQUE,
        NO_EFFECT,
        TORQUE_THROUGH_LOOP,
        TORQUE_TITLE_NO_CURRENT,
    )

    _capture, path = bench_recording(tmp_path)
    window = make_window()
    window.session.state.set_load_inertia(0.3)
    page = window.page(PageId.MODELCHECK)
    page.load_recording(path)
    with qtbot.waitSignal(page.sigFinished, timeout=60000) as done:
        page.run()
    item = page.torque_plot.getPlotItem()
    assert TORQUE_TITLE_NO_CURRENT in item.titleLabel.text
    assert item.listDataItems()[0].name() == NO_CURRENT_TORQUE
    table = page.effects_table
    assert not done.args[0].effects  # a clean simulated axis, its inertia declared right
    assert table.rowCount() == 1 and table.item(0, 0).text() == NO_EFFECT
    assert table.columnSpan(0, 0) == table.columnCount()
    findings = page.findings.toPlainText()
    assert f"{TORQUE_THROUGH_LOOP}: checked." in findings and "Motor current: not checked" in findings
    assert "motor current" not in " ".join(p.getPlotItem().titleLabel.text for p in page.gap_plots.values())
    assert page.where_channel.itemText(0) == TORQUE_THROUGH_LOOP
    resimulation = page.resim_torque_plot.getPlotItem().titleLabel.text
    assert "recorded command position" in resimulation and "cmd_pos" not in resimulation


def test_a_model_check_plot_of_hundredths_of_a_newton_metre_reads_them_as_they_are(qtbot):
    """A residual of a few hundredths of a N·m: its axis says "N·m" with ticks such as 0.2, not
    "N·m (x0.001)" beside ticks of hundreds (pyqtgraph's own prefix for a unit it does not know)."""
    import numpy as np

    from fha_studio.gui.pages.modelcheck.page import _plot

    # a plot made with its data, as the gap tab makes them
    plot = _plot("Torque: 0.0576 → 0.0576 N·m rms", "N·m", empty=False)
    qtbot.addWidget(plot)
    plot.resize(600, 300)
    plot.show()
    t = np.linspace(0.0, 1.6, 400)
    plot.plot(t, 0.3 * np.sin(8 * t))
    qtbot.waitUntil(lambda: plot.getPlotItem().viewRange()[1][1] < 1.0, timeout=10000)
    label = plot.getPlotItem().getAxis("left").labelString()
    assert "N·m" in label and "(x" not in label


def test_the_coast_after_an_alarm_is_shown_beside_the_gaps(make_window, qtbot, tmp_path):
    """A capture with the ALARM line: the move, an alarm at speed and the axis coasting with a
    viscous drag the servo-on part cannot see. The page names it with where it was read, and the
    gap tab shows the coast's speed, recorded and from each model, in r/min."""
    model = AxisModel.from_actuator(get_actuator(CODE), load_inertia_kgm2=0.3)
    drag = Effects().with_effect("viscous_friction", coefficient_nm_s_per_rad=2.0)
    axis = ServoAxis(model.with_effects(drag))
    axis.servo_on()
    alarm = [0]
    instrument = VirtualBenchInstrument(axis, 200e3, Cn2Settings(pulse_form=0), alarm=lambda: alarm[0])
    instrument.record(0.03)
    axis.move_by_pulses(90000, speed_rad_s=8 * RPM)
    instrument.record(0.3)
    alarm[0] = 60  # the deviation counter overflowed: the drive de-energises the motor
    axis.servo_off()
    instrument.record(0.4)
    _, path = _imported(instrument, tmp_path, "coast", "coast", {"in_position": "IN_POS", "alarm": "ALARM"})
    window = make_window()
    window.session.state.set_load_inertia(0.3)
    page = window.page(PageId.MODELCHECK)
    page.load_recording(path)
    with qtbot.waitSignal(page.sigFinished, timeout=60000):
        page.run()
    table = page.effects_table
    rows = {table.item(r, 0).text(): table.item(r, 1).text() for r in range(table.rowCount())}
    assert "from the coast after the alarm at 0.33 s" in rows["Viscous friction"], rows
    assert "N·m·s/rad" in rows["Viscous friction"] or "N m s/rad" in rows["Viscous friction"], rows
    titles = [p.getPlotItem().titleLabel.text for p in page.gap_plots.values()]
    coast = next(t for t in titles if t.startswith("Coast after the alarm at 0.33 s"))
    assert "r/min rms against the recorded one" in coast
    assert not page.gap_empty.isVisible()
    assert "Coast after the alarm at 0.33 s" in page.summary.toPlainText(), page.summary.toPlainText()
    assert "Viscous friction: named from the coast after the alarm at 0.33 s" in page.findings.toPlainText()
    for text in (page.summary.toPlainText(), page.findings.toPlainText()):  # the manual's units on a page
        assert "kg·m²" in text or "N·m" in text
        assert not any(ascii_unit in text for ascii_unit in ("kg m^2", " N m", "arcsec")), text
