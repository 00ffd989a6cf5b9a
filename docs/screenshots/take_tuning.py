"""Takes the README's screenshot of the Tuning page on the embedded simulated drive: an
FHA-25C-50 with a load of its own inertia on the gear's spring, measured, the resonance marked,
gains proposed.

    xvfb-run -a -s "-screen 0 1366x768x24" python docs/screenshots/take_tuning.py [OUTDIR]

Settings and data go to a temporary directory, never the user's.
"""

from __future__ import annotations

from shots import ScreenshotRun, private_folder, users_sim_drive

TMP = private_folder()
URL = users_sim_drive("FHA-25C-50-US250", 0.81, paced="0", effects="torsional_compliance")


def main() -> int:
    run = ScreenshotRun((1366, 740), settle_before_shot_s=0.0)
    window, wait_until = run.window, run.wait_until
    from fha_studio.gui.link import Servo

    window.connect_to(URL)
    wait_until(lambda: window.link.connected, "the connection", 20.0)
    window.link.send(Servo(True))
    wait_until(lambda: window.link.status is not None and window.link.status.servo_on, "servo-ON", 20.0)
    page = window.show_page("tuning")
    page.load_spin.setValue(0.81)
    page.show_plan()
    wait_until(page.start_button.isEnabled, "the excitation's plan", 30.0)
    done: list[object] = []
    page.sigMeasured.connect(done.append)
    print("measuring", flush=True)
    page.measure()
    wait_until(lambda: done, "the measurement", 120.0)
    proposed: list[object] = []
    page.sigProposed.connect(proposed.append)
    page.propose()
    wait_until(lambda: proposed, "the proposed gains", 120.0)
    run.shot("tuning")
    window.link.send(Servo(False))
    wait_until(lambda: not window.link.servo_on, "servo-OFF")
    run.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
