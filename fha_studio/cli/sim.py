"""``fha-studio sim``: serve a simulated HA-655 with an FHA-C actuator on a pty or a TCP port.

    fha-studio sim --pty                       prints the pty path, serves until killed
    fha-studio sim --tcp 5000                  serves socket://127.0.0.1:5000
    fha-studio sim --pty --actuator FHA-32C-100-S248-B-L --load-inertia 4 \\
        --effect coulomb_friction:torque_nm=8 --eeprom my-drive.json --record run.csv
    fha-studio sim --pty --catalogue-friction  the friction of the catalogue (TF, 2-4-4): after
                                               an alarm the axis comes to rest, as a real one

Point any serial terminal or FHA Studio at the printed address: the drive speaks CN3
(docs/protocol.md) at the pace of a 19200 baud line (``--unpaced`` for memory speed).
"""

from __future__ import annotations

import signal
import sys
import threading
from typing import TYPE_CHECKING, Any

from fha_studio import plausible
from fha_studio.catalog import DEFAULT_ACTUATOR
from fha_studio.cli import CliError
from fha_studio.cli._values import in_range, output_path, tcp_port, text
from fha_studio.hardware.protocol import BAUDRATE

if TYPE_CHECKING:
    from fha_studio.hardware.api import SimPanel
    from fha_studio.hardware.sim import SimConfig

ORDER = 30


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "sim",
        help="serve a simulated drive on a pty or a TCP port",
        description="Serve a simulated HA-655/HA-675 driver with an FHA-C actuator over CN3 "
        "(docs/protocol.md) on a pseudo-terminal or a TCP port, until killed.",
    )
    where = p.add_mutually_exclusive_group(required=True)
    where.add_argument("--pty", action="store_true",
                       help="serve on a new pseudo-terminal; prints its path")
    where.add_argument("--tcp", type=tcp_port, metavar="PORT",
                       help="serve socket://127.0.0.1:PORT (0: any free port)")
    p.add_argument("--actuator", default=DEFAULT_ACTUATOR, metavar="CODE", type=text,
                   help="actuator model code, options included (e.g. FHA-25C-50-S248-B-L); "
                   "default %(default)s")
    p.add_argument("--driver", metavar="MODEL", type=text,
                   help="driver model (default: the HA-655 of FHA-C manual 1-3)")
    p.add_argument("--load-inertia", type=in_range(plausible.LOAD_INERTIA_KGM2), default=0.0, metavar="KGM2",
                   help=f"load inertia [kg m^2], {plausible.LOAD_INERTIA_KGM2.allowed()}")
    p.add_argument("--effect", action="append", default=[], metavar="ID:NAME=VALUE,...",
                   help="switch on a physical effect, e.g. coulomb_friction:torque_nm=8 (repeatable)")
    p.add_argument("--catalogue-friction", action="store_true",
                   help="friction as the catalogue gives it: TF = Kt x Im - TM at maximum speed (FHA-C "
                   "manual 2-4-4), half Coulomb, half viscous; an --effect of the same id wins. Without it "
                   "the axis is frictionless: after an alarm it coasts on")
    p.add_argument("--brake", choices=("yes", "no"),
                   help="fit or leave out the motor brake (default: option B of the code)")
    p.add_argument("--sensors", choices=("yes", "no"),
                   help="fit or leave out the option-L sensor set (default: option L of the code)")
    p.add_argument("--eeprom", metavar="PATH",
                   help="EEPROM file (default: the user data directory, one file per driver and actuator)")
    p.add_argument("--unpaced", action="store_true", help=f"reply at memory speed instead of {BAUDRATE} baud")
    p.add_argument("--oww-seconds", type=in_range(plausible.OWW_CLEAR_S), metavar="S",
                   help=f"how long OWW takes (default 5 s; {plausible.OWW_CLEAR_S.allowed()})")
    p.add_argument("--profile", choices=("full", "documented"), default="full",
                   help="full: every command of docs/protocol.md (default); documented: only what the "
                   "HA-655 manual documents (DGR, OWW; s to everything while the servo is on)")
    p.add_argument("--text-trace", action="store_true",
                   help="trace blocks in text only (TRB), as a drive from before the packed encoding (TRP)")
    p.add_argument("--panel", action="store_true",
                   help="read the controller's side from stdin, one per line: 'servo on', 'servo off' "
                   "(the CN2 servo-ON input), 'fwd DEG' or 'rev DEG' (a command pulse train, servo on), "
                   "'turn DEG' (turn the output by hand, servo off), 'brake release', 'brake hold'")
    p.add_argument("--record", metavar="FILE.csv", type=output_path,
                   help="write what the axis does as an fha-recording/1 CSV (FILE.csv.partial until the "
                   "sim stops)")
    p.add_argument("--record-rate", type=in_range(plausible.SIM_RECORD_RATE_HZ), default=1000.0, metavar="HZ",
                   help="recording sample rate (default %(default)s Hz)")
    p.add_argument("--record-torque", action="store_true",
                   help="the recording also has the column torque: what a torque sensor between the output "
                   "flange and the load reads (N m, positive = the flange driving the load CW)")
    p.set_defaults(func=run)


