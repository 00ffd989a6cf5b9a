"""``fha-studio procedures ...``: the guided procedures on the command line (no Qt).

- ``procedures list --actuator CODE [--session FILE]``: the procedures, whether they apply, status.
- ``procedures show ID --actuator CODE``: the checklist filled in for the actuator (to print).
- ``procedures run ID --session FILE [--actuator CODE] [--operator NAME] [--drive URL]``: walk it
  in the terminal; live steps ask the drive when ``--drive`` is given, else they are confirmed by
  hand. Ctrl-D pauses (the session file keeps the place).
- ``procedures report SESSION [-o OUT.html] [--sign NAME]``: the commissioning report as HTML
  (PDF from the GUI).
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from fha_studio import fileio
from fha_studio.catalog import ModelCodeError
from fha_studio.cli import CliError
from fha_studio.cli._values import output_path, text

ORDER = 60


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "procedures",
        help="guided procedures of the manual and the commissioning report",
        description="The FHA-C manual's procedures (receiving inspection 3-1, installation 3-3, wiring "
        "1-14/4-2, sensor set 4-7-2, rotary direction 1-10) as checklists for one actuator, "
        "recorded in a session file, and the commissioning report.",
    )
    sub = p.add_subparsers(dest="action", metavar="ACTION", required=True)
    ls = sub.add_parser("list", help="the procedures for an actuator and their status")
    ls.add_argument("--actuator", type=text, help="model code, e.g. FHA-25C-50-US250-B-L (or from --session)")
    ls.add_argument("--session", type=Path, help="a session file: show each procedure's status")
    ls.set_defaults(func=_list)
    show = sub.add_parser("show", help="print a checklist filled in for an actuator")
    show.add_argument("procedure", metavar="ID", type=text)
    show.add_argument("--actuator", required=True, type=text)
    show.set_defaults(func=_show)
    run = sub.add_parser("run", help="walk a procedure in the terminal, recorded in the session file")
    run.add_argument("procedure", metavar="ID", type=text)
    run.add_argument("--session", type=Path, required=True, help="session file (created when missing)")
    run.add_argument("--actuator", type=text, help="model code (needed to create a session)")
    run.add_argument("--operator", default="", type=text, help="your name: every check records it")
    run.add_argument(
        "--drive", metavar="URL", type=text, help="drive for live checks, e.g. sim://FHA-25C-50-US250?paced=0"
    )
    run.set_defaults(func=_run)
    report = sub.add_parser("report", help="write the commissioning report of a session as HTML")
    report.add_argument("session", type=Path)
    report.add_argument("-o", "--output", type=output_path, help="HTML file (default: beside the session)")
    report.add_argument("--sign", metavar="NAME", type=text, help="sign it (refused while checks are open): "
                        "with NAME's key when the register has one (fha-studio register keys add)")
    report.add_argument("--key-file", type=Path, metavar="PATH",
                        help="the signer's private key (default: NAME's in the user data directory)")
    report.add_argument("--register", metavar="FILE_OR_URL", help="the register that keeps the signers' "
                        "keys (default: as for fha-studio register)")
    report.set_defaults(func=_report)


def _context(code: str):
    from fha_studio.logic.procedures.context import build_context

    try:
        return build_context(code)
    except ModelCodeError as exc:
        raise CliError(str(exc)) from None


def _load_session(path: Path):
    from fha_studio.logic.procedures import ProcedureSession, SessionError

    try:
        return ProcedureSession.load(path)
    except SessionError as exc:
        raise CliError(str(exc)) from None


def _list(args) -> int:
    from fha_studio.logic.procedures import load_all

    session = _load_session(args.session) if args.session else None
    code = args.actuator or (session.actuator_code if session else None)
    if not code:
        raise CliError("give --actuator CODE or --session FILE")
    for procedure in load_all(_context(code)):
        state = session.runs.get(procedure.id) if session else None
        status = "does not apply" if not procedure.applies else (state.status if state else "not started")
        print(f"{procedure.id:22} {procedure.section:10} {procedure.title}  [{status.replace('_', ' ')}]")
    return 0


def _show(args) -> int:
    from fha_studio.logic.procedures import ProcedureError, load_procedure

    try:
        procedure = load_procedure(args.procedure, _context(args.actuator))
    except ProcedureError as exc:
        raise CliError(str(exc)) from None
    print(f"{procedure.title} ({procedure.section}) — {args.actuator.upper()}")
    if not procedure.applies:
        print("Does not apply to this actuator.")
        return 0
    for number, definition in enumerate(procedure.steps, start=1):
        step = definition.resolve(procedure.context, _AnyAnswer())
        condition = (
            f"  (when {', '.join(definition.when)})" if any("answer:" in c for c in definition.when) else ""
        )
        print(f"{number:3}. [{step.section}] {step.text}{condition}")
        if step.expected_text() and step.kind != "confirm":
            print(f"       passes: {step.expected_text()}")
    return 0


class _AnyAnswer(dict):
    def __contains__(self, key: object) -> bool:
        return True

    def __missing__(self, key: str) -> str:
        return f"<{key}>"


def _ask(prompt: str) -> str:
    try:
        return input(prompt)
    except EOFError:
        raise _Pause from None


class _Pause(Exception):
    pass


def _run(args) -> int:
    from fha_studio.logic.procedures import (
        ProcedureError,
        ProcedureRun,
        ProcedureSession,
        StepInputError,
        load_procedure,
    )

    if args.drive:  # a URL that can name no drive is refused before the session file is made
        from fha_studio.hardware.transport import check_url

        try:
            check_url(args.drive)
        except ValueError as exc:
            raise CliError(f"--drive: {exc}") from None
    if os.path.lexists(args.session):
        session = _load_session(args.session)
        if args.actuator and args.actuator.strip().upper() != session.actuator_code:
            raise CliError(f"{args.session} is a session for {session.actuator_code}, not {args.actuator}")
    else:
        if not args.actuator:
            raise CliError(f"{args.session} does not exist: give --actuator CODE to start a new session")
        _context(args.actuator)
        session = ProcedureSession(actuator_code=args.actuator.strip().upper(), operator=args.operator)
        fileio.check_output_path(args.session)
    context = _context(session.actuator_code)
    try:  # an unknown procedure is refused before a new session file is made
        procedure = load_procedure(args.procedure, context)
    except ProcedureError as exc:
        raise CliError(str(exc)) from None
    if session.path is None:
        session.save(args.session)
    try:
        run = ProcedureRun(session, procedure)
    except ProcedureError as exc:
        raise CliError(str(exc)) from None
    client = None
    if args.drive:
        from fha_studio.hardware.client import DriveClient
        from fha_studio.hardware.errors import LinkError

        try:
            client = DriveClient.open(args.drive)
        except (LinkError, ValueError) as exc:
            raise CliError(f"drive {args.drive}: {exc}") from None
        identity = client.identify()
        if identity is not None and not session.driver:
            session.driver = {
                "model": identity.driver_model,
                "adjusted_for": identity.adjusted_for,
                "version": identity.firmware,
            }
    who = args.operator or session.operator
    print(f"{run.procedure.title} ({run.procedure.section}) for {session.actuator_code}; Ctrl-D pauses.")
    try:
        while (step := run.current()) is not None:
            if run.stopped:
                print(f"STOPPED: {run.state.stop_warning}")
                note = _ask("Put right? Type what was done to check again (empty: stay stopped): ").strip()
                if not note:
                    return 1
                run.retry(who, note)
                continue
            done, total = run.progress()
            print(f"\n[{done + 1}/{total}] § {step.section}\n{step.text}")
            try:
                value = _answer_in_terminal(step, client, context, session)
                record = run.submit(value, who=who)
            except StepInputError as exc:
                print(f"  {exc}")
                continue
            print("  pass" if record.passed else "  FAIL" + (f": {record.detail}" if record.detail else ""))
    except (_Pause, KeyboardInterrupt):
        run.pause()
        print(f"\nPaused; {args.session} keeps the place.")
        return 0
    finally:
        if client is not None:
            client.close()
    print(f"{run.procedure.title}: done.")
    return 0


def _answer_in_terminal(step, client, context, session):
    if step.kind == "confirm":
        return _ask("  done / checked? [y/n] ").strip().lower() in ("y", "yes")
    if step.kind in ("measure", "text"):
        hint = f" ({step.expected_text()})" if step.kind == "measure" else ""
        return _ask(f"  value{hint}: ")
    if step.kind == "choose":
        return _ask(f"  one of {', '.join(step.choices)}: ").strip()
    if step.kind == "live":
        if client is not None:
            from fha_studio.logic.procedures.live import LiveEnv, run_live_check

            _ask("  press Enter to check on the drive ")
            seen = run_live_check(client, step, LiveEnv(context, dict(session.sensor_angles_deg)))
            print(f"  drive: {seen.detail}")
            if seen.available:
                return seen
        return _ask("  checked by hand, OK? [y/n] ").strip().lower() in ("y", "yes")
    if step.kind == "sensor_angle":
        return _ask("  output angle where it switched (deg): ")
    raise CliError(f"step kind {step.kind} cannot be answered here")


def _report(args) -> int:
    from fha_studio.logic.procedures.report import SignError, build_report, sign

    session = _load_session(args.session)
    output = Path(args.output) if args.output else args.session.with_suffix(".html")
    if args.key_file and not args.sign:
        raise CliError("--key-file signs a report: give --sign NAME too")
    if args.sign and _sign_with_key(args, session, output):
        report = build_report(session)
    else:
        if args.sign:
            try:
                sign(session, args.sign)
            except SignError as exc:
                raise CliError(str(exc)) from None
            print(f"note: signed by name only: {args.sign} has no signing key in the register "
                  "(fha-studio register keys add --name NAME makes one)", file=sys.stderr)
        report = build_report(session)
        from fha_studio.logic.register.report_signing import report_file_bytes

        fileio.write_bytes(output, report_file_bytes(session))  # a key signature the session keeps
    print(f"{output}  ({len(report.warnings)} open warning(s))")
    for warning in report.warnings:
        print(f"  - {warning}", file=sys.stderr)
    return 0


def _sign_with_key(args, session, output: Path) -> bool:
    """Sign and write the report with the signer's key; False when the signer has none (then the
    report is signed by name only). Everything that can be refused is refused before a write."""
    from fha_studio.cli._register_signing import passphrase
    from fha_studio.logic.procedures.report import SignError
    from fha_studio.logic.register import Register, RegisterError, register_location
    from fha_studio.logic.register.report_signing import private_key_file_for, sign_report_file
    from fha_studio.logic.register.signing import SigningError, key_file_encrypted, load_private_key

    where = register_location(args.register)
    if not args.key_file and isinstance(where, Path) and not where.exists():
        return False
    try:
        with Register(where, create=False) as reg:
            key_file = args.key_file.expanduser() if args.key_file else private_key_file_for(reg, args.sign)
            if key_file is None:
                return False
            secret = passphrase(f"Passphrase of {key_file}: ") if key_file_encrypted(key_file) else ""
            key = load_private_key(key_file, secret)
            signed = sign_report_file(reg, session, args.sign, key, output)
    except (RegisterError, SigningError, SignError) as exc:
        raise CliError(str(exc)) from None
    print(f"signed by {signed.signer} with key {signed.key_id} (SHA-256 {signed.sha256}); "
          f"check it: fha-studio register verify {output}", file=sys.stderr)
    return True
