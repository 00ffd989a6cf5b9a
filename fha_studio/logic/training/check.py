"""``fha-studio training check``: does each hidden fault of a scenario show through the ordinary
client? The same walk a trainee would make (alarm, parameters 6 and 8, absolute position, sensor
dogs, brake release, a short jog each way with the current watched) is made on the drive without
the fault and on the drive with it; what differs is what the trainee can observe.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable
from dataclasses import dataclass

from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.errors import LinkError
from fha_studio.hardware.parameters import MonitorItem
from fha_studio.hardware.protocol import ABSOLUTE_COUNTS_PER_TURN
from fha_studio.logic.training.scenario import Fault, Scenario

JOG_SPEED_RPM = 5.0  # output speed of the check's jogs: slow, as a first jog is
JOG_S = 0.6  # how long each jog of the check lasts [s]
KEEPALIVE_S = 0.04  # JOG repeated well inside the drive's 100 ms watchdog
AMPS_PER_MA = 0.001


@dataclass(frozen=True)
class Observed:
    """One thing the walk saw, as a person would say it; ``number`` and ``tolerance`` (absolute)
    for a measured value that may scatter a little between two runs."""

    text: str
    number: float | None = None
    tolerance: float = 0.0

    def differs(self, other: Observed) -> bool:
        if self.number is not None and other.number is not None:
            scale = max(self.tolerance, 0.2 * max(abs(self.number), abs(other.number)))
            return abs(self.number - other.number) > scale
        return self.text != other.text


@dataclass(frozen=True)
class FaultCheck:
    """Whether ``fault`` showed, and what differed from the same drive without it."""

    fault: Fault
    differences: tuple[tuple[str, str, str], ...]  # (what, without the fault, with it)

    @property
    def observable(self) -> bool:
        return bool(self.differences)


def _try(out: dict[str, Observed], name: str, read: Callable[[], Observed]) -> None:
    try:
        out[name] = read()
    except LinkError as exc:  # a refusal is itself what a trainee sees
        out[name] = Observed(f"refused ({type(exc).__name__.replace('Refused', ' refused').strip()})")


def walk(url: str) -> dict[str, Observed]:
    """The walk on the drive at ``url`` (a ``sim://`` address): name -> what was seen."""
    out: dict[str, Observed] = {}
    client = DriveClient.open(url)
    try:
        caps = client.capabilities
        out["What the drive answers"] = Observed(caps.level.name.lower().replace("_", " "))
        if caps.parameters:
            _try(out, "Alarm at power-on", lambda: Observed(str(client.alarm()) or "none"))
            _try(
                out,
                "Parameter 6 (position error allowance)",
                lambda: Observed(str(client.read_parameter("system", 6))),
            )
            _try(
                out,
                "Parameter 8 (rotary direction)",
                lambda: Observed(str(client.read_parameter("system", 8))),
            )
            _try(
                out,
                "Sensor dogs (origin, limit 1, limit 2)",
                lambda: Observed(", ".join(f"{v:.0f} deg" for v in client.sensor_angles().values())),
            )
            _try(
                out,
                "Brake released with its 24 V switched on",
                lambda: Observed("yes" if client.set_inputs(brake_released=True).brake_released else "no"),
            )
        _try(
            out,
            "Absolute position at power-on (motor turns)",
            lambda: Observed(str(round(client.absolute_position() / ABSOLUTE_COUNTS_PER_TURN))),
        )
        if caps.can_move and client.alarm() == 0:
            _jogs(client, out)
    finally:
        client.close()
    return out


def _jogs(client: DriveClient, out: dict[str, Observed]) -> None:
    client.servo(True)
    try:
        time.sleep(0.2)
        # the 10 ms mean: one instantaneous sample carries the quantised encoder's dither
        holding = client.read_monitor(MonitorItem.MOTOR_CURRENT_MEAN) * AMPS_PER_MA
        out["Current holding still (A)"] = Observed(f"{holding:.2f}", holding, 0.25)
        for name, sign in (("FWD", 1.0), ("REV", -1.0)):
            start = client.read_monitor(MonitorItem.LOAD_POSITION)
            peak = steady = 0.0
            t0 = time.monotonic()
            while (elapsed := time.monotonic() - t0) < JOG_S:
                try:
                    client.jog(sign * JOG_SPEED_RPM)
                except LinkError:
                    break
                both = client.read_monitors((MonitorItem.MOTOR_CURRENT, MonitorItem.MOTOR_CURRENT_MEAN))
                peak = max(peak, abs(both[MonitorItem.MOTOR_CURRENT]) * AMPS_PER_MA)
                if elapsed > JOG_S / 2:
                    steady = abs(both[MonitorItem.MOTOR_CURRENT_MEAN]) * AMPS_PER_MA
                time.sleep(KEEPALIVE_S)
            client.stop()
            time.sleep(0.25)
            moved = client.read_monitor(MonitorItem.LOAD_POSITION) - start
            way = "did not turn" if abs(moved) < 50 else ("turned CW" if moved > 0 else "turned CCW")
            out[f"A {name} jog"] = Observed(way)
            out[f"Alarm after the {name} jog"] = Observed(str(client.alarm()) or "none")
            out[f"Peak current starting the {name} jog (A)"] = Observed(f"{peak:.2f}", peak, 0.3)
            out[f"Current at {name} jog speed (A)"] = Observed(f"{steady:.2f}", steady, 0.25)
            if client.alarm():
                break
    finally:
        with contextlib.suppress(LinkError):  # an alarm may have switched it off already
            client.servo(False)


def check_fault(scenario: Scenario, fault: Fault, baseline: dict[str, Observed] | None = None) -> FaultCheck:
    """Walk the drive without and with ``fault`` (the scenario's other faults left out)."""
    before = baseline if baseline is not None else walk(scenario.sim_url((), paced="0"))
    after = walk(scenario.sim_url((fault,), paced="0"))
    differences = []
    for name, seen in after.items():
        was = before.get(name)
        if was is None or seen.differs(was):
            differences.append((name, was.text if was is not None else "not seen", seen.text))
    for name, was in before.items():
        if name not in after:
            differences.append((name, was.text, "not seen"))
    return FaultCheck(fault, tuple(differences))


def check_scenario(scenario: Scenario) -> list[FaultCheck]:
    """Every fault of ``scenario`` on its own against the drive without faults."""
    baseline = walk(scenario.sim_url((), paced="0"))
    return [check_fault(scenario, fault, baseline) for fault in scenario.faults]


__all__ = ["FaultCheck", "Observed", "check_fault", "check_scenario", "walk"]
