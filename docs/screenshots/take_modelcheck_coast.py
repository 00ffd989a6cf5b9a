"""Takes the model-check screenshots of a bench capture without current that ends in a coast: an
FHA-17C with the catalogue's friction, the controller's moves captured on CN2 by a logic analyzer
(encoder, command pulses, IN-POS and the ALARM line), then alarm 60 at 15 r/min and the
de-energised axis coasting; imported as ``fha-studio bench import`` does and opened on the Model
check page with its load inertia declared (tests/modelcheck/bench_capture_gen.py makes it).

    xvfb-run -a -s "-screen 0 1366x768x24" python docs/screenshots/take_modelcheck_coast.py [OUTDIR]

Settings and data go to a temporary directory, never the user's.
"""

from __future__ import annotations

import sys
from pathlib import Path

from shots import ROOT, ScreenshotRun, private_folder

TMP = private_folder()
CODE = "FHA-17C-50-US250"
LOAD_INERTIA_KGM2 = 0.5
#: the speed loop's crossover with the load (Hz), as a technician tunes this axis
CROSSOVER_HZ = 30.0


def main() -> int:
    sys.path.insert(0, str(ROOT / "tests" / "modelcheck"))
    from bench_capture_gen import BenchAxis, BenchCase, make_capture

    from fha_studio.physics import AxisModel, PanelGains
    from fha_studio.recording import write_recording

    gain = PanelGains.speed_loop_gain_for(AxisModel.from_code(CODE, load_inertia_kgm2=LOAD_INERTIA_KGM2),
                                          CROSSOVER_HZ)
    axis = BenchAxis(CODE, LOAD_INERTIA_KGM2, preset=f"tune.0={round(gain)}")
    case = BenchCase(axis, catalogue_friction=True, coast_s=0.8, coast_rpm=15.0)
    captured = make_capture(case, Path(TMP) / "bench")
    path = Path(TMP) / "move-and-coast.csv"
    write_recording(path, captured.recording)
    # the capture under the name a technician gives it (the generator names it after the case)
    capture = captured.capture.rename(Path(TMP) / "move-and-coast.sr")
    text = path.read_text(encoding="utf-8").replace(str(captured.capture), str(capture))
    path.write_text(text, encoding="utf-8")

    run = ScreenshotRun((1366, 740), settle_before_shot_s=0.0)
    window = run.window
    window.session.state.set_load_inertia(LOAD_INERTIA_KGM2)
    page = window.show_page("modelcheck")
    page.load_recording(path)
    finished: list[object] = []
    page.sigFinished.connect(finished.append)
    page.run()
    run.wait_until(lambda: finished, "the model check's result", 120.0)
    for index, name in ((2, "modelcheck-coast-effects"), (3, "modelcheck-coast-gap")):
        page.steps.setCurrentIndex(index)
        run.settle(0.2)
        run.shot(name)
    run.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
