"""`SimResponder`: the simulated drive's face on CN3 (docs/protocol.md says what each command does).

It takes a decoded request (:class:`fha_studio.hardware.protocol.Request`, or an
:class:`~fha_studio.hardware.protocol.UnknownRequest` for three letters that name no command)
and returns a :class:`SimReply` carrying the terminal :class:`~fha_studio.hardware.protocol.Status`.
It owns everything of the protocol that is not the drive itself:

- the command table, one handler per :class:`Command`, and its narrowing by the drive's profile
  (``documented``: DGR and OWW only, ``s`` to everything while the servo is on; a drive from
  before the packed trace encoding: no TRP), and so what CAP lists;
- the item PSL / TSL / JSL selected for PRD and PWR;
- replies that come later than their command (OWW's ``q``, :meth:`SimResponder.take_deferred_replies`);
- a training drive's journal: every command and panel action with the drive's state before it.

The :class:`SimDrive` it holds speaks units (r/min, degrees, item values): the handlers turn the
wire's integers into those and the drive's answers back into data lines. A handler returns the
reply's data lines (None: none, a string: one line) or :data:`DEFERRED`; it raises
:class:`SimRefused` to answer ``s`` or ``x``. Every command runs under the drive's lock.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from enum import Enum
from typing import Final

from fha_studio import __version__ as _version
from fha_studio import clock
from fha_studio.hardware.api import IoState, SensorName
from fha_studio.hardware.parameters import Mode
from fha_studio.hardware.protocol import (
    DOCUMENTED_COMMANDS,
    EXTENSION_COMMANDS,
    INPUT_MASK,
    Command,
    IoBit,
    Request,
    Status,
    UnknownRequest,
    encode_packed_block,
    mask_items,
)
from fha_studio.hardware.sim import excitation
from fha_studio.hardware.sim.drive import SimDrive
from fha_studio.hardware.sim.journal import Journal, JournalEntry, PanelAction
from fha_studio.hardware.sim.memory import ItemId
from fha_studio.hardware.sim.monitors import monitor_wire
from fha_studio.hardware.sim.options import Profile, SimConfigError, training_registration
from fha_studio.hardware.sim.reply import SimRefused, SimReply, rejected, servo_is_on
from fha_studio.hardware.sim.trace import TraceError


class _Deferred(Enum):
    DEFERRED = "deferred"


#: A handler's result meaning "the reply comes later" (see :meth:`SimResponder.take_deferred_replies`).
DEFERRED: Final = _Deferred.DEFERRED

HandlerResult = str | Sequence[str] | _Deferred | None
Handler = Callable[["SimResponder", int], HandlerResult]

IDENTIFICATION = f"FHA Studio simulated drive {_version}"


@dataclass(frozen=True)
class _Before:
    """The drive's state a journal entry records from before the action."""

    item: ItemId | None
    servo_on: bool
    brake_holding: bool
    blocked_fwd: bool
    blocked_rev: bool
    alarm: int


