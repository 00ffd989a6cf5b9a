"""``fha-studio drive ...``: talk to a connected drive from a script (a contract: keep it stable).

    fha-studio drive probe    --url URL [--actuator CODE] [--json]
    fha-studio drive position --url URL --actuator CODE [--json]
    fha-studio drive origin   --url URL --actuator CODE --yes [--json]
    fha-studio drive params read|write|backup|restore --url URL ...

Exit status: 0 done; 2 a mistake on the command line; 3 nothing usable answers (silent, garbage,
flooding or slow line: within ``PROBE_S`` of the start, whatever the line does); 4 the drive
answered but cannot do it (servo on, incremental encoder, no parameter access). Every failure is
one line on stderr.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fha_studio import fileio
from fha_studio.cli import CliError
from fha_studio.cli._values import whole
from fha_studio.hardware.protocol import BAUD_RATES, BAUDRATE

ORDER = 35

#: The command promises exit 3 within 5 s of being run, whatever the line does. It is kept by
#: construction: one deadline, fixed from the process's own start (Python's start-up counts),
#: for opening the port (a TCP connect included) and asking the drive what it is, every attempt
#: and retry inside it; what comes after it (closing the port, the one line, the interpreter's
#: exit) has the rest of PROBE_S, and PROBE_S leaves half a second to the promise. (A sim:// drive
#: is built in this process first, which waits on no line; its deadline counts from then.)
PROBE_S = 4.5
CONNECT_S = 4.0
#: Extra wall time for parameter reads and writes on a drive that has them.
PARAMETERS_S = 60.0

EXIT_NO_ANSWER = 3
EXIT_REFUSED = 4

FRONT_PANEL = (
    "this drive gives no parameter access over CN3 (it answers only the manual's DGR and OWW): read and "
    "set parameters on the drive's front panel (parameter mode), and enter them on FHA Studio's "
    "Parameters page as values on the drive's panel"
)


class _Stop(Exception):
    """Ends the command with ``code`` and one line."""

    def __init__(self, code: int, message: str):
        super().__init__(message)
        self.code = code


def register(subparsers: Any) -> None:
    d = subparsers.add_parser(
        "drive",
        help="probe a drive, read its absolute position, set its absolute origin, back up its parameters",
        description="Talk to a drive over CN3 (a serial device, a pty path, socket://host:port or "
        "sim://...). Exit 0 done, 2 command-line mistake, 3 nothing usable answers (within 5 s), "
        "4 the drive cannot do it now (servo on, incremental encoder, no parameter access).",
    )
    sub = d.add_subparsers(dest="drive_command", metavar="WHAT", required=True)

    def common(p: argparse.ArgumentParser, actuator_required: bool = False) -> None:
        p.add_argument("--url", required=True, help="the drive: /dev/ttyUSB0, a pty path, socket://host:port")
        p.add_argument("--baud", type=whole(1, 10_000_000), default=BAUDRATE, choices=BAUD_RATES,
                       metavar="RATE",
                       help="baud rate (default %(default)s, CN3's; one of "
                       f"{', '.join(map(str, BAUD_RATES))})")
        p.add_argument("--actuator", required=actuator_required, metavar="CODE",
                       help="actuator model code (its ratio scales the position), e.g. FHA-25C-50-S248")

    p = sub.add_parser("probe", help="what the drive is and can do, its servo state and position",
                       description="Ask the drive what it is. JSON keys: link, driver, parameter_access, "
                       "documented_only, servo, encoder, position_counts, position_deg.")
    common(p)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=_run(_probe))

    p = sub.add_parser("position", help="the absolute position (DGR; servo off, absolute encoder)",
                       description="Read the absolute position (DGR). With the servo on the drive does "
                       "not answer: exit 4.")
    common(p, actuator_required=True)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=_run(_position))

    p = sub.add_parser("origin", help="set the absolute origin: clear the multi-turn data (OWW)",
                       description="Clear the absolute encoder's multi-turn data (OWW) and read the "
                       "position back. Needs the servo off and an absolute encoder; takes about 5 s.")
    common(p, actuator_required=True)
    p.add_argument("--yes", action="store_true", help="do it without asking")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=_run(_origin))

    params = sub.add_parser("params",
                            help="read, write, back up or restore parameters (drives that allow it)",
                            description="Parameters over CN3: only on a drive with parameter access "
                            "(the simulated drive's full profile). A drive of the manual's commands "
                            "only: exit 4, use its front panel.")
    psub = params.add_subparsers(dest="params_command", metavar="ACTION", required=True)
    p = psub.add_parser("read", help="every tune and parameter-mode item")
    common(p)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=_run(_params_read, PARAMETERS_S))
    p = psub.add_parser("write", help="write items and verify them by reading back")
    common(p)
    p.add_argument("assignments", nargs="+", metavar="ITEM=VALUE",
                   help="item by key (rotary_direction) or MODE:NUMBER (system:8), wire value")
    p.set_defaults(func=_run(_params_write, PARAMETERS_S))
    p = psub.add_parser("backup", help="save the drive's values to a parameter file")
    common(p)
    p.add_argument("--out", required=True, metavar="FILE.toml", help="the parameter file to write")
    p.set_defaults(func=_run(_params_backup, PARAMETERS_S))
    p = psub.add_parser("restore", help="write a parameter file's values to the drive")
    common(p)
    p.add_argument("file", metavar="FILE.toml", help="a parameter file (fha-parameters/1)")
    p.set_defaults(func=_run(_params_restore, PARAMETERS_S))


# --- connecting within a bounded time -----------------------------------------------------------


@dataclass
class _Link:
    client: Any
    bounded: Any
    url: str


@contextlib.contextmanager
def _connect(args: argparse.Namespace) -> Iterator[_Link]:
    from fha_studio.clock import process_started_monotonic
    from fha_studio.hardware.client import DriveClient, LinkSettings
    from fha_studio.hardware.deadline import DeadlineTransport
    from fha_studio.hardware.errors import LinkFailure
    from fha_studio.hardware.transport import open_transport

    if args.baud <= 0:
        raise CliError(f"--baud {args.baud}: must be a positive number of bit/s")
    # one retry, and no reply longer than a second: a probe must finish inside CONNECT_S
    settings = LinkSettings(baudrate=args.baud, retries=1, max_reply_s=1.0)
    deadline = process_started_monotonic() + CONNECT_S
    simulated = args.url.lower().startswith("sim://")
    bounded = None
    try:
        try:
            port = open_transport(args.url, baudrate=args.baud, timeout=settings.poll_s,
                                  open_timeout_s=deadline - time.monotonic())
        except ValueError as exc:
            raise CliError(f"--url: {exc}") from None
        if simulated:  # the drive was built in this process (seconds on a loaded machine): no line
            deadline = time.monotonic() + CONNECT_S  # was waited on, its line starts now
        bounded = DeadlineTransport(port)
        bounded.allow_until(deadline, CONNECT_S)
        client = DriveClient.attach(bounded, settings)
    except LinkFailure as exc:
        raise _Stop(EXIT_NO_ANSWER, _no_answer(args.url, exc, bounded)) from None
    try:
        yield _Link(client, bounded, args.url)
    except LinkFailure as exc:
        raise _Stop(EXIT_NO_ANSWER, _no_answer(args.url, exc, bounded)) from None
    finally:
        client.close()


def _no_answer(url: str, exc: Exception, bounded: Any) -> str:
    from fha_studio.clock import process_started_monotonic
    from fha_studio.hardware.deadline import DeadlinePassed

    if bounded is None:  # the port did not open
        return str(exc)
    # how long since the command was run: the time the promise counts, said where it gave up
    taken = f"in {time.monotonic() - process_started_monotonic():.1f} s"
    heard = bounded.received_bytes
    if heard == 0:
        return (f"no drive answers on {url}: nothing arrived {taken} (check the cable, the port and "
                "the drive's power)")
    if isinstance(exc, DeadlinePassed) or "no drive answers" in str(exc) or "no reply" in str(exc):
        return (f"no drive answers on {url}: {heard} bytes arrived {taken} but no usable reply (check "
                f"the baud rate, {BAUDRATE} 8N1, and that this is the drive's CN3 port)")
    return f"the link to {url} failed: {exc}"


def _run(action: Callable[[argparse.Namespace, _Link], int], seconds: float | None = None
         ) -> Callable[[argparse.Namespace], int]:
    def run(args: argparse.Namespace) -> int:
        ratio = _ratio(args)
        args.ratio = ratio
        name = " ".join(filter(None, ("drive", args.drive_command, getattr(args, "params_command", None))))
        try:
            with _connect(args) as link:
                if seconds is not None:
                    link.bounded.allow(seconds)
                return action(args, link)
        except _Stop as stop:
            print(f"fha-studio {name}: {stop}", file=sys.stderr)
            return stop.code

    return run


def _ratio(args: argparse.Namespace) -> int | None:
    if not getattr(args, "actuator", None):
        return None
    from fha_studio.catalog import ModelCodeError, parse_model_code

    try:
        return parse_model_code(args.actuator).ratio
    except ModelCodeError as exc:
        raise CliError(f"--actuator {args.actuator}: {exc}") from None


def _refused(exc: Exception, command: Any) -> _Stop:
    from fha_studio.logic.absolute import refusal_text

    return _Stop(EXIT_REFUSED, refusal_text(exc, command))  # type: ignore[arg-type]


# --- the commands -------------------------------------------------------------------------------


def _probe(args: argparse.Namespace, link: _Link) -> int:
    from fha_studio.logic.absolute import probe

    result = probe(link.client, args.ratio)
    if args.json:
        print(json.dumps(result.as_dict(), indent=2))
    else:
        print("\n".join(result.lines()))
    return 0


def _position(args: argparse.Namespace, link: _Link) -> int:
    from fha_studio.hardware.errors import DriveRefused
    from fha_studio.hardware.protocol import Command
    from fha_studio.logic.absolute import output_deg, position_text

    try:
        counts = link.client.absolute_position()
    except DriveRefused as exc:
        raise _refused(exc, Command.DGR) from None
    angle = output_deg(counts, args.ratio)
    if args.json:
        print(json.dumps({"position_counts": counts, "position_deg": angle}, indent=2))
    else:
        print(position_text(counts, angle))
    return 0


def _origin(args: argparse.Namespace, link: _Link) -> int:
    from fha_studio.hardware.errors import DriveRefused
    from fha_studio.hardware.protocol import Command
    from fha_studio.logic.absolute import output_deg, position_text

    client = link.client
    try:
        before = client.absolute_position()  # proves servo off and an absolute encoder
    except DriveRefused as exc:
        raise _refused(exc, Command.DGR) from None
    if not args.yes:
        if not sys.stdin.isatty():
            raise CliError("origin clears the absolute encoder's multi-turn data: confirm with --yes")
        print(f"position now: {position_text(before, output_deg(before, args.ratio))}")
        answer = input("Clear the multi-turn data so that this becomes turn 0? [y/N] ")
        if answer.strip().lower() not in ("y", "yes"):
            print("nothing cleared")
            return 1
    link.bounded.allow(client.settings.oww_timeout_s + CONNECT_S)
    from fha_studio.logic.absolute import set_absolute_origin

    try:
        result = set_absolute_origin(client, args.ratio)
    except DriveRefused as exc:
        raise _refused(exc, Command.OWW) from None
    if args.json:
        print(json.dumps(result.as_dict(), indent=2))
    else:
        print(f"before: {position_text(result.before_counts, output_deg(result.before_counts, args.ratio))}")
        print(f"multi-turn data cleared (the drive acknowledged after {result.oww_s:.1f} s)")
        print(f"position read back: {position_text(result.after_counts, result.after_deg)}")
    return 0


def _need_parameters(link: _Link) -> None:
    if not link.client.capabilities.parameters:
        raise _Stop(EXIT_REFUSED, FRONT_PANEL)


def _modes() -> tuple[Any, ...]:
    from fha_studio.hardware.parameters import Mode

    return (Mode.TUNE, Mode.SYSTEM)


def _read_values(client: Any) -> dict[tuple[str, int], int]:
    values: dict[tuple[str, int], int] = {}
    for mode in _modes():
        for number, wire in client.read_all_parameters(mode).items():
            if wire is not None:
                values[(str(mode), number)] = wire
    return values


def _params_read(args: argparse.Namespace, link: _Link) -> int:
    _need_parameters(link)
    client = link.client
    values = _read_values(client)
    rows = []
    for item in client.model:
        wire = values.get((str(item.mode), item.number))
        if str(item.mode) not in ("tune", "system"):
            continue
        rows.append((item, wire))
    if args.json:
        print(json.dumps([
            {"mode": str(item.mode), "number": item.number, "key": item.key, "name": item.name,
             "value": wire, "unit": item.unit, "text": None if wire is None else item.format(wire)}
            for item, wire in rows
        ], indent=2))
    else:
        for item, wire in rows:
            shown = "not answered" if wire is None else item.format(wire)
            print(f"{item.mode.value:<6} {item.number:>2}  {item.name:<40} {shown}")
    return 0


def _parse_assignment(client: Any, text: str) -> tuple[Any, int]:
    from fha_studio.hardware.parameters import ParameterValueError

    name, sep, value = text.partition("=")
    if not sep:
        raise CliError(f"{text!r}: expected ITEM=VALUE, e.g. rotary_direction=1 or system:8=1")
    try:
        if ":" in name:
            mode, _, number = name.partition(":")
            item = client.model.item(mode.strip(), int(number))
        else:
            item = client.model.by_key(name.strip())
    except (KeyError, ValueError):
        raise CliError(f"{name!r}: no such item (use its key, e.g. rotary_direction, or MODE:NUMBER)"
                       ) from None
    try:
        wire = int(value.strip())
        item.check(wire)
    except ValueError as exc:
        if isinstance(exc, ParameterValueError):
            raise CliError(str(exc)) from None
        raise CliError(f"{text!r}: the value must be an integer") from None
    return item, wire


def _params_write(args: argparse.Namespace, link: _Link) -> int:
    _need_parameters(link)
    client = link.client
    writes = [_parse_assignment(client, a) for a in args.assignments]  # all checked before any write
    return _write_all(client, writes)


def _write_all(client: Any, writes: list[tuple[Any, int]]) -> int:
    from fha_studio.hardware.errors import DriveRefused

    failed = 0
    for item, wire in writes:
        try:
            result = client.write_parameter(item.mode, item.number, wire)
        except DriveRefused as exc:
            print(f"fha-studio drive params: {exc}", file=sys.stderr)
            failed += 1
            continue
        print(result.message)
        failed += 0 if result.verified else 1
    return EXIT_REFUSED if failed else 0


def _params_backup(args: argparse.Namespace, link: _Link) -> int:
    from fha_studio.logic.paramfile import dump_parameter_file

    _need_parameters(link)
    client = link.client
    identity = client.identify()
    values = _read_values(client)
    text = dump_parameter_file(
        client.model, values,
        actuator=args.actuator or (identity.adjusted_for if identity else ""),
        driver_model=identity.driver_model if identity else client.model.driver,
    )
    _write_atomically(Path(args.out), text)
    print(f"{len(values)} items saved to {args.out}")
    return 0


def _params_restore(args: argparse.Namespace, link: _Link) -> int:
    from fha_studio.logic.paramfile import ParameterFileError, load_parameter_file

    _need_parameters(link)
    client = link.client
    try:
        loaded = load_parameter_file(args.file, client.model)
    except ParameterFileError as exc:
        raise CliError(str(exc)) from None
    for line in loaded.not_mapped:
        print(f"not restored: {line}", file=sys.stderr)
    current = _read_values(client)
    writes = [(client.model.item(mode, number), wire)
              for (mode, number), wire in sorted(loaded.values.items())
              if current.get((mode, number)) != wire]
    if not writes:
        print("the drive already holds every value of the file")
        return 0
    return _write_all(client, writes)


def _write_atomically(path: Path, text: str) -> None:
    # fileio refuses a device (renaming over /dev/full would replace the device) and a path
    # under a file, writes a temporary file, fsyncs and renames it
    try:
        fileio.write_text(path, text)
    except fileio.FileProblem as exc:
        raise CliError(str(exc)) from None
