"""The simulated drive's command table: one handler per CN3 command, keyed by
:class:`fha_studio.hardware.protocol.Command` (docs/protocol.md says what each does).

A handler gets the drive and the command's integer value and returns the reply's data lines
(None: none, a string: one line), or :data:`DEFERRED` when the reply comes later (OWW). It
raises :class:`SimRefused` to answer ``s`` or ``x``. :meth:`SimDrive.execute` holds the drive's
lock while a handler runs.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from enum import Enum
from typing import TYPE_CHECKING, Final

from fha_studio import __version__ as _version
from fha_studio.hardware.parameters import Mode
from fha_studio.hardware.protocol import Command, encode_packed_block, mask_items
from fha_studio.hardware.sim.reply import SimRefused, rejected

if TYPE_CHECKING:
    from fha_studio.hardware.sim.drive import SimDrive


class _Deferred(Enum):
    DEFERRED = "deferred"


#: A handler's result meaning "the reply comes later" (see :meth:`SimDrive.take_deferred_replies`).
DEFERRED: Final = _Deferred.DEFERRED

HandlerResult = str | Sequence[str] | _Deferred | None
Handler = Callable[["SimDrive", int], HandlerResult]

IDENTIFICATION = f"FHA Studio simulated drive {_version}"


def _dgr(d: SimDrive, value: int) -> str:
    if d.servo_on:
        raise SimRefused("s", "DGR: the servo is on")
    if not d.absolute_encoder:
        raise rejected("DGR: the encoder is incremental")
    return str(d.absolute_counts)


def _oww(d: SimDrive, value: int) -> _Deferred:
    d.clear_multi_turn()
    return DEFERRED


def _idn(d: SimDrive, value: int) -> list[str]:
    return [d.driver, d.actuator_code, IDENTIFICATION]


def _cap(d: SimDrive, value: int) -> str:
    return " ".join(d.capabilities())


def _selector(mode: Mode) -> Handler:
    def select(d: SimDrive, value: int) -> None:
        d.select_item(mode, value)

    return select


def _prd(d: SimDrive, value: int) -> str:
    if d.selected_item is None:
        raise rejected("PRD: no item selected (PSL/TSL first)")
    return str(d.read_parameter(*d.selected_item))


def _pwr(d: SimDrive, value: int) -> None:
    if d.selected_item is None:
        raise rejected("PWR: no item selected (PSL/TSL first)")
    d.write_parameter(*d.selected_item, value)


def _mon(d: SimDrive, value: int) -> str:
    return str(d.monitor(value))


def _mmr(d: SimDrive, value: int) -> str:
    if value <= 0 or value >= 1 << 16:
        raise rejected(f"MMR: mask {value} selects no monitor item 100-115")
    items = mask_items(value)
    return ",".join(str(d.monitor(i)) for i in items)


def _svo(d: SimDrive, value: int) -> None:
    if value not in (0, 1):
        raise rejected(f"SVO {value}: 1 on, 0 off")
    d.set_servo(bool(value))


def _jog(d: SimDrive, value: int) -> None:
    d.jog(value / 100.0)


def _spd(d: SimDrive, value: int) -> None:
    d.set_move_speed(value / 100.0)


def _mov(d: SimDrive, value: int) -> None:
    d.move_by(value / 100.0)


def _stp(d: SimDrive, value: int) -> None:
    d.stop()


def _alm(d: SimDrive, value: int) -> str:
    return str(d.alarm)


def _ahs(d: SimDrive, value: int) -> list[str]:
    return [f"{a.code},{round(a.seconds_since_power_on)}" for a in d.alarm_history]


def _acl(d: SimDrive, value: int) -> None:
    d.clear_alarm()


def _ios(d: SimDrive, value: int) -> str:
    return str(d.io_bits())


def _inp(d: SimDrive, value: int) -> None:
    d.set_inputs(value)


def _pwc(d: SimDrive, value: int) -> None:
    d.power_cycle()


def _tch(d: SimDrive, value: int) -> None:
    d.trace.set_channels(value)


def _tdv(d: SimDrive, value: int) -> None:
    d.trace.set_divider(value)


def _ttg(d: SimDrive, value: int) -> None:
    d.trace.set_trigger(value)


def _ttc(d: SimDrive, value: int) -> None:
    d.trace.set_trigger_channel(value)


def _ttl(d: SimDrive, value: int) -> None:
    d.trace.set_trigger_level(value)


def _tpr(d: SimDrive, value: int) -> None:
    d.trace.set_pretrigger(value)


def _tar(d: SimDrive, value: int) -> None:
    d.trace.arm(value)


def _tst(d: SimDrive, value: int) -> str:
    state, count = d.trace.status()
    return f"{state},{count}"


def _trb(d: SimDrive, value: int) -> list[str]:
    return [",".join(str(v) for v in row) for row in d.trace.block(value)]


def _trp(d: SimDrive, value: int) -> list[str]:
    return encode_packed_block(d.trace.block(value))


def _flt(d: SimDrive, value: int) -> None:
    d.raise_alarm(value)


def _sensor(which: str) -> Handler:
    def move(d: SimDrive, value: int) -> None:
        d.set_sensor_angle(which, value / 100.0)

    return move


def _snq(d: SimDrive, value: int) -> str:
    return ",".join(str(round(a * 100)) for a in (d.origin_deg, d.ls1_deg, d.ls2_deg))


#: Every command the simulated drive speaks, with its handler.
COMMANDS: Mapping[Command, Handler] = {
    Command.DGR: _dgr,
    Command.OWW: _oww,
    Command.IDN: _idn,
    Command.CAP: _cap,
    Command.PSL: _selector(Mode.SYSTEM),
    Command.TSL: _selector(Mode.TUNE),
    Command.JSL: _selector(Mode.TEST),
    Command.PRD: _prd,
    Command.PWR: _pwr,
    Command.MON: _mon,
    Command.MMR: _mmr,
    Command.SVO: _svo,
    Command.JOG: _jog,
    Command.SPD: _spd,
    Command.MOV: _mov,
    Command.STP: _stp,
    Command.ALM: _alm,
    Command.AHS: _ahs,
    Command.ACL: _acl,
    Command.IOS: _ios,
    Command.INP: _inp,
    Command.PWC: _pwc,
    Command.TCH: _tch,
    Command.TDV: _tdv,
    Command.TTG: _ttg,
    Command.TTC: _ttc,
    Command.TTL: _ttl,
    Command.TPR: _tpr,
    Command.TAR: _tar,
    Command.TST: _tst,
    Command.TRB: _trb,
    Command.TRP: _trp,
    Command.FLT: _flt,
    Command.SNO: _sensor("origin"),
    Command.SNA: _sensor("ls1"),
    Command.SNB: _sensor("ls2"),
    Command.SNQ: _snq,
}

#: What a drive of the public HA-655 manual speaks (the ``documented`` profile): DGR and OWW.
DOCUMENTED_ONLY: Mapping[Command, Handler] = {c: COMMANDS[c] for c in (Command.DGR, Command.OWW)}

__all__ = ["COMMANDS", "DEFERRED", "DOCUMENTED_ONLY", "IDENTIFICATION", "Handler", "HandlerResult"]
