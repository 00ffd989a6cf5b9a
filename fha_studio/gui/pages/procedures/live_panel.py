"""A live step of a procedure: the check asked of the drive, or what the technician saw.

"Check on the drive" runs the step's live check in the link thread (the worker's call; the page
never touches the port), says where the output is and which sensors are on while the check moves
the axis, and hands the drive's observation to the page to record. When the drive cannot tell (a
drive of the manual's commands only, no drive connected) the technician enters what they saw,
and that value is recorded, saying it was entered by hand. On the simulated drive the trainee
switches the brake's 24 V supply here, as at the machine.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from functools import partial
from typing import Any

from PySide6.QtCore import QObject, Signal, Slot
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from fha_studio.gui.link import Call, DriveStatus, LinkReply, SetInputs
from fha_studio.hardware.protocol import IoBit
from fha_studio.logic.procedures import Observation, Step

#: The sensors a live check's samples report, by I/O bit (docs/protocol.md, IOS).
_SENSOR_BITS = (
    (IoBit.LIMIT_SWITCH_1, "limit switch 1"),
    (IoBit.LIMIT_SWITCH_2, "limit switch 2"),
    (IoBit.ORIGIN_SENSOR, "origin sensor"),
)
#: How often the progress of a check that moves the axis is said [s].
PROGRESS_INTERVAL_S = 0.2


class SampleRelay(QObject):
    """Carries samples of a live check's move from the link thread to the GUI thread."""

    sigSample = Signal(float, int)  # output angle [deg], the I/O bits


def _live_check_in_link_thread(step: Step, context: Mapping[str, Any], angles: dict, relay: SampleRelay,
                               memo: dict, client) -> Observation:
    """Runs in the link thread (worker CALL). ``memo`` is kept by the panel between two presses."""
    from fha_studio.logic.procedures.live import LiveEnv, run_live_check

    env = LiveEnv(context, angles, on_sample=lambda angle, io: relay.sigSample.emit(angle, io.raw), memo=memo)
    return run_live_check(client, step, env)