def _flag(text: str | None) -> bool | None:
    return None if text is None else text == "yes"


def sim_config(args: Any) -> SimConfig:
    """The simulated drive the parsed arguments ask for; SimConfigError names a bad option."""
    from fha_studio.hardware.sim import SimConfig
    from fha_studio.hardware.sim.options import parse_effects

    return SimConfig(
        actuator=args.actuator,
        driver=args.driver,
        load_inertia_kgm2=args.load_inertia,
        brake=_flag(args.brake),
        sensors=_flag(args.sensors),
        effects=parse_effects(args.effect),
        catalogue_friction=args.catalogue_friction,
        eeprom=args.eeprom or "user",
        paced=not args.unpaced,
        oww_clear_s=args.oww_seconds,
        profile=args.profile,
        packed_trace=not args.text_trace,
    )


def run(args: Any) -> int:
    from fha_studio.hardware.sim import EepromError, SimConfigError, SimDrive, SimProtocolServer
    from fha_studio.hardware.sim.serve import serve_pty, serve_tcp

    try:
        config = sim_config(args)
        drive = SimDrive(config=config)
    except (SimConfigError, EepromError) as exc:
        raise CliError(str(exc)) from None

    stop = threading.Event()

    def on_signal(signum: int, frame: object) -> None:
        stop.set()

    previous = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGTERM, signal.SIGINT)}
    if hasattr(signal, "SIGHUP"):
        previous[signal.SIGHUP] = signal.signal(signal.SIGHUP, on_signal)

    def announce(address: str) -> None:
        print(address, flush=True)
        print(f"# {drive.driver} with {drive.actuator_code}, EEPROM {drive.eeprom.path}"
              f"{'' if config.paced else ', unpaced'}", file=sys.stderr, flush=True)

    server = SimProtocolServer(drive, paced=config.paced)
    try:
        if args.record:
            try:
                drive.start_recording(args.record, args.record_rate, torque_sensor=args.record_torque)
            except (OSError, ValueError) as exc:
                raise CliError(f"--record: {exc}") from None
        drive.start()
        if args.panel:
            threading.Thread(target=_panel, args=(server.responder, sys.stdin, stop), name="sim-panel",
                             daemon=True).start()
        if args.pty:
            serve_pty(server, stop, announce)
        else:
            try:
                serve_tcp(server, args.tcp, stop, announce)
            except OSError as exc:
                raise CliError(f"--tcp {args.tcp}: {exc.strerror or exc}") from None
    finally:
        drive.close()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    return 0


def panel_line(sim: SimPanel, line: str) -> str:
    """Do one line of ``--panel`` input on the drive behind ``sim`` (which journals what a training
    drive is done to); returns what happened (one line)."""
    from fha_studio.hardware.sim import SimRefused

    words = line.strip().lower().split()
    try:
        match words:
            case ["servo", ("on" | "off") as state]:
                sim.set_servo(state == "on")
                return f"servo {state} (CN2)"
            case ["fwd" | "rev" as sense, angle]:
                sign = 1.0 if sense == "fwd" else -1.0
                sim.controller_command(sign * float(angle))
                return f"controller: {sense.upper()} {float(angle):g} deg"
            case ["turn", angle]:
                sim.turn_by_hand(float(angle))
                return f"turned by hand by {float(angle):g} deg"
            case ["brake", ("release" | "hold") as state]:
                sim.release_brake(state == "release")
                return f"brake {'released' if state == 'release' else 'holds'}"
            case []:
                return ""
    except SimRefused as exc:
        return f"refused: {exc.reason}"
    except ValueError:
        pass
    return f"not understood: {line.strip()!r} (servo on|off, fwd DEG, rev DEG, turn DEG, brake release|hold)"


def _panel(sim: SimPanel, stream: Any, stop: threading.Event) -> None:
    for line in stream:
        if stop.is_set():
            return
        answer = panel_line(sim, line)
        if answer:
            print(f"# {answer}", file=sys.stderr, flush=True)
