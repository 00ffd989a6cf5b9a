"""``fha-studio register [--register FILE_OR_URL] ACTION ...``: the questions a plant asks of the register.

- ``machines``: the machines, their sites, how many axes and open items.
- ``axes [MACHINE]``: every axis with actuator, driver, port, checks passed/failed, report.
- ``history AXIS [--since TIME]``: everything recorded for an axis, oldest first.
- ``diff A B``: the parameters that differ between two snapshots (by number) or two axes' latest
  known values (``MACHINE/AXIS``: this axis against its twin).
- ``find KEY[=VALUE] [--machine M]``: the axes whose latest known value of a parameter is VALUE.
- ``open [MACHINE]``: open checks and unsigned reports.
- ``report MACHINE [-o FILE.html]``: the machine report (the GUI writes it as PDF too).
- ``export [--machine M] [-o FILE]``: everything as JSON.
- ``check``: SQLite's integrity check, and what a damaged register still holds.
- ``add-machine NAME``, ``add-axis MACHINE/AXIS``, ``import FILE... --machine M``: fill it.
- ``keys add --name PERSON [--key-file PATH]``, ``keys list``: each person's signing key;
  ``verify REPORT``: is the report the one that was signed, and by whom (exit 0, else 5).
- ``correct snapshot|check|note NUMBER --reason TEXT ...``: a mistake corrected by a new fact that
  points at the wrong one (nothing is ever changed).
- ``roles setup|grant LOGIN ROLE [--person NAME]|revoke LOGIN ROLE|list``: who may add what to a
  register on a server (technician, reviewer, administrator).

Every action takes ``--json``. The register is ``--register FILE`` (or a plant's register on a
PostgreSQL server: ``--register postgresql://USER:PASSWORD@HOST/DB``), else
``$FHA_STUDIO_REGISTER``, else ``register.sqlite`` in the user data directory: the GUI's rule and
option (``register_location``). ``--db FILE`` is the old name of ``--register``, still taken.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
from contextlib import contextmanager
from dataclasses import asdict
from pathlib import Path
from typing import Any

from fha_studio import fileio, plausible
from fha_studio.cli import CliError, _register_correct, _register_roles, _register_signing, _register_sync
from fha_studio.cli._values import in_range
from fha_studio.logic.register.words import (
    KIND_WORDS,
    SOURCE_WORDS,
    parameter_item,
    parameter_name,
    value_text,
    when_text,
)
from fha_studio.names import quoted

ORDER = 70


class _OldName(argparse.Action):
    """``--db FILE``: the old name of ``--register FILE``, taken with a note on stderr."""

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        print(f"{parser.prog}: note: --db is now called --register", file=sys.stderr)
        setattr(namespace, self.dest, values)


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "register",
        help="the register of machines and axes: history, differences, find, open items",
        description="The register keeps every commissioning fact of every axis (parameter snapshots, "
        "verified writes, checks, alarms, reports, recordings, model checks) in one SQLite file, or for a "
        "plant in a database on a PostgreSQL server (--register postgresql://...).",
    )
    p.add_argument(
        "--register",
        metavar="FILE_OR_URL",
        help="the register: a file, or postgresql://USER:PASSWORD@HOST/DB for a plant's register on a "
        "server (default: $FHA_STUDIO_REGISTER, else register.sqlite in the user data directory), "
        "as for the GUI",
    )
    p.add_argument("--db", dest="register", action=_OldName, help=argparse.SUPPRESS)
    p.add_argument("--json", action="store_true", help="print JSON")
    common = argparse.ArgumentParser(add_help=False, allow_abbrev=False)
    # also accepted after the action; SUPPRESS keeps the action from resetting what came before it
    hidden = argparse.SUPPRESS
    common.add_argument("--register", metavar="FILE_OR_URL", default=hidden, help=hidden)
    common.add_argument("--db", dest="register", action=_OldName, default=hidden, help=hidden)
    common.add_argument("--json", action="store_true", default=argparse.SUPPRESS, help="print JSON")
    sub = p.add_subparsers(dest="action", metavar="ACTION", required=True)

    s = sub.add_parser("machines", parents=[common], help="the machines in the register")
    s.set_defaults(func=_machines)
    s = sub.add_parser("axes", parents=[common], help="the axes (of one machine) and where they stand")
    s.add_argument("machine", nargs="?", metavar="MACHINE")
    s.set_defaults(func=_axes)
    s = sub.add_parser("history", parents=[common], help="everything recorded for an axis")
    s.add_argument("axis", metavar="AXIS", help="MACHINE/AXIS (or the axis name when it is unique)")
    s.add_argument(
        "--since", metavar="TIME", help="from this time on (ISO 8601, e.g. 2026-11-30 or 2026-11-30T08:00Z)"
    )
    s.add_argument("--numbers", action="store_true",
                   help="each line's number (what register correct KIND NUMBER takes)")
    s.set_defaults(func=_history)
    s = sub.add_parser(
        "diff",
        parents=[common],
        help="parameters that differ between two snapshots or two axes",
        description="A and B are each a snapshot number (see history) or MACHINE/AXIS for that axis's "
        'latest known values, e.g. \'diff "Line 3/table" "Line 3/table twin"\'.',
    )
    s.add_argument("a", metavar="A")
    s.add_argument("b", metavar="B")
    s.set_defaults(func=_diff)
    s = sub.add_parser(
        "find",
        parents=[common],
        help="the axes with a parameter value, e.g. rotary_direction=1",
        description="KEY is the parameter's name in the manual's words (rotary_direction, or "
        "'Rotary direction'); VALUE the drive's value (e.g. 1 = reversed). Without =VALUE every "
        "axis's value is listed. Compared is each axis's latest known value.",
    )
    s.add_argument("query", metavar="KEY[=VALUE]")
    s.add_argument("--machine", metavar="MACHINE")
    s.set_defaults(func=_find)
    s = sub.add_parser("open", parents=[common], help="open checks and unsigned reports")
    s.add_argument("machine", nargs="?", metavar="MACHINE")
    s.set_defaults(func=_open)
    s = sub.add_parser("export", parents=[common], help="everything (of one machine) as JSON")
    s.add_argument("--machine", metavar="MACHINE")
    s.add_argument("-o", "--output", type=Path, metavar="FILE", help="write to FILE instead of printing")
    s.set_defaults(func=_export)
    s = sub.add_parser(
        "report",
        parents=[common],
        help="the machine report as HTML: every axis summarised, then each axis's report",
        description="The machine report from the register: a summary of every axis (actuator, driver, "
        "rotary direction, origin, checks passed/failed, signed or not), then each axis's commissioning "
        "report from its procedure session file (the one last recorded). The PDF is written by the GUI.",
    )
    s.add_argument("machine", metavar="MACHINE")
    s.add_argument("-o", "--output", type=Path, metavar="FILE", help="HTML file (default: MACHINE.html here)")
    s.set_defaults(func=_report)
    s = sub.add_parser(
        "check",
        parents=[common],
        help="SQLite's integrity check of the register, and what a damaged one still holds",
        description="Runs SQLite's integrity check on the register file (opened read-only, never "
        "changed) and says, table by table, how many entries can still be read, and which machines "
        "and axes. Exit 0 when the file is sound, 1 when it is damaged.",
    )
    s.set_defaults(func=_check)
    s = sub.add_parser("add-machine", parents=[common], help="add a machine")
    s.add_argument("name", metavar="NAME")
    s.add_argument("--site", default="")
    s.add_argument("--notes", default="")
    s.set_defaults(func=_add_machine)
    s = sub.add_parser("add-axis", parents=[common], help="add an axis to a machine")
    s.add_argument("axis", metavar="MACHINE/AXIS")
    s.add_argument("--actuator", default="", help="model code, e.g. FHA-25C-50-US250")
    s.add_argument("--driver", default="", help="driver model, e.g. HA-655-2-200")
    s.add_argument("--port", default="", help="the port: /dev/ttyUSB0, COM3, socket://host:port, sim://...")
    s.add_argument(
        "--load-inertia", type=in_range(plausible.LOAD_INERTIA_KGM2), default=None, metavar="KGM2",
        help=f"declared load inertia [kg m^2], {plausible.LOAD_INERTIA_KGM2.allowed()}",
    )
    s.add_argument("--serial-number", default="", help="from the actuator's label")
    s.add_argument("--notes", default="")
    s.add_argument("--operator", default="", help="who adds it")
    s.set_defaults(func=_add_axis)
    s = sub.add_parser(
        "import",
        parents=[common],
        help="import session files and parameter files",
        description="Session files (fha-session/1, JSON) and parameter files (fha-parameters/1, TOML) "
        "into the register. The axis is the session's own (or --axis); importing a file again adds nothing.",
    )
    s.add_argument("files", nargs="+", type=Path, metavar="FILE")
    s.add_argument("--machine", required=True, metavar="MACHINE", help="added when it is not there")
    s.add_argument("--axis", metavar="AXIS", help="the axis (needed for a parameter file)")
    s.add_argument("--operator", default="", help="who imports it (for parameter files)")
    s.set_defaults(func=_import)
    _register_signing.add_actions(sub, common, _open_register)
    _register_correct.add_actions(sub, common, _open_register)
    _register_roles.add_actions(sub, common)
    _register_sync.add_actions(sub, common, _open_register)


# -- plumbing -------------------------------------------------------------------------------------------


@contextmanager
def _open_register(args):
    from fha_studio.logic.register import Register, RegisterError, register_location

    # a question asked of a register that is not there is a mistake (a typed path), not an empty
    # answer; adding or importing creates it
    create = args.action in ("add-machine", "add-axis", "import") or getattr(args, "writes", False)
    # a question changes nothing in the file (the report records itself: it writes)
    question = not create and args.action not in ("report", "resolve")
    try:
        reg = Register(register_location(args.register), create=create, read_only=question)
    except RegisterError as exc:
        none = "there is no register" in str(exc)
        hint = " (start one: fha-studio register add-machine NAME)" if none else ""
        raise CliError(f"{exc}{hint}") from None
    try:
        yield reg
    except RegisterError as exc:
        raise CliError(str(exc)) from None
    finally:
        reg.close()


def _print_json(data: Any) -> None:
    print(json.dumps(data, indent=2, ensure_ascii=False))


def _table(rows: list[list[str]], headers: list[str]) -> None:
    widths = [max(len(str(r[i])) for r in [headers, *rows]) for i in range(len(headers))]
    for row in [headers, *rows]:
        print("  ".join(str(c).ljust(w) for c, w in zip(row, widths, strict=True)).rstrip())


def _item(key: str, driver_model: str = ""):
    return parameter_item(key, driver_model)


# -- actions --------------------------------------------------------------------------------------------


def _direction_text(value: int | None) -> str:
    """ "FWD = CW", or "reversed (FWD = CCW)" for a rotary direction value (the 1-10 table); ""
    when unknown."""
    if value is None:
        return ""
    from fha_studio.catalog.tables import rotary_direction_setting

    try:
        setting = rotary_direction_setting(value)
    except ValueError:
        return str(value)
    fwd = f"FWD = {setting.fwd_direction}"
    return fwd if setting.default else f"reversed ({fwd})"


def _machines(args) -> int:
    with _open_register(args) as reg:
        open_items = reg.open_items()
        rows = []
        for m in reg.machines():
            axes = reg.axes(m.name)
            n_open = sum(1 for i in open_items if i.axis.machine == m.name)
            rows.append({**asdict(m), "axes": len(axes), "open_items": n_open})
    if args.json:
        _print_json(rows)
    elif not rows:
        print("No machines in the register yet (add one: fha-studio register add-machine NAME).")
    else:
        _table(
            [[r["name"], r["site"], str(r["axes"]), str(r["open_items"])] for r in rows],
            ["Machine", "Site", "Axes", "Open items"],
        )
    return 0


def _axes(args) -> int:
    with _open_register(args) as reg:
        rows = []
        for axis in reg.axes(args.machine):
            passed, failed = reg.check_counts(axis)
            report = reg.latest_report(axis)
            direction = reg.current_values(axis).values.get("rotary_direction")
            rows.append(
                {
                    **asdict(axis),
                    "ref": axis.ref,
                    "checks_passed": passed,
                    "checks_failed": failed,
                    "rotary_direction": direction.value if direction else None,
                    "report": report["file"] if report else None,
                    "report_signed_by": report["signed_by"] if report else None,
                }
            )
    if args.json:
        _print_json(rows)
        return 0
    if not rows:
        print("No axes in the register yet (add one: fha-studio register add-axis MACHINE/AXIS).")
        return 0
    table = []
    for r in rows:
        report = (
            "none"
            if r["report"] is None
            else (f"signed by {r['report_signed_by']}" if r["report_signed_by"] else "not signed")
        )
        direction = _direction_text(r["rotary_direction"])
        inertia = "" if r["load_inertia_kgm2"] is None else f"{r['load_inertia_kgm2']:g} kg m²"
        table.append(
            [
                r["ref"],
                r["actuator_code"],
                r["driver_model"],
                r["port_url"],
                inertia,
                direction,
                f"{r['checks_passed']} / {r['checks_failed']}",
                report,
            ]
        )
    _table(
        table,
        ["Axis", "Actuator", "Driver", "Port", "Load inertia", "Direction", "Checks pass/fail", "Report"],
    )
    return 0


def _history(args) -> int:
    with _open_register(args) as reg:
        axis = reg.axis(args.axis)
        events = reg.history(axis, since=args.since)
        conflicts = reg.conflicts(axis)
    if args.json:
        _print_json({"axis": asdict(axis), "events": [e.as_dict() for e in events],
                     "open_conflicts": [c.as_dict() for c in conflicts]})
        return 0
    entries = "entry" if len(events) == 1 else "entries"
    driver = f" on {axis.driver_model}" if axis.driver_model else ""
    print(
        f"{axis.ref}: {axis.actuator_code or 'actuator not given'}{driver}"
        f" — {len(events)} {entries} (times UTC)"
    )
    for e in events:
        who = f" [{e.who}]" if e.who else ""
        number = f"{e.ref if e.ref is not None else '':>6}  " if args.numbers else ""
        print(f"{when_text(e.at_utc)}  {number}{KIND_WORDS[e.kind]:<11} {e.text}{who}")
    if conflicts:
        print(f"OPEN CONFLICTS: {len(conflicts)} (registers synced after they were apart disagree; "
              "settle each: fha-studio register resolve ID --keep N)")
        for c in conflicts:
            print(f"conflict {c.short}: {c.summary()}")
            print("\n".join(c.lines()))
    return 0


def _diff(args) -> int:
    with _open_register(args) as reg:
        a, b = reg.parameter_set(args.a), reg.parameter_set(args.b)
        differences = reg.diff(a, b)
    driver = a.axis.driver_model or b.axis.driver_model
    if args.json:
        _print_json({"a": a.label, "b": b.label, "differences": [asdict(d) for d in differences]})
        return 0
    print(f"A: {a.label}\nB: {b.label}")
    if not differences:
        print(f"No difference in the {len(set(a.values) | set(b.values))} parameters they hold.")
        return 0
    _table(
        [
            [parameter_name(d.key, driver), value_text(d.key, d.a, driver), value_text(d.key, d.b, driver)]
            for d in differences
        ],
        ["Parameter", "A", "B"],
    )
    return 0


def _parse_query(reg, query: str) -> tuple[str, int | None, Any]:
    key_text, _, value_part = query.partition("=")
    wanted = key_text.strip().lower().replace(" ", "_").replace("-", "_")
    if not wanted:
        raise CliError("find: give a parameter, e.g. rotary_direction=1")
    item = _item(wanted)
    if item is None:
        from fha_studio.hardware.parameters import load_parameter_model

        by_name = {i.name.lower().replace(" ", "_"): i for i in load_parameter_model("HA-655")}
        item = by_name.get(wanted)
    key = item.key if item is not None else wanted
    if item is None and key not in reg.known_keys():
        raise CliError(
            f"find: no parameter called '{key_text.strip()}' (e.g. rotary_direction, in_position_range)"
        )
    if not value_part.strip():
        return key, None, item
    try:
        # the drive's whole-number value: ASCII digits only (1_5 and Arabic-Indic digits are
        # not numbers here, as nowhere on the command line)
        if not re.fullmatch(r"[+-]?[0-9]{1,11}", value_part.strip()):
            raise ValueError(value_part)
        value = int(value_part.strip())
    except ValueError:
        allowed = (
            ", ".join(f"{k} = {v}" for k, v in item.choices.items())
            if item is not None and item.choices
            else ""
        )
        raise CliError(
            f"find: {quoted(value_part.strip())} for {item.name if item else key} is not the drive's"
            " whole-number value" + (f" ({allowed})" if allowed else "")
        ) from None
    if item is not None:
        try:
            item.check(value)
        except ValueError as exc:
            raise CliError(f"find: {exc}") from None
    return key, value, item


def _find(args) -> int:
    with _open_register(args) as reg:
        key, value, item = _parse_query(reg, args.query)
        found = reg.find(key, value, machine=args.machine)
    if args.json:
        _print_json(
            {"key": key, "value": value, "axes": [{"axis": f.axis.ref, **asdict(f.value)} for f in found]}
        )
        return 0
    what = item.name if item is not None else key
    if not found:
        wanted = f" = {value_text(key, value)}" if value is not None else ""
        print(f"No axis has {what}{wanted}.")
        return 0
    _table(
        [
            [
                f.axis.ref,
                value_text(key, f.value.value, f.axis.driver_model),
                SOURCE_WORDS[f.value.source],
                when_text(f.value.at_utc),
            ]
            for f in found
        ],
        ["Axis", what, "Known from", "When (UTC)"],
    )
    return 0


def _open(args) -> int:
    with _open_register(args) as reg:
        items = reg.open_items(args.machine)
    if args.json:
        _print_json([{"axis": i.axis.ref, "kind": i.kind, "text": i.text} for i in items])
        return 0
    if not items:
        print("Nothing open: every check passed and every report is signed.")
        return 0
    for i in items:
        print(f"{i.axis.ref}: {i.kind if i.kind in ('report', 'conflict') else 'check'}: {i.text}")
    return 0


def _export(args) -> int:
    with _open_register(args) as reg:
        data = reg.export(args.machine)
    text = json.dumps(data, indent=2, ensure_ascii=False) + "\n"
    if args.output:
        if not os.path.lexists(args.output.parent):
            args.output.parent.mkdir(parents=True, exist_ok=True)
        # whole or not at all; a device or a path under a file is refused (fileio)
        fileio.write_text(args.output, text)
        print(f"{args.output}: {len(data['machines'])} machine(s)", file=sys.stderr)
    else:
        sys.stdout.write(text)
    return 0


def _report(args) -> int:
    from fha_studio.logic.machine import MachineError, MachineProject
    from fha_studio.logic.machine_report import build_machine_report, render_machine_html

    with _open_register(args) as reg:
        try:
            project = MachineProject.from_register(reg, args.machine)
        except MachineError as exc:
            raise CliError(str(exc)) from None
        for axis in project:
            recorded = reg.session_file(f"{project.name}/{axis.name}")
            axis.session_file = Path(recorded) if recorded else None
        output = args.output or Path(f"{project.name}.html")
        if not os.path.lexists(output.parent):
            output.parent.mkdir(parents=True, exist_ok=True)
        fileio.check_output_path(output)  # before the work: a target that cannot be written
        report = build_machine_report(project, register=reg)
        existed = os.path.lexists(output)
        # the register's write is begun first: a read-only or locked register refuses before
        # the report is written, and a report the register could not record is taken back
        try:
            with reg.batch():
                fileio.write_text(output, render_machine_html(report))  # whole or not at all
                reg.record_report(
                    output, machine=project.name, open_warnings=sum(s.open_warnings for s in report.summaries)
                )
        except BaseException:
            if not existed:
                output.unlink(missing_ok=True)
            raise
    if args.json:
        _print_json(
            {
                "file": str(output),
                "axes": [asdict(s) for s in report.summaries],
                "problems": list(report.problems),
            }
        )
        return 0
    print(f"{output}: {len(report.summaries)} axes")
    for s in report.summaries:
        conflicts = f", {len(s.open_conflicts)} OPEN CONFLICT(S)" if s.open_conflicts else ""
        print(f"  {s.axis}: {s.checks_passed} passed, {s.checks_failed} failed, {s.signed}{conflicts}")
    for problem in report.problems:
        print(f"  - {problem}", file=sys.stderr)
    return 0


def _check(args) -> int:
    from fha_studio.logic.register import RegisterError, register_location
    from fha_studio.logic.register.check import check_register
    from fha_studio.logic.register.server import shown_url

    path = register_location(args.register)
    if isinstance(path, str):
        raise CliError(f"register check reads a register file; the register {shown_url(path)} is on a "
                       "server, which keeps its own pages and constraints")
    try:
        result = check_register(path)
    except RegisterError as exc:
        raise CliError(str(exc)) from None
    if args.json:
        _print_json({**asdict(result), "path": str(result.path)})
        return 0 if result.ok else 1
    if result.ok:
        rows = sum(t.rows for t in result.tables)
        print(f"{path}: sound (SQLite's integrity check: ok); {len(result.machines)} machine(s), "
              f"{len(result.axes)} axes, {rows} entries in all.")
        return 0
    more = f" (and {len(result.findings) - 1} more)" if len(result.findings) > 1 else ""
    print(f"{path}: DAMAGED. SQLite's integrity check: {quoted(result.findings[0], 200, False)}{more}")
    print("What can still be read:")
    for t in result.tables:
        if t.complete:
            state = f"{t.rows} (all)"
        elif t.rows:
            state = f"{t.rows}, then damaged"
        else:
            state = "none: damaged"
        print(f"  {t.words:<22} {state}")
    print(f"Machines that can be read: {', '.join(map(quoted, result.machines)) or 'none'}")
    print(f"Axes that can be read: {', '.join(map(quoted, result.axes)) or 'none'}")
    print(f"To save what can be read into a new file, SQLite's own tool: "
          f"sqlite3 {path} .recover | sqlite3 saved.sqlite")
    return 1


def _add_machine(args) -> int:
    with _open_register(args) as reg:
        machine = reg.add_machine(args.name, site=args.site, notes=args.notes)
    if args.json:
        _print_json(asdict(machine))
    else:
        print(f"Machine '{machine.name}' added.")
    return 0


def _add_axis(args) -> int:
    machine, sep, name = args.axis.partition("/")
    if not sep or not machine.strip() or not name.strip():
        raise CliError(f"add-axis: '{args.axis}': name the axis as MACHINE/AXIS")
    if args.actuator:
        from fha_studio.catalog import ModelCodeError, parse_model_code

        try:
            parse_model_code(args.actuator)
        except ModelCodeError as exc:
            raise CliError(f"add-axis: --actuator: {exc}") from None
    with _open_register(args) as reg:
        axis = reg.add_axis(
            machine,
            name,
            actuator_code=args.actuator,
            driver_model=args.driver,
            port_url=args.port,
            load_inertia_kgm2=args.load_inertia,
            notes=args.notes,
            serial_number=args.serial_number,
            who=args.operator,
        )
    if args.json:
        _print_json(asdict(axis))
    else:
        print(f"Axis '{axis.ref}' added.")
    return 0


def _import(args) -> int:
    from fha_studio.logic.register import import_parameter_file, import_session_file

    results = []
    lines: list[str] = []
    # every file into one transaction: a refused file leaves nothing of the others either
    with _open_register(args) as reg, reg.batch():
        for path in args.files:
            if not path.is_file():
                raise CliError(f"import: {path}: no such file")
            if _is_session(path):
                result = import_session_file(reg, path, args.machine, args.axis)
                what = f"{result.checks_added} new check(s), {result.procedures} procedure(s)"
            else:
                if not args.axis:
                    raise CliError(f"import: {path} is a parameter file: say which axis with --axis")
                result = import_parameter_file(reg, path, args.machine, args.axis, who=args.operator)
                what = "already there" if result.snapshot is None else f"snapshot {result.snapshot}"
            if result.snapshot is not None and _is_session(path):
                what += f", snapshot {result.snapshot}"
            results.append(
                {
                    "file": str(path),
                    "axis": result.axis.ref,
                    "checks_added": result.checks_added,
                    "snapshot": result.snapshot,
                    "not_taken": list(result.not_taken),
                }
            )
            lines.append(f"{path} -> {result.axis.ref}: {what}")
            lines.extend(f"  not taken: {line}" for line in result.not_taken)
    if not args.json:
        print("\n".join(lines))
    if args.json:
        _print_json(results)
    return 0


def _is_session(path: Path) -> bool:
    """A session file is JSON (starts with '{', after a byte-order mark); a parameter file is TOML."""
    return fileio.read_text(path).lstrip().startswith("{")  # a regular file, bounded
