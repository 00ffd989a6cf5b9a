"""Takes the README's screenshots of commissioning a drive that answers only DGR and OWW.

    xvfb-run -a -s "-screen 0 1366x768x24" python docs/screenshots/take_documented.py [OUTDIR]

The embedded simulated drive's documented profile (as a real HA-655: DGR and OWW only), with its
panel playing the controller's servo-ON and FWD command and the technician's hands. Settings and
data go to a temporary directory, never the user's.
"""

from __future__ import annotations

from shots import ScreenshotRun, private_folder, users_sim_drive

TMP = private_folder()
URL = users_sim_drive("FHA-25C-50-S248", documented=True, paced="0", sensors="1", oww_clear_s="5",
                      eeprom=f"{TMP}/eeprom.json")


def main() -> int:
    run = ScreenshotRun((1366, 740), settle_before_shot_s=0.2)
    window, wait_until, settle, shot, panel = run.window, run.wait_until, run.settle, run.shot, run.panel

    window.connect_to(URL)
    wait_until(lambda: window.link.status is not None and window.link.status.absolute_counts is not None)
    window.state.set_actuator("FHA-25C-50-S248-L", acknowledged=True)

    # the front-panel worksheet: values read on the drive's panel, entered with who and when
    params = window.show_page("parameters")
    params.who_edit.setText("J. Field")
    model = params.model
    for key, text in (("position_loop_gain", "60"), ("rotary_direction", "0"), ("in_position_range", "20")):
        try:
            model.setData(model.index(model.row_of(key), 3), text)
        except StopIteration:
            continue
    params.table.selectRow(model.row_of("position_loop_gain"))
    shot("front-panel-worksheet")

    page = window.show_page("absolute")
    page.who_edit.setText("J. Field")
    settle()
    # encoder check: +10 deg by hand
    page.encoder_start_button.click()
    wait_until(lambda: page._encoder_start is not None)
    panel("turn", 10.0)
    n = len(page.records)
    page.encoder_end_button.click()
    wait_until(lambda: len(page.records) > n)
    # rotary direction 1-10: parameter 8 = 0 from the panel; servo on, FWD 5 deg, servo off
    page.tabs.setCurrentIndex(1)
    page.direction_param.setCurrentIndex(1)
    page.direction_start_button.click()
    wait_until(lambda: page._direction_start is not None)
    window.sim_panel.servo_check.setChecked(True)
    wait_until(lambda: window.link.status.servo_on)
    panel("command", 5.0)
    settle(1.5)
    window.sim_panel.servo_check.setChecked(False)
    wait_until(lambda: window.link.status.servo_on is False)
    wait_until(lambda: page.direction_end_button.isEnabled())
    n = len(page.records)
    page.direction_end_button.click()
    wait_until(lambda: len(page.records) > n)
    shot("dgr-checks")

    # sensor dogs: limit switch 2 near +150 deg
    page.tabs.setCurrentIndex(2)
    angle = page.records[-1].values["after_counts"] * 360 / (8192 * 50)
    panel("turn", 150.5 - angle)
    page.dog_sensor.setCurrentIndex(1)
    n = len(page.records)
    page.dog_record_button.click()
    wait_until(lambda: len(page.records) > n)

    # absolute origin: OWW, about 5 s, read back
    page.tabs.setCurrentIndex(3)
    n = len(page.records)
    page.origin_button.click()
    wait_until(lambda: len(page.records) > n, timeout_s=30.0)
    shot("origin-wizard")

    alarms = window.show_page("alarms")
    alarms.panel_code_edit.setText("60")
    alarms.alm_checks["B"].setChecked(True)
    alarms.alm_read_check.setChecked(True)
    alarms.enter_from_panel()
    shot("alarms-front-panel")

    window.show_page("direction")
    shot("rotary-direction-documented")

    run.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