class SimResponder:
    """Answers CN3 requests for one :class:`SimDrive` (see the module docstring)."""

    def __init__(self, drive: SimDrive):
        self.drive = drive
        config = drive.config
        table = COMMANDS
        if not config.packed_trace:  # a drive from before the packed encoding: no TRP
            table = {c: h for c, h in table.items() if c is not Command.TRP}
        if config.profile is Profile.DOCUMENTED:
            table = DOCUMENTED_ONLY
        #: The commands this drive speaks and their handlers.
        self.command_table: Mapping[Command, Handler] = table
        # a training drive writes what is done to it in its registration's journal
        registration = training_registration(config.training) if config.training else None
        self.journal: Journal | None = registration.journal if registration is not None else None
        self.selected_item: ItemId | None = None  # the item PSL / TSL / JSL selected
        self._clears_answered = drive.multi_turn_clears_done

    @property
    def documented_only(self) -> bool:
        """True for the ``documented`` profile: DGR and OWW only, ``s`` to all while the servo is on."""
        return self.command_table is DOCUMENTED_ONLY

    def capabilities(self) -> list[Command]:
        """The extension commands this drive answers (CAP), in the codec's order."""
        return [c for c in Command if c in EXTENSION_COMMANDS and c in self.command_table]

    # ------------------------------------------------------------------ CN3
    def respond(self, request: Request | UnknownRequest) -> SimReply | None:
        """Do one decoded request. Returns its reply, or None when the reply comes later (OWW:
        see :meth:`take_deferred_replies`). An unknown command does nothing and is not journaled."""
        with self.drive.lock:
            if isinstance(request, UnknownRequest):
                return self._refuse_unknown(request.name)
            if self.journal is None:
                return self._answer(request)
            before = self._before()
            reply = self._answer(request)
            self._write(request.command, request.value, reply.terminal if reply is not None else None, before)
            return reply

    def take_deferred_replies(self) -> list[SimReply]:
        """Replies that came later than their command (OWW's ``q``), oldest first."""
        with self.drive.lock:
            done = self.drive.multi_turn_clears_done
            finished, self._clears_answered = done - self._clears_answered, done
            return [SimReply(Status.DONE)] * finished

    def _refuse_unknown(self, name: str) -> SimReply:
        if self.documented_only and self.drive.servo_on:
            # HA-655 manual p.21: with the servo on the drive processes nothing over CN3
            return SimReply(Status.SERVO_ON, reason=f"{name}: the servo is on (CN2)")
        return SimReply(Status.REJECTED, reason=f"unknown command {name}")

    def _answer(self, request: Request) -> SimReply | None:
        command = request.command
        handler = self.command_table.get(command)
        if handler is None or (self.documented_only and self.drive.servo_on):
            return self._refuse_unknown(command.value)
        try:
            result = handler(self, request.value)
        except SimRefused as exc:
            return SimReply(exc.terminal, reason=exc.reason)
        except (TraceError, SimConfigError) as exc:
            return SimReply(Status.REJECTED, reason=str(exc))
        if result is DEFERRED:
            return None
        if result is None:
            return SimReply(Status.DONE)
        if isinstance(result, str):
            return SimReply(Status.DONE, (result,))
        return SimReply(Status.DONE, tuple(result))

    def select(self, mode: Mode, number: int) -> None:
        """PSL / TSL / JSL: the item PRD reads and PWR writes; ``x`` for one the drive does not have."""
        self.selected_item = self.drive.item_id(mode, number)

    # ------------------------------------------------------------------ the panel (outside CN3)
    # (an api.SimPanel: what the GUI's panel and ``fha-studio sim --panel`` do)
    @property
    def has_sensors(self) -> bool:
        """The actuator has option L (origin sensor, limit switches)."""
        return self.drive.has_sensors

    def io_state(self) -> IoState:
        """The I/O bits as the drive's indicators show them."""
        return IoState(self.drive.io_bits())

    def release_brake(self, released: bool) -> None:
        """24 V on the brake (released) or not (it holds); the other inputs stay as they are."""
        bit = 1 << IoBit.BRAKE_RELEASED
        with self.drive.lock:
            others = self.drive.io_bits() & INPUT_MASK & ~bit
            self.drive.set_inputs(others | (bit if released else 0))

    def set_servo(self, on: bool) -> None:
        """The controller's servo-ON input on CN2 (any profile; the only way with ``documented``)."""
        self.drive.set_servo(on)

    def controller_command(self, angle_deg: float) -> None:
        """The controller's pulse train on CN2 (:meth:`SimDrive.controller_command`), journaled."""
        drive = self.drive
        with drive.lock:
            if self.journal is None:
                drive.controller_command(angle_deg)
                return
            before = self._before()
            terminal = Status.DONE
            try:
                drive.controller_command(angle_deg)
            except SimRefused as exc:
                terminal = exc.terminal
                raise
            finally:
                self._write(PanelAction.CN2_MOVE, round(angle_deg), terminal, before)

    def turn_by_hand(self, angle_deg: float) -> None:
        """The output turned by hand (:meth:`SimDrive.turn_by_hand`), journaled when it turned."""
        with self.drive.lock:
            self.drive.turn_by_hand(angle_deg)
            if self.journal is not None:
                self._write(PanelAction.HAND_TURN, round(angle_deg), Status.DONE, self._before())

    # ------------------------------------------------------------------ the journal
    def _before(self) -> _Before:
        d = self.drive
        fwd, rev = d.blocked_directions()
        return _Before(self.selected_item, d.servo_on, d.brake_holding, fwd, rev, d.alarm)

    def _write(
        self, action: Command | PanelAction, value: int, terminal: Status | None, before: _Before
    ) -> None:
        if self.journal is None:
            return
        self.journal.append(JournalEntry(
            at_s=clock.now_s(), command=action, value=int(value), terminal=terminal, item=before.item,
            servo_on=before.servo_on, brake_holding=before.brake_holding,
            blocked_fwd=before.blocked_fwd, blocked_rev=before.blocked_rev,
            alarm_before=before.alarm, alarm_after=self.drive.alarm,
        ))


# ---------------------------------------------------------------------------------------------
# The handlers: wire integers -> the drive's units -> data lines
# ---------------------------------------------------------------------------------------------


def _dgr(r: SimResponder, value: int) -> str:
    d = r.drive
    if d.servo_on:
        raise servo_is_on("DGR: the servo is on")
    if not d.absolute_encoder:
        raise rejected("DGR: the encoder is incremental")
    return str(d.absolute_counts)


def _oww(r: SimResponder, value: int) -> _Deferred:
    r.drive.clear_multi_turn()
    return DEFERRED


def _idn(r: SimResponder, value: int) -> list[str]:
    return [r.drive.driver, r.drive.actuator_code, IDENTIFICATION]


def _cap(r: SimResponder, value: int) -> str:
    return " ".join(c.value for c in r.capabilities())


