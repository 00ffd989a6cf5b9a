"""A stand-in DriveClient in memory, for GUI tests that must not depend on the simulated drive's
timing. It follows the DriveClient API (fha_studio.hardware.client) and the protocol's rules."""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass


class LinkLost(Exception):
    pass


class ServoOnRefused(Exception):
    pass


class CommandRejected(Exception):
    pass


@dataclass
class Identity:
    driver_model: str = "HA-655-2-200"
    adjusted_for: str = "FHA-25C-50-US250"
    firmware: str = "fake 1.0"


class Capabilities:
    can_jog = True
    can_monitor = True

    def describe(self) -> str:
        return "fake drive: parameters, monitors, jog, alarms"


class FakeDriveClient:
    def __init__(self, url="fake://", model=None):
        from fha_studio.hardware.parameters import load_parameter_model

        self.model = model or load_parameter_model()
        self.values = {(i.mode.value, i.number): i.default for i in self.model if i.default is not None}
        self.effective = dict(self.values)
        self.capabilities = Capabilities()
        self.closed = False
        self.servo_on = False
        self.alarm_code = 0
        self.history = []
        self.inputs = 0
        self.position = 0.0
        self.jog_speed = 0.0
        self.jog_until = 0.0
        self.t = time.monotonic()
        self.lock = threading.Lock()
        self.calls = []

    def _check(self):
        if self.closed:
            raise LinkLost("port closed")
        now = time.monotonic()
        if self.jog_speed and now < self.jog_until:
            self.position += self.jog_speed * (now - self.t) * 1000
        elif now >= self.jog_until:
            self.jog_speed = 0.0
        self.t = now

    def close(self):
        self.closed = True

    def identify(self):
        self._check()
        return Identity()

    def read_parameter(self, mode, number):
        self._check()
        return self.values[(str(mode), number)]

    def write_parameter(self, mode, number, value):
        self._check()
        key = (str(mode), number)
        item = self.model.item(mode, number)
        if str(mode) == "system" and self.servo_on:
            raise ServoOnRefused("servo on")
        item.check(value)
        old = self.values[key]
        self.values[key] = value
        if not item.restart_required:
            self.effective[key] = value
        return {
            "old": old,
            "read_back": self.values[key],
            "verified": True,
            "restart_required": item.restart_required,
        }

    def alarm(self):
        self._check()
        return self.alarm_code

    def alarm_history(self):
        self._check()
        return list(self.history)

    def raise_alarm(self, code):
        self.alarm_code = code
        self.servo_on = False
        self.history.insert(0, (code, 123.0))

    def clear_alarm(self):
        self._check()
        if self.alarm_code not in (0, 20, 60):
            raise CommandRejected("needs a power cycle")
        self.alarm_code = 0

    def io_state(self):
        self._check()
        bits = int(self.servo_on) | (1 << 1) | (bool(self.alarm_code) << 2) | self.inputs
        if self.jog_speed:
            bits |= 1 << 15
        return bits

    def read_monitors(self, items):
        self._check()
        return {100: int(self.position), 103: self.jog_speed, 104: 0.5 if self.jog_speed else 0.0}

    def servo(self, on):
        self._check()
        if on and self.alarm_code:
            raise CommandRejected("alarm active")
        self.servo_on = bool(on)

    def jog(self, speed_rpm):
        self._check()
        if not self.servo_on:
            raise CommandRejected("servo off")
        self.calls.append(("jog", speed_rpm))
        self.jog_speed = speed_rpm
        self.jog_until = time.monotonic() + 0.1

    def stop(self):
        self._check()
        self.calls.append(("stop",))
        self.jog_speed = 0.0

    def set_move_speed(self, speed_rpm):
        self._check()

    def move_by(self, angle_deg):
        self._check()
        if not self.servo_on:
            raise CommandRejected("servo off")
        self.position += angle_deg / 360 * 1_000_000

    def power_cycle(self):
        self._check()
        if self.servo_on:
            raise ServoOnRefused("servo on")
        self.effective = dict(self.values)
        if self.alarm_code:
            self.alarm_code = 0