class LiveCheckPanel(QWidget):
    """The inputs of a live step. ``answer`` records an observation for the current step (False
    when it was not taken); ``message`` says something on the page."""

    sigDone = Signal(object)  # Observation of a check (after it was recorded or shown), None if it failed

    def __init__(self, link, answer: Callable[[Observation], bool], message: Callable[[str], None],
                 parent: QWidget | None = None):
        super().__init__(parent)
        self.link = link
        self._answer = answer
        self._message = message
        self.relay = SampleRelay(self)
        self._asking: Step | None = None  # the step whose check the drive is running
        self._memo: dict = {}  # a live check's state between two presses (the link thread uses it)
        self._by_hand_why = ""  # why the drive cannot answer the step on show
        self._started_s = 0.0
        self._shown_s = 0.0
        layout = QVBoxLayout(self)
        row = QHBoxLayout()
        self.live_button = QPushButton("&Check on the drive")
        row.addWidget(self.live_button)
        row.addStretch(1)
        layout.addLayout(row)
        # the drive cannot tell: the technician enters what they saw, and that value is recorded
        self.by_hand_box = QWidget()
        hb = QHBoxLayout(self.by_hand_box)
        hb.setContentsMargins(0, 0, 0, 0)
        self.by_hand_edit = QLineEdit()
        self.by_hand_edit.setObjectName("by_hand_value")
        self.by_hand_result = QComboBox()
        self.by_hand_result.addItems(["as it should be", "NOT as it should be"])
        self.by_hand_button = QPushButton("Record what I &saw")
        self.by_hand_button.clicked.connect(self.answer_by_hand)
        hb.addWidget(QLabel("Seen:"))
        hb.addWidget(self.by_hand_edit, 1)
        hb.addWidget(self.by_hand_result)
        hb.addWidget(self.by_hand_button)
        self.by_hand_box.setVisible(False)
        layout.addWidget(self.by_hand_box)
        self.sim_brake_check = QCheckBox("Simulated drive: brake supply 24 V on")
        self.sim_brake_check.setObjectName("sim_brake")
        self.sim_brake_check.toggled.connect(
            lambda on: self.link.send(SetInputs({"brake_released": on})) if self.link.connected else None
        )
        layout.addWidget(self.sim_brake_check)
        self.live_label = QLabel("")
        self.live_label.setObjectName("live_result")
        self.live_label.setWordWrap(True)
        layout.addWidget(self.live_label)
        self.relay.sigSample.connect(self._progress)
        link.sigStatus.connect(self._on_status)

    @property
    def asking(self) -> bool:
        """A check is running on the drive."""
        return self._asking is not None

    def reset(self, brake_switch: bool) -> None:
        """Another step is on show: no by-hand entry yet; the brake switch when the simulated drive's
        actuator has a brake."""
        self.sim_brake_check.setVisible(brake_switch)
        self.by_hand_box.setVisible(False)

    def answered(self) -> None:
        """The step was answered: what its check kept and said belongs to it."""
        self._memo.clear()
        self.live_label.setText("")

    def run(self, step: Step, context: Mapping[str, Any], sensor_angles: Mapping[str, float]) -> None:
        """Ask the drive (in the link thread); the answer is recorded when it comes."""
        if self._asking is not None:
            return
        if not self.link.connected:
            self._message("No drive connected: connect first, or enter what you saw.")
            self.ask_by_hand(step, "no drive is connected")
            return
        self.live_label.setText("Asking the drive …")
        self._started_s = time.monotonic()
        self.live_button.setEnabled(False)
        self._asking = step
        function = partial(_live_check_in_link_thread, step, context, dict(sensor_angles), self.relay,
                           self._memo)
        self.link.send(Call(function), self._answered)

    def ask_by_hand(self, step: Step | None, why: str) -> None:
        """Show the by-hand entry for a live step the drive cannot answer, saying what to enter."""
        from fha_studio.logic.procedures.live import BY_HAND

        if step is None:
            return
        what = BY_HAND.get(step.check or "", "what you saw")
        self.by_hand_edit.setPlaceholderText(what)
        self.by_hand_edit.setToolTip(f"Enter {what}")
        self._by_hand_why = why
        self.by_hand_box.setVisible(True)

    def answer_by_hand(self) -> bool:
        """Record the value the technician entered for a live step the drive cannot answer."""
        value = self.by_hand_edit.text().strip()
        if not value:
            self._message(f"Enter {self.by_hand_edit.placeholderText()} first: it is what the record keeps.")
            return False
        passed = self.by_hand_result.currentIndex() == 0
        why = self._by_hand_why or "the drive cannot tell"
        if self._answer(Observation(value, passed, f"entered by hand ({why})")):
            self.by_hand_edit.clear()
            return True
        return False

    @Slot(float, int)
    def _progress(self, angle_deg: float, io_bits: int) -> None:
        """While a live check moves the axis (the sensor test run takes tens of seconds), say
        where the output is and which sensors are on, a few times a second."""
        now = time.monotonic()
        if self._asking is None or now - self._shown_s < PROGRESS_INTERVAL_S:
            return
        self._shown_s = now
        on = [name for bit, name in _SENSOR_BITS if io_bits >> bit & 1]
        sensors = f"; on: {', '.join(on)}" if on else "; no sensor on"
        self.live_label.setText(
            f"Running on the drive ({now - self._started_s:.0f} s): the output is at "
            f"{angle_deg:+.1f}°{sensors} …"
        )

    def _answered(self, result: LinkReply[Observation]) -> None:
        step, self._asking = self._asking, None
        self.live_button.setEnabled(True)
        if not result.ok:
            self.live_label.setText(f"The check could not run: {result.error}")
            self.sigDone.emit(None)
            return
        observation = result.answer
        self.live_label.setText(observation.detail)
        if observation.available:
            self._answer(observation)
            self.live_label.setText(observation.detail)
        else:
            self.ask_by_hand(step, observation.detail)
        self.sigDone.emit(observation)

    @Slot(object)
    def _on_status(self, status: DriveStatus) -> None:
        released = status.bit(IoBit.BRAKE_RELEASED)
        if released is not None and self.sim_brake_check.isVisible():
            self.sim_brake_check.blockSignals(True)
            self.sim_brake_check.setChecked(released)
            self.sim_brake_check.blockSignals(False)
