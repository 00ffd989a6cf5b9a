"""Takes the README's screenshots of every page on the embedded simulated drive.

    xvfb-run -a -s "-screen 0 1366x768x24" python docs/screenshots/take.py [OUTDIR]

A scripted commissioning session: connect, read, set the rotary direction to reversed (not
written), servo on and jog, raise alarm 20 on the simulated drive, a sizing duty, a procedures
session; the connect dialog and the Register line's dialog. Settings and data go to a temporary
directory, never the user's.
"""

from __future__ import annotations

from pathlib import Path

from shots import ScreenshotRun, private_folder, users_sim_drive

TMP = private_folder()


def main() -> int:
    run = ScreenshotRun((1366, 740))  # fha-studio's window, with its Register line
    window, wait_until, settle, shot = run.window, run.wait_until, run.settle, run.shot
    from fha_studio.gui.link import Servo

    window.connect_to(users_sim_drive("FHA-25C-50-US250", paced="0"))
    wait_until(lambda: len(window.state.drive_values) >= 14, "the drive's values", 60.0)
    window.show_page("connection")
    shot("connection")

    page = window.show_page("parameters")
    page.model.setData(page.model.index(page.model.row_of("position_loop_gain"), 3), "60")
    shot("parameters")

    page = window.show_page("direction")
    page.ccw_radio.setChecked(True)
    shot("rotary-direction")
    page.cw_radio.setChecked(True)

    window.link.send(Servo(True))
    wait_until(lambda: window.link.servo_on, "servo-ON")
    page = window.show_page("jog")
    page.motion.speed_spin.setValue(8.0)
    page.motion._jog(+1)  # as if FWD were held
    wait_until(lambda: window.link.moving, "the jog")
    settle(0.7)
    shot("jog")
    window.link.jog_release()  # _jog pressed no button: releasing the buttons would not end it
    wait_until(lambda: not window.link.moving, "the jog's end")

    run.sim_drive().raise_alarm(20)
    wait_until(lambda: window.alarm_lamp.state is True, "alarm 20")
    window.show_page("alarms")
    settle(0.5)
    shot("alarms")

    page = window.show_page("sizing")
    page.inertia_spin.setValue(1.2)
    page.speed_spin.setValue(40.0)
    page.angle_spin.setValue(120.0)
    page.cycle_spin.setValue(1.5)
    page.calculate()
    shot("sizing")

    # the actuator is typed once, on the Connection page; the procedures take it from there
    window.connection_page.actuator_combo.setCurrentText("FHA-25C-50-US250-B-L")
    window.connection_page.check_pairing()
    page = window.show_page("procedures")
    page.operator_edit.setText("T. Trainee")
    page.new_session(Path(TMP) / "axis1.json")
    page.select_procedure("receiving-inspection")
    shot("procedures")

    from fha_studio.gui.connect_dialog import ConnectDialog

    dialog = ConnectDialog(window, ports=[("/dev/ttyUSB0", "FT232R USB UART"), ("/dev/ttyS0", "")])
    dialog.show()
    shot("connect-dialog", dialog)
    dialog.close()
    from fha_studio.gui.window_register import WindowAxisDialog

    naming = WindowAxisDialog(window.window_register, window)  # the toolbar's Register line
    naming.machine_combo.setCurrentText("Line 3 positioner")
    naming.axis_combo.setCurrentText("table")
    naming.show()
    shot("register-axis", naming)
    naming.close()
    window.link.send(Servo(False))
    wait_until(lambda: not window.link.servo_on, "servo-OFF")
    run.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
