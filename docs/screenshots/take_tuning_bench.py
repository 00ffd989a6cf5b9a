"""Takes the README's screenshot of the Tuning page on a drive of the manual's commands (the
documented profile: CN3 silent while the servo is on), tuned from the bench: the excitation file
written, played into the simulated drive's SPD-CMD in speed mode (an FHA-25C-50 with a load of its
own inertia on the gear's spring), the capture of CN2 analysed, gains proposed for the worksheet.

    xvfb-run -a -s "-screen 0 1366x768x24" python docs/screenshots/take_tuning_bench.py [OUTDIR]

Settings and data go to a temporary directory, never the user's.
"""

from __future__ import annotations

from shots import ScreenshotRun, private_folder, users_sim_drive

TMP = private_folder()
CODE = "FHA-25C-50-US250"
URL = users_sim_drive(CODE, documented=True, paced="0")
LOAD = 0.81


def main() -> int:
    run = ScreenshotRun((1366, 740), settle_before_shot_s=0.0)
    window, wait_until = run.window, run.wait_until
    from fha_studio.hardware.sim.cn2 import record_playback
    from fha_studio.hardware.sim.drive import SimDrive
    from fha_studio.hardware.sim.options import config_from_url

    window.connect_to(URL)
    wait_until(lambda: window.link.connected, "the connection", 20.0)
    page = window.show_page("tuning")
    page.actuator_edit.setText(CODE)
    page.load_spin.setValue(LOAD)
    window.session.state.enter_front_panel("system", 0, 1, "T. Technician")  # speed mode, from the panel
    bench = page.bench
    excitation = bench.write_excitation(f"{TMP}/excitation.csv")
    print("playing the excitation on the simulated bench", flush=True)
    # the bench's axis is the window's drive (its friction too), in speed mode, on the gear's spring
    with SimDrive(CODE, load_inertia_kgm2=LOAD, effects={"torsional_compliance": {}},
                  catalogue_friction=config_from_url(URL).catalogue_friction,
                  preset=(("system", 0, 1),)) as drive:
        drive.set_servo(True)
        drive.advance(0.05)
        capture = record_playback(drive, excitation, 25000.0).write(f"{TMP}/capture.sr", "sr")
    bench.load_capture(str(capture))
    analysed: list[object] = []
    bench.sigAnalysed.connect(analysed.append)
    bench.analyse()
    wait_until(lambda: analysed, "the capture's analysis", 120.0)
    proposed: list[object] = []
    page.sigProposed.connect(proposed.append)
    page.propose()
    wait_until(lambda: proposed, "the proposed gains", 120.0)
    run.shot("tuning-bench")
    run.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
