"""Takes the README's screenshots of the Scope page on the embedded simulated drive (with a
kinematic error): live while jogging with the cursors, a triggered move's trace, the move test, the
spectrum of a constant-speed trace.

    xvfb-run -a -s "-screen 0 1366x768x24" python docs/screenshots/take_scope.py [OUTDIR]

Settings and data go to a temporary directory, never the user's.
"""

from __future__ import annotations

from shots import ScreenshotRun, private_folder, users_sim_drive

TMP = private_folder()
URL = users_sim_drive("FHA-25C-50-US250", 0.5,
                      effects="kinematic_error:amplitude_arcsec=40,cycles_per_motor_rev=2")


def main() -> int:
    from fha_studio.gui.link import MoveBy, Servo, SetMoveSpeed
    from fha_studio.hardware import protocol as p

    run = ScreenshotRun((1366, 740))
    w, settle = run.window, run.settle

    def wait_until(condition, timeout=20.0):
        run.wait_until(condition, "a step of the scope's session", timeout)

    link = w.link
    w.connect_to(URL)
    wait_until(lambda: link.connected)
    page = w.show_page("scope")
    view = page.view
    view.load_inertia.setValue(0.5)
    wait_until(lambda: page.controller.connected)
    settle(0.5)
    view.start_live()
    wait_until(lambda: view.indicator_text() == "LIVE")
    link.send(Servo(True))
    wait_until(lambda: link.servo_on)
    view.time_base.setCurrentIndex(view.time_base.findData(10.0))
    panel = page.jog_panel  # the scope's own Move panel, as a technician jogs while watching
    panel.speed_spin.setValue(30.0)
    panel.fwd_button.sigHeld.emit()
    settle(2.5)
    panel.fwd_button.sigReleased.emit()
    settle(1.5)
    panel.speed_spin.setValue(15.0)
    panel.rev_button.sigHeld.emit()
    settle(2.0)
    panel.rev_button.sigReleased.emit()
    settle(2.0)
    view.set_cursors(*(lambda r: (r[0] + 4.0, r[0] + 6.5))(view.time_plot.x_range()))
    settle(0.3)
    run.shot("scope-live")
    view.cursors_box.setChecked(False)

    # a triggered move
    view.trigger_kind.setCurrentIndex(view.trigger_kind.findData(p.TriggerKind.IO_BIT_RISES))
    view.trigger_channel.setCurrentIndex(view.trigger_channel.findData("moving"))
    view.trace_samples.setValue(1024)
    view.trace_rate.setValue(1000)
    view.arm_trace()
    wait_until(lambda: "waiting for the trigger" in view.trace_state.text())
    link.send(SetMoveSpeed(20.0))
    link.send(MoveBy(45.0))
    wait_until(lambda: view.last_trace is not None, timeout=120)
    settle(0.5)
    view.set_cursors(0.0, 0.3)
    settle(0.3)
    run.shot("scope-trace")
    view.cursors_box.setChecked(False)

    # the move test
    view.test_angle.setValue(30.0)
    view.test_speed.setValue(20.0)
    view.run_test("move")
    wait_until(lambda: view.last_test is not None, timeout=180)
    settle(0.5)
    side = next(t for t in view.findChildren(type(view.plots)) if t is not view.plots)
    side.setCurrentIndex(1)
    settle(0.3)
    run.shot("scope-move-test")

    # spectrum of a constant-speed trace (kinematic error)
    view.trigger_kind.setCurrentIndex(view.trigger_kind.findData(p.TriggerKind.IMMEDIATE))
    view.trace_samples.setValue(2048)
    view.trace_rate.setValue(1000)
    keys = ("load_position", "feedback_position", "output_speed", "error_pulses")
    for box, key in zip(view.trace_channels, keys, strict=True):
        box.setCurrentIndex(max(0, box.findData(key)))
    link.jog_press(10.0)
    settle(1.5)
    view.last_trace = None
    view.arm_trace()
    wait_until(lambda: view.last_trace is not None, timeout=180)
    link.jog_release()
    view.spectrum_channel.setCurrentIndex(view.spectrum_channel.findData("load_position"))
    view.spectrum_panel.spectrum_detrend.setCurrentIndex(0)
    view.compute_spectrum()
    settle(0.5)
    run.shot("scope-spectrum")
    print("peaks:", view.spectrum_label.text())
    print("test:", view.last_test.describe())
    run.close()

    return 0


if __name__ == "__main__":
    raise SystemExit(main())
