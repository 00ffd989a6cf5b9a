"""Scripted drives for the scope tests (the simulated drive is tested by `sim`)."""

from __future__ import annotations

from fha_studio.hardware import protocol as p
from fha_studio.hardware.client import LinkSettings

FAST = LinkSettings(response_timeout_s=0.08, retries=0, max_consecutive_failures=50)
OK = p.Reply()
X = p.Reply((), p.Status.REJECTED)
S = p.Reply((), p.Status.SERVO_ON)


class MonitorDrive:
    """Answers CAP, MMR and the trace commands from fixed numbers; ``silent`` drops requests."""

    def __init__(self, caps: str = "MON MMR IOS TCH TDV TTG TTC TTL TPR TAR TST TRB"):
        self.caps = caps
        self.monitors = {100: 500_000, 101: 250_000, 103: -1234, 104: 1500, 106: 0b1001}
        self.silent = False
        self.trace: dict[str, int] = {}
        self.trace_rows: list[tuple[int, ...]] = []

    def __call__(self, request):
        if self.silent or isinstance(request, p.UnknownRequest):
            return None
        c, v = request.command, request.value
        if c is p.Command.CAP:
            return p.Reply((self.caps,))
        if c is p.Command.DGR:
            return p.Reply(("0",))
        if c is p.Command.MMR:
            return p.Reply((p.format_values(self.monitors.get(i, 0) for i in p.mask_items(v)),))
        if c.value in ("TCH", "TDV", "TTG", "TTC", "TTL", "TPR", "TAR"):
            self.trace[c.value] = v
            return OK
        if c is p.Command.TST:
            return p.Reply((p.format_values([3, len(self.trace_rows)]),))
        if c is p.Command.TRB:
            first = v * p.TRACE_BLOCK_SAMPLES
            rows = self.trace_rows[first:first + p.TRACE_BLOCK_SAMPLES]
            return p.Reply(tuple(p.format_values(r) for r in rows)) if rows else X
        return X
