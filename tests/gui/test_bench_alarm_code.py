"""The Bench tab reads ALARM and the alarm code lines ALM-A ... D of the simulated drive's CN2 (the
sim-cn2 instrument) and says the code in the manual's words as it comes: 0010 is alarm 60, error
counter overflow, as the HA-655's table gives it; the lines are kept with the instrument's mapping."""

from __future__ import annotations

from fha_studio.gui.pages.scope import bench_mappings

CODE = "FHA-25C-50-US250"
URL = f"sim://{CODE}?paced=0&profile=documented"


def test_the_alarm_code_lines_are_shown_in_the_manuals_words(make_window, qtbot):
    window = make_window(connect=URL)
    drive = window.link._worker._client.transaction.transport.inner.sim_drive
    scope = window.show_page("scope")
    bench = scope.bench
    scope.view.plots.setCurrentWidget(bench)
    with qtbot.waitSignal(bench.source.sigStarted, timeout=10000):
        bench.start("sim-cn2", "ENC_A,ENC_B,ALARM,ALM_A,ALM_B,ALM_C,ALM_D", "50k",
                    "ENC_A,ENC_B", alarm="ALARM", alm=("ALM_A", "ALM_B", "ALM_C", "ALM_D"))
    assert bench.source.started.logic == ("ENC_A", "ENC_B", "ALARM", "ALM_A", "ALM_B", "ALM_C", "ALM_D")
    qtbot.waitUntil(lambda: not bench.alarm_label.isHidden(), timeout=10000)
    assert bench.alarm_label.text() == "ALARM off; ALM-D C B A 0000: no alarm"
    drive.raise_alarm(60)
    qtbot.waitUntil(lambda: "60" in bench.alarm_label.text(), timeout=10000)
    assert bench.alarm_label.text() == ("Alarm from the bench: ALARM ON; ALM-D C B A 0010: 60 Error "
                                        "counter overflow; the front panel's 2-digit code and the Alarms "
                                        "page say more")
    # the code lines in one lane, as a logic analyzer shows a bus: the code written in it
    lanes = [name for _, name in bench.plot.getAxis("right")._tickLevels[0]]
    assert lanes == ["bench sim-cn2:ENC_A", "bench sim-cn2:ENC_B", "bench sim-cn2:ALARM",
                     "bench sim-cn2:ALM-D C B A"]
    qtbot.waitUntil(lambda: "0010" in [t.toPlainText() for t in bench._code_texts if t.isVisible()],
                    timeout=10000)
    with qtbot.waitSignal(bench.source.sigStopped, timeout=10000):
        bench.start_button.click()
    saved = bench_mappings.saved("sim-cn2")
    assert (saved["alarm"], saved["alm_a"], saved["alm_d"]) == ("ALARM", "ALM_A", "ALM_D")


def test_an_alarm_line_not_among_the_channels_is_refused_in_one_line(qtbot):
    from fha_studio.gui.pages.scope.bench_panel import BenchPanel

    bench = BenchPanel()
    qtbot.addWidget(bench)
    try:
        bench.start("demo", "D0,D1", "1m", alm=("D0", "", "D7"))
        assert bench.status_label.text() == "ALM-C D7: it must be among the channels (D0, D1)."
        assert not bench.start_button.isChecked() and not bench.source.running
        pin = "CN2 pin: see the CN2 pin table in chapter 3 of the HA-655 manual"
        assert pin in bench.alm_edits[0].toolTip()
        assert "(CN2-33)" in bench.in_position_edit.toolTip()
    finally:
        bench.shutdown()
