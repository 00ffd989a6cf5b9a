"""``fha-studio register sync --from FILE_OR_URL --to FILE_OR_URL``: two registers (a laptop's file
and the plant's server) brought to the same facts, both ways; ``register conflicts``: what
registers synced after they were apart disagree on; ``register resolve CONFLICT --keep N``: a
person settles one.

``sync`` exits 0 when it is done (open conflicts are for a person, not a failure), 2 when a
register cannot be opened, 3 when it stopped before it was done (a server gone in the middle):
what it moved is kept, and running it again finishes it.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from fha_studio.cli import CliError
from fha_studio.cli._values import whole
from fha_studio.logic.register.identity import BATCH_FACTS
from fha_studio.logic.register.words import when_text

#: Exit status of a sync that stopped before it was done (run it again).
STOPPED = 3


def add_actions(sub: argparse._SubParsersAction, common: argparse.ArgumentParser, opener) -> None:
    """The ``sync``, ``conflicts`` and ``resolve`` actions of ``fha-studio register``."""
    s = sub.add_parser(
        "sync",
        parents=[common],
        help="sync two registers both ways (a laptop's file and the plant's server)",
        description="Brings two registers to the same facts, both ways: what each lacks of the other's "
        "facts is copied into it, each fact once (a sync run twice, or stopped and run again, moves each "
        "fact once); with --send-only, what --to lacks of --from's, and nothing back. Machines and axes "
        "are matched by their names (machine name, axis name). An axis "
        "both registers changed while apart, on which they disagree, is a conflict in both, for a "
        f"person to settle (register conflicts, register resolve). Exit 0 when done, {STOPPED} when it "
        "stopped before (what it moved is kept: run it again).",
    )
    s.add_argument(
        "--from",
        dest="source",
        metavar="FILE_OR_URL",
        help="one register (default: this computer's, as --register chooses it)",
    )
    s.add_argument(
        "--to",
        dest="target",
        required=True,
        metavar="FILE_OR_URL",
        help="the other: the plant's server (postgresql://...) or a file (made when missing)",
    )
    s.add_argument("--operator", default="", help="who syncs (the conflicts it finds say so)")
    s.add_argument("--progress", action="store_true", help="a line on stderr for each batch of facts moved")
    s.add_argument("--batch", type=whole(1, 100_000), metavar="N",
                   help=f"facts moved in one transaction (default {BATCH_FACTS}; fewer on a slow link)")
    s.add_argument("--send-only", action="store_true",
                   help="only from --from to --to: nothing comes back (a laptop that delivers its facts "
                   "without taking a copy of the plant's)")
    s.set_defaults(func=_sync)
    c = sub.add_parser(
        "conflicts",
        parents=[common],
        help="what registers synced after they were apart disagree on",
        description="The open conflicts (or all, --all): an axis changed in two registers while they were "
        "apart (parameter values, its origin, its fields), each side's values, numbered for register "
        "resolve.",
    )
    c.add_argument("where", nargs="?", metavar="MACHINE_OR_AXIS", help="one machine, or one MACHINE/AXIS")
    c.add_argument("--all", action="store_true", help="settled ones too")
    c.set_defaults(func=_conflicts, open_register=opener)
    r = sub.add_parser(
        "resolve",
        parents=[common],
        help="settle a conflict: keep one side's values",
        description="A person settles a conflict by keeping one side (its number in register conflicts): "
        "a new fact that names the conflict; nothing is removed. A kept origin or axis field is the axis's "
        "again, kept parameter values its latest known values.",
    )
    r.add_argument("conflict", metavar="CONFLICT", help="its id (the first 8 characters do)")
    r.add_argument("--keep", type=int, required=True, metavar="N", help="the side kept: 1, 2")
    r.add_argument("--note", default="", help="why, for the register")
    r.add_argument("--operator", default="", help="who settles it")
    r.set_defaults(func=_resolve, open_register=opener)


def _print_json(data: Any) -> None:
    print(json.dumps(data, indent=2, ensure_ascii=False))


def _sync(args) -> int:
    from fha_studio.logic.register import Register, RegisterError, register_location
    from fha_studio.logic.register.sync import SyncProgress, sync_registers

    source = register_location(args.source or args.register)
    target = register_location(args.target)
    opened: list[Register] = []
    try:
        for where, create in ((source, False), (target, True)):
            opened.append(Register(where, create=create))
    except RegisterError as exc:
        for reg in opened:
            reg.close()
        raise CliError(str(exc)) from None
    show = args.progress or sys.stderr.isatty()

    def progress(p: SyncProgress) -> None:
        if show and p.stage in ("sending", "receiving"):
            print(
                f"sync: {p.done:,} of {p.total:,} facts moved ({p.stage}, batch {p.batches})",
                file=sys.stderr,
                flush=True,
            )

    try:
        result = sync_registers(opened[0], opened[1], progress=progress, who=args.operator,
                                batch_facts=args.batch or BATCH_FACTS, send_only=args.send_only)
    except RegisterError as exc:
        print(f"fha-studio register: error: sync stopped: {exc}", file=sys.stderr)
        return STOPPED
    finally:
        for reg in opened:
            reg.close()
    if args.json:
        _print_json(result.as_dict())
        return 0
    print(
        f"Synced {result.source} and {result.target}: {result.sent:,} fact(s) sent, {result.received:,} "
        f"received, {result.already_there:,} already in both."
    )
    if result.machines_added or result.axes_added:
        print(f"{result.machines_added} machine(s) and {result.axes_added} axis/axes added.")
    if result.conflicts:
        print(
            f"{len(result.conflicts)} open conflict(s) "
            "(settle each: fha-studio register resolve ID --keep N):"
        )
        for c in result.conflicts:
            new = " (found now)" if c.uid in result.found_now else ""
            print(f"{c.axis.ref}: conflict {c.short}{new}: {c.summary()}")
            print("\n".join(c.lines()))
    return 0


def _conflicts(args) -> int:
    with args.open_register(args) as reg:
        where = (args.where or "").strip()
        if "/" in where:
            found = reg.conflicts(reg.axis(where), open_only=not args.all)
        else:
            if where:
                reg.machine(where)  # a machine the register does not have is said
            found = reg.conflicts(open_only=not args.all, machine=where or None)
    if args.json:
        _print_json([c.as_dict() for c in found])
        return 0
    if not found:
        print("No open conflicts." if not args.all else "No conflicts.")
        return 0
    for c in found:
        by = f" by {c.who}" if c.who else ""
        print(
            f"{c.axis.ref} — conflict {c.short}, found {when_text(c.at_utc)} UTC{by}: {c.summary()}"
        )
        print("\n".join(c.lines()))
        for r in c.resolutions:
            note = f": {r.note}" if r.note else ""
            print(
                f"  settled: kept {r.kept} ({r.who or 'someone'}, {when_text(r.at_utc)} UTC){note}"
            )
    if not args.all:
        print("Settle one: fha-studio register resolve ID --keep N [--note WHY] [--operator NAME]")
    return 0


def _resolve(args) -> int:
    with args.open_register(args) as reg:
        found = reg.conflict(args.conflict)
        resolution = reg.resolve_conflict(args.conflict, args.keep, who=args.operator, note=args.note)
    if args.json:
        _print_json(
            {
                "conflict": found.short,
                "uid": found.uid,
                "axis": found.axis.ref,
                "kept": resolution.kept,
                "settled": resolution.settled,
                "resolution": resolution.uid,
            }
        )
        return 0
    side = found.sides[resolution.kept - 1]
    print(f"Conflict {found.short} of {found.axis.ref} settled: kept {resolution.kept} ({side.register}).")
    return 0