def _selector(mode: Mode) -> Handler:
    def select(r: SimResponder, value: int) -> None:
        r.select(mode, value)

    return select


def _selected(r: SimResponder, command: Command) -> ItemId:
    if r.selected_item is None:
        raise rejected(f"{command}: no item selected (PSL/TSL first)")
    return r.selected_item


def _prd(r: SimResponder, value: int) -> str:
    return str(r.drive.read_parameter(*_selected(r, Command.PRD)))


def _pwr(r: SimResponder, value: int) -> None:
    r.drive.write_parameter(*_selected(r, Command.PWR), value)


def _mon(r: SimResponder, value: int) -> str:
    return str(monitor_wire(r.drive, value))


def _mmr(r: SimResponder, value: int) -> str:
    if value <= 0 or value >= 1 << 16:
        raise rejected(f"MMR: mask {value} selects no monitor item 100-115")
    return ",".join(str(monitor_wire(r.drive, i)) for i in mask_items(value))


def _svo(r: SimResponder, value: int) -> None:
    if value not in (0, 1):
        raise rejected(f"SVO {value}: 1 on, 0 off")
    r.drive.set_servo(bool(value))


def _jog(r: SimResponder, value: int) -> None:
    r.drive.jog(value / 100.0)


def _spd(r: SimResponder, value: int) -> None:
    r.drive.set_move_speed(value / 100.0)


def _mov(r: SimResponder, value: int) -> None:
    r.drive.move_by(value / 100.0)


def _stp(r: SimResponder, value: int) -> None:
    r.drive.excitation.stop()
    r.drive.stop()


def _alm(r: SimResponder, value: int) -> str:
    return str(r.drive.alarm)


def _ahs(r: SimResponder, value: int) -> list[str]:
    return [f"{a.code},{round(a.seconds_since_power_on)}" for a in r.drive.alarm_history]


def _acl(r: SimResponder, value: int) -> None:
    r.drive.clear_alarm()


def _ios(r: SimResponder, value: int) -> str:
    return str(r.drive.io_bits())


def _inp(r: SimResponder, value: int) -> None:
    r.drive.set_inputs(value)


def _pwc(r: SimResponder, value: int) -> None:
    r.drive.power_cycle()


def _tch(r: SimResponder, value: int) -> None:
    r.drive.trace.set_channels(value)


def _tdv(r: SimResponder, value: int) -> None:
    r.drive.trace.set_divider(value)


def _ttg(r: SimResponder, value: int) -> None:
    r.drive.trace.set_trigger(value)


def _ttc(r: SimResponder, value: int) -> None:
    r.drive.trace.set_trigger_channel(value)


def _ttl(r: SimResponder, value: int) -> None:
    r.drive.trace.set_trigger_level(value)


def _tpr(r: SimResponder, value: int) -> None:
    r.drive.trace.set_pretrigger(value)


def _tar(r: SimResponder, value: int) -> None:
    r.drive.trace.arm(value)


def _tst(r: SimResponder, value: int) -> str:
    state, count = r.drive.trace.status()
    return f"{state},{count}"


def _trb(r: SimResponder, value: int) -> list[str]:
    return [",".join(str(v) for v in row) for row in r.drive.trace.block(value)]


def _trp(r: SimResponder, value: int) -> list[str]:
    return encode_packed_block(r.drive.trace.block(value))


def _flt(r: SimResponder, value: int) -> None:
    r.drive.raise_alarm(value)


def _sensor(which: SensorName) -> Handler:
    def move(r: SimResponder, value: int) -> None:
        r.drive.set_sensor_angle(which, value / 100.0)

    return move


def _snq(r: SimResponder, value: int) -> str:
    d = r.drive
    return ",".join(str(round(a * 100)) for a in (d.io.origin_deg, d.io.ls1_deg, d.io.ls2_deg))


def _exa(r: SimResponder, value: int) -> None:
    excitation.set_amplitude(r.drive, value)


def _exl(r: SimResponder, value: int) -> None:
    excitation.set_travel_limit(r.drive, value)


def _exg(r: SimResponder, value: int) -> None:
    excitation.run(r.drive, value)


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
    Command.SNO: _sensor(SensorName.ORIGIN),
    Command.SNA: _sensor(SensorName.LS1),
    Command.SNB: _sensor(SensorName.LS2),
    Command.SNQ: _snq,
    Command.EXA: _exa,
    Command.EXL: _exl,
    Command.EXG: _exg,
}

#: What a drive of the public HA-655 manual speaks (the ``documented`` profile): DGR and OWW.
DOCUMENTED_ONLY: Mapping[Command, Handler] = {c: h for c, h in COMMANDS.items() if c in DOCUMENTED_COMMANDS}

__all__ = ["COMMANDS", "DEFERRED", "DOCUMENTED_ONLY", "IDENTIFICATION", "Handler", "HandlerResult",
           "SimResponder"]
