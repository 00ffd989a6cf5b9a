"""Takes the model-check screenshots: a back-and-forth move on a simulated drive with a hidden
Coulomb friction, captured by the scope's trace and handed to the model check page.

    xvfb-run -a -s "-screen 0 1366x768x24" python docs/screenshots/take_modelcheck.py [OUTDIR]

Settings and data go to a temporary directory, never the user's.
"""

from __future__ import annotations

import time

from shots import ScreenshotRun, private_folder

TMP = private_folder()
URL = "sim://FHA-25C-50-US250?paced=0&load_inertia=0.5&effects=coulomb_friction:torque_nm=12"
#: Longest a 90° move at 20 r/min may take (it takes about 0.8 s) before the run gives up.
MOVE_DEADLINE_S = 20.0


def back_and_forth(client, deadline_s: float = MOVE_DEADLINE_S) -> None:
    """Moves 90° and back; TimeoutError when a move has not ended within ``deadline_s``."""
    client.servo(True)
    client.set_move_speed(20.0)
    for angle in (90.0, -90.0):
        client.move_by(angle)
        time.sleep(0.05)
        end = time.monotonic() + deadline_s
        while client.io_state().moving:
            if time.monotonic() > end:
                raise TimeoutError(f"the move by {angle:g}° had not ended after {deadline_s:g} s "
                                   "(the drive still says it is moving): no screenshots taken")
            time.sleep(0.02)
        time.sleep(0.15)


def main() -> int:
    run = ScreenshotRun((1366, 740), settle_before_shot_s=0.0)
    window = run.window
    from fha_studio.gui.link import Call
    from fha_studio.hardware import protocol as p

    window.connect_to(URL)
    run.wait_until(lambda: window.link.connected, "the connection to the simulated drive", 10.0)
    scope = window.show_page("scope").view
    scope.load_inertia.setValue(0.5)
    scope.trace_samples.setValue(p.TRACE_MAX_SAMPLES)
    scope.trace_pre.setValue(2)
    scope.trigger_kind.setCurrentIndex(scope.trigger_kind.findData(p.TriggerKind.IO_BIT_RISES))
    scope.trigger_channel.setCurrentIndex(scope.trigger_channel.findData("moving"))
    traced: list[object] = []
    scope.sigTraceDone.connect(traced.append)
    scope.arm_trace()
    run.settle(1.0)
    failures: list[str] = []
    window.link.send(Call(back_and_forth), lambda r: r.ok or failures.append(str(r.error)))
    run.wait_until(lambda: traced or failures, "the scope's trace of the move", 30.0)
    if not traced:
        raise TimeoutError(f"the scope's trace of the move did not come: {failures[-1]}")
    run.shot("modelcheck-capture")
    page = window.show_page("modelcheck")
    page.take_scope_capture()
    finished: list[object] = []
    page.sigFinished.connect(finished.append)
    page.run()
    run.wait_until(lambda: finished, "the model check's result", 60.0)
    for index, name in ((0, "modelcheck-residual"), (1, "modelcheck-where"), (3, "modelcheck-gap"),
                        (4, "modelcheck-resimulation"), (2, "modelcheck-effects")):
        page.steps.setCurrentIndex(index)
        run.settle(0.1)
        run.shot(name)
    run.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
