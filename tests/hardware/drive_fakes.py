"""A minimal scripted drive for the client tests (the real simulated drive is tested by `sim`)."""

from __future__ import annotations

from typing import ClassVar

from fha_studio.hardware import protocol as p
from fha_studio.hardware.parameters import Mode, load_parameter_model
from fha_studio.hardware.protocol import Command, Reply, Status
from tests.support.links import FAST as FAST  # the client tests take their settings from here

OK = Reply()
X = Reply((), Status.REJECTED)
S = Reply((), Status.SERVO_ON)


class MiniDrive:
    """Just enough drive behind the codec: parameters, servo, monitors, I/O, a canned trace.

    ``override`` maps a command name to a callable(request) -> answer that takes over (faults).
    """

    SELECT: ClassVar = {Command.PSL: Mode.SYSTEM, Command.TSL: Mode.TUNE, Command.JSL: Mode.TEST}

    def __init__(self, caps=None):
        model = load_parameter_model()
        self.values = {(i.mode, i.number): i.default for i in model if i.default is not None}
        self.model = model
        self.selected = None
        self.servo_on = False
        self.inputs = 0
        self.caps = caps if caps is not None else sorted(c.value for c in p.EXTENSION_COMMANDS)
        self.override = {}
        self.trace_channels = ()
        self.trace_count = 0
        self.moves = []

    def __call__(self, request):
        if isinstance(request, p.UnknownRequest):
            return X
        name = request.command.value
        if name in self.override:
            return self.override[name](request)
        if name not in self.caps and name != "CAP" and request.command not in p.DOCUMENTED_COMMANDS:
            return X
        return self.handle(request.command, request.value)

    def handle(self, c, v):
        if c is Command.CAP:
            return Reply((" ".join(self.caps),))
        if c is Command.IDN:
            return Reply(("HA-655-2-200", "FHA-17C-50-US250", "mini 0.1"))
        if c is Command.DGR:
            return S if self.servo_on else Reply(("-8193",))
        if c is Command.OWW:
            return [0.2, OK]
        if c in self.SELECT:
            if (self.SELECT[c], v) not in self.values:
                return X
            self.selected = (self.SELECT[c], v)
            return OK
        if c is Command.PRD:
            return X if self.selected is None else Reply((str(self.values[self.selected]),))
        if c is Command.PWR:
            if self.selected is None:
                return X
            if self.selected[0] is Mode.SYSTEM and self.servo_on:
                return S
            try:
                self.model.item(*self.selected).check(v)
            except ValueError:
                return X
            self.values[self.selected] = v
            return OK
        if c is Command.MON:
            return Reply((str(1000 + v),))
        if c is Command.MMR:
            return Reply((p.format_values(1000 + i for i in p.mask_items(v)),)) if v else X
        if c is Command.SVO:
            self.servo_on = bool(v)
            return OK
        if c in (Command.JOG, Command.SPD, Command.STP, Command.ACL, Command.PWC):
            return OK
        if c in (Command.FLT, Command.SNO, Command.SNA, Command.SNB):
            self.moves.append((c.value, v))
            return OK
        if c is Command.SNQ:
            return Reply(("0,-9000,9000",))
        if c is Command.MOV:
            self.moves.append(v)
            return OK
        if c is Command.ALM:
            return Reply(("0",))
        if c is Command.AHS:
            return Reply(("60,12", "20,3"))
        if c is Command.IOS:
            return Reply((str(self.inputs | (1 if self.servo_on else 0) | p.io_with_alm_bits(0, 0b0010)),))
        if c is Command.INP:
            self.inputs = v
            return OK
        if c is Command.TCH:
            self.trace_channels = tuple(p.mask_items(v))
            return OK
        if c in (Command.TDV, Command.TTG, Command.TTC, Command.TTL, Command.TPR):
            return OK
        if c is Command.TAR:
            self.trace_count = v
            return OK
        if c is Command.TST:
            return Reply((p.format_values([3 if self.trace_count else 0, self.trace_count]),))
        if c in (Command.TRB, Command.TRP):
            first = v * p.TRACE_BLOCK_SAMPLES
            width = len(self.trace_channels)
            rows = [[i * 10 + k for k in range(width)]
                    for i in range(first, min(first + p.TRACE_BLOCK_SAMPLES, self.trace_count))]
            if c is Command.TRP:
                return Reply(tuple(p.encode_packed_block(rows)))
            return Reply(tuple(p.format_values(row) for row in rows))
        return X
