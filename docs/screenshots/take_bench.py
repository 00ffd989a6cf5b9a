"""Takes the README's screenshots of the scope's Bench tab: a real HA-655 seen through its CN2.

    xvfb-run -a -s "-screen 0 1366x768x24" python docs/screenshots/take_bench.py [OUTDIR]

The embedded simulated drive's documented profile (CN3 silent while the servo is on, as a real
HA-655), its CN2 streamed as the ``sim-cn2`` instrument (a logic analyzer on the encoder
outputs, the command pulse inputs, IN-POS, ALARM and ALM-A ... D, an oscilloscope channel on
SPD-MON), parameter 8 entered from the drive's panel, the Procedures page on the rotary
direction's FWD step, the controller played by the drive's panel: servo-ON and a 10 deg FWD
command, which answers that step (the tab holds the move its figures describe while the
stream goes on); then, back to live, an alarm (60) on the code lines. Then sigrok-cli's
``demo`` driver, as any of its instruments shows on the tab. Settings and data go to a
temporary directory, never the user's.
"""

from __future__ import annotations

from shots import ScreenshotRun, private_folder, users_sim_drive

TMP = private_folder()
CODE = "FHA-25C-50-S248"  # absolute: CN3 gives the position (DGR) while the servo is off
URL = users_sim_drive(CODE, documented=True, paced="0")


def main() -> int:
    run = ScreenshotRun((1366, 768))
    window, wait_until, settle, shot = run.window, run.wait_until, run.settle, run.shot

    window.connect_to(URL)
    wait_until(lambda: window.link.status is not None, "the drive's first status")
    window.state.set_actuator(CODE, acknowledged=True)
    window.state.enter_front_panel("system", 8, 0, "A. Technician")  # rotary direction, from the panel
    # the Procedures page at the rotary direction's FWD step (parameter 8 as the panel shows it)
    procedures = window.show_page("procedures")
    procedures.operator_edit.setText("A. Technician")
    procedures.new_session(f"{TMP}/axis1.fha-session.json", CODE)
    procedures.select_procedure("rotary-direction")
    procedures.choice_combo.setCurrentText("CW")
    procedures.choice_button.click()
    asked: list = []
    procedures.sigLiveDone.connect(asked.append)
    procedures.live_button.click()
    wait_until(lambda: asked, "the parameter 8 check")
    procedures.by_hand_edit.setText("0")
    procedures.answer_by_hand()
    scope = window.show_page("scope")
    bench = scope.bench
    scope.view.plots.setCurrentWidget(bench)
    listed: list[int] = []
    bench.sigDevicesListed.connect(listed.append)
    bench.scan()
    wait_until(lambda: listed, "the instrument list")
    scope.view.start_live()  # CN3 beside: silent while the servo is on
    wait_until(lambda: scope.view.time_plot.live, "the CN3 live view")
    bench.start(bench.device_box.itemText(0),
                "ENC_A,ENC_B,CMD_A,CMD_B,IN_POS,ALARM,ALM_A,ALM_B,ALM_C,ALM_D,SPD_MON", "250k",
                "ENC_A,ENC_B", "CMD_A,CMD_B", "IN_POS", "ALARM", ("ALM_A", "ALM_B", "ALM_C", "ALM_D"))
    wait_until(lambda: bench.source.started is not None, "the sim-cn2 stream")
    window.show_page("procedures")  # the step says the bench watches
    window.show_page("scope")
    window.sim_panel.servo_check.setChecked(True)
    wait_until(lambda: window.link.status is not None and window.link.status.servo_on, "servo-ON")
    settle(0.5)
    window.sim_panel.command_spin.setValue(10.0)
    window.sim_panel.fwd_button.click()
    wait_until(lambda: bench.move_figures is not None, "the move's figures")
    settle(2.5)  # the stream goes on past the live window: the tab holds the move its figures describe
    shot("bench-move")
    wait_until(lambda: procedures.run is not None and procedures.run.completed, "the FWD step from the bench")
    scope.view.plots.setCurrentWidget(scope.view.time_plot)  # the same stream beside CN3's channels
    settle(1.0)
    shot("scope-bench-time")
    window.show_page("procedures")
    settle(0.3)
    shot("procedures-bench")
    window.show_page("scope")
    scope.view.plots.setCurrentWidget(bench)
    bench.back_button.click()  # the newest seconds again, to watch the alarm come
    # an alarm: the code on ALM-D C B A in the manual's words (60: the error counter overflowed)
    window.link._worker._client.transaction.transport.inner.sim_drive.raise_alarm(60)
    wait_until(lambda: "60 Error counter overflow" in bench.alarm_label.text(), "the alarm code")
    shot("bench-alarm")
    bench.start_button.click()
    wait_until(lambda: not bench.source.running, "the stream's end")
    window.link._worker._client.transaction.transport.inner.sim_drive.clear_alarm()
    window.sim_panel.servo_check.setChecked(False)
    wait_until(lambda: window.link.status is not None and not window.link.status.servo_on, "servo-OFF")
    scope.view.stop_live()

    # any instrument sigrok-cli drives: its demo at 10 kHz (every sample drawn), D0/D1 counted as an encoder
    bench.start("demo", "D0,D1,D2,D3", "10k", "D0,D1")
    wait_until(lambda: bench.source.started is not None, "the demo's stream")
    settle(2.5)
    shot("bench-demo")
    bench.start_button.click()
    wait_until(lambda: not bench.source.running, "the demo's end")
    run.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
