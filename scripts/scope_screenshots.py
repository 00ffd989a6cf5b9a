"""Screenshots of the scope page in the real main window against the embedded simulated drive.

Run: xvfb-run -a -s "-screen 0 1366x768x24" python scripts/scope_screenshots.py [OUTDIR]
(the images in docs/screenshots/scope-*.png come from it; OUTDIR defaults to docs/screenshots).
Settings and data go to a temporary directory, never the user's (as the tests' and the other
screenshot scripts')."""
import os
import sys
import tempfile
import time
from pathlib import Path

TMP = tempfile.mkdtemp(prefix="fha-scope-shots-")
os.environ["XDG_CONFIG_HOME"] = f"{TMP}/config"
os.environ["XDG_DATA_HOME"] = f"{TMP}/data"
os.environ.pop("FHA_STUDIO_REGISTER", None)

from PySide6.QtCore import QCoreApplication, QEventLoop, QTimer  # noqa: E402
from PySide6.QtWidgets import QApplication  # noqa: E402

from fha_studio.hardware import protocol as p  # noqa: E402

OUT = sys.argv[1] if len(sys.argv) > 1 else str(Path(__file__).resolve().parents[1] / "docs" / "screenshots")
app = QApplication([])
QCoreApplication.setOrganizationName("FHA Studio Shots")
from fha_studio.gui.link import LinkController, MoveBy, Servo, SetMoveSpeed  # noqa: E402
from fha_studio.gui.main_window import MainWindow  # noqa: E402


def run(seconds):
    loop = QEventLoop()
    QTimer.singleShot(int(seconds * 1000), loop.quit)
    loop.exec()


def wait_until(cond, timeout=20.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if cond():
            return True
        run(0.05)
    raise TimeoutError(cond)


url = "sim://FHA-25C-50-US250?load_inertia=0.5&effects=kinematic_error:amplitude_arcsec=40,cycles_per_motor_rev=2"
link = LinkController()
w = MainWindow(link)
link.setParent(w)
w.resize(1366, 768)
w.show()
w.connect_to(url)
wait_until(lambda: link.connected)
page = w.show_page("scope")
view = page.view
view.load_inertia.setValue(0.5)
wait_until(lambda: page.controller.connected)
run(0.5)
view.start_live()
wait_until(lambda: view.indicator_text() == "LIVE")
link.send(Servo(True))
wait_until(lambda: link.servo_on)
view.time_base.setCurrentIndex(view.time_base.findData(10.0))
panel = page.jog_panel  # the scope's own Move panel, as a technician jogs while watching
panel.speed_spin.setValue(30.0)
panel.fwd_button.sigHeld.emit()
run(2.5)
panel.fwd_button.sigReleased.emit()
run(1.5)
panel.speed_spin.setValue(15.0)
panel.rev_button.sigHeld.emit()
run(2.0)
panel.rev_button.sigReleased.emit()
run(2.0)
view.set_cursors(*(lambda r: (r[0] + 4.0, r[0] + 6.5))(view.time_plot.x_range()))
run(0.3)
w.grab().save(f"{OUT}/scope-live.png")
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
run(0.5)
view.set_cursors(0.0, 0.3)
run(0.3)
w.grab().save(f"{OUT}/scope-trace.png")
view.cursors_box.setChecked(False)

# the move test
view.test_angle.setValue(30.0)
view.test_speed.setValue(20.0)
view.run_test("move")
wait_until(lambda: view.last_test is not None, timeout=180)
run(0.5)
side = next(t for t in view.findChildren(type(view.plots)) if t is not view.plots)
side.setCurrentIndex(1)
run(0.3)
w.grab().save(f"{OUT}/scope-move-test.png")

# spectrum of a constant-speed trace (kinematic error)
view.trigger_kind.setCurrentIndex(view.trigger_kind.findData(p.TriggerKind.IMMEDIATE))
view.trace_samples.setValue(2048)
view.trace_rate.setValue(1000)
keys = ("load_position", "feedback_position", "output_speed", "error_pulses")
for box, key in zip(view.trace_channels, keys, strict=True):
    box.setCurrentIndex(max(0, box.findData(key)))
link.jog_press(10.0)
run(1.5)
view.last_trace = None
view.arm_trace()
wait_until(lambda: view.last_trace is not None, timeout=180)
link.jog_release()
view.spectrum_channel.setCurrentIndex(view.spectrum_channel.findData("load_position"))
view.spectrum_panel.spectrum_detrend.setCurrentIndex(0)
view.compute_spectrum()
run(0.5)
w.grab().save(f"{OUT}/scope-spectrum.png")
print("peaks:", view.spectrum_label.text())
print("test:", view.last_test.describe())
w._closing_confirmed = True
w.shutdown()
w.close()
