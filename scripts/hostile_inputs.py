"""Hostile inputs, tried again against the real command line: a table of what each did.

Run: python scripts/hostile_inputs.py [--only TEXT] [--markdown]

Every case a hostile tester once found on the register, its imports, machine files, training,
``drive`` and ``size`` (seven classes and the odd ones: the register's SQLite errors and
devices, session files of the wrong shape, deep and huge structures, times and numbers in
arguments, names, files after a kill, an option taken for another) runs ``python -m fha_studio``
as a script would, in a fresh temporary folder of its own, and the table says: the class, the
case, the command, the exit status, the lines on stderr, whether a traceback was printed, whether
anything was left half-written (a temporary or partial file, a new file that should not be
there, an input changed, a register's content changed by a refused write, ``/dev/zero-journal``,
bytes on a pty taken for a register) and the verdict. A refusal is good when it is one line (at
most two), its exit status is non-zero (below 128), there is no traceback and nothing is
half-written; a few cases are answers, not refusals (a read-only register answers a question; the
GUI on a read-only register opens and says so), and their row says what was expected.

Read-only registers are made as the tests make them, with their helper (tests/support/read_only.py):
the files chmod read-only, and as root the command runs without root's overrides of a file's mode
(setpriv; still root, so it reads a checkout in a 0700 home).
Settings, data and the journal of temporaries go to a temporary home, never the user's.
The exit status of the script is 0 when every verdict is good.
"""

from __future__ import annotations

import os
import tempfile

HOME = tempfile.mkdtemp(prefix="fha-hostile-home-")
os.environ["XDG_CONFIG_HOME"] = f"{HOME}/config"
os.environ["XDG_DATA_HOME"] = f"{HOME}/data"
os.environ.pop("FHA_STUDIO_REGISTER", None)

import argparse  # noqa: E402
import json  # noqa: E402
import select  # noqa: E402
import shutil  # noqa: E402
import signal  # noqa: E402
import socket  # noqa: E402
import sqlite3  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import textwrap  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable  # noqa: E402
from dataclasses import dataclass, field  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
CORPUS = ROOT / "tests" / "corpus"
ACTUATOR = "FHA-25C-50-US250"
sys.path.insert(0, str(ROOT))

from tests.support.killed_writer import KILLED_WRITER  # noqa: E402
from tests.support.read_only import seal, unseal, without_overrides  # noqa: E402

# --- what a case is ---------------------------------------------------------------------------------


@dataclass
class Case:
    klass: str
    name: str
    args: list[str]  # fha-studio's arguments; {d} is the case's folder
    setup: Callable[[Path], dict[str, object]] | None = None
    read_only: bool = False  # on a folder the command cannot write (a read-only register)
    answer: str = ""  # not a refusal: what is expected instead (exit 0)
    check: Callable[[Path, subprocess.CompletedProcess[str], dict[str, object]], str] | None = None
    killed: bool = False  # killed mid-write; the row is about what the next start leaves
    timeout: float = 120.0
    extra_files: tuple[str, ...] = ()  # new files that are the command's own doing, not half-written
    writes: bool = False  # an answer that rightly changes the register (an import taken)


@dataclass
class Row:
    klass: str
    name: str
    command: str
    code: int | None
    lines: int
    traceback: bool
    half_written: str
    verdict: str
    good: bool
    seconds: float = 0.0
    notes: list[str] = field(default_factory=list)


# --- the folder each case runs in ---------------------------------------------------------------------


BASE = Path(tempfile.mkdtemp(prefix="fha-hostile-"))
#: the home of a command on a read-only register: the one place it may write
READ_ONLY_HOME = Path(tempfile.mkdtemp(prefix="fha-hostile-read-only-home-"))


def _env(read_only: bool) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("FHA_")}
    env.update(PYTHONPATH=str(ROOT), QT_QPA_PLATFORM="offscreen", PYTHONDONTWRITEBYTECODE="1")
    if read_only:
        home = str(READ_ONLY_HOME)
        env.update(HOME=home, XDG_DATA_HOME=f"{home}/data", XDG_CONFIG_HOME=f"{home}/config",
                   XDG_CACHE_HOME=f"{home}/cache", XDG_RUNTIME_DIR=home)
    return env


# --- fixtures: registers, sessions, files ------------------------------------------------------------


def session_dict(**changes: object) -> dict[str, object]:
    session: dict[str, object] = {
        "format": "fha-session/1", "actuator_code": ACTUATOR, "axis": "feed", "operator": "T. Trainee",
        "site": "Plant A", "created_utc": "2026-11-29T09:00:00+00:00",
        "driver": {"model": "HA-655-2-200", "adjusted_for": ACTUATOR, "version": "sim 1"},
        "parameters": {"values": {"rotary_direction": 1, "in_position_range": 20},
                       "read_utc": "2026-11-29T10:00:00+00:00"},
        "runs": {},
    }
    session.update(changes)
    return session


def write_session(path: Path, bom: bool = False, **changes: object) -> Path:
    text = json.dumps(session_dict(**changes))
    path.write_bytes((b"\xef\xbb\xbf" if bom else b"") + text.encode())
    return path


_TEMPLATE: list[Path] = []


def filled_register(d: Path) -> Path:
    """A register with machine 'Press 7', axis 'feed' and two snapshots (1 and 2), and the two
    session files imported (made once, copied for each case)."""
    if not _TEMPLATE:
        folder = BASE / "template"
        folder.mkdir()
        _TEMPLATE.append(_make_filled_register(folder))
    path = d / "r.sqlite"
    for name in ("r.sqlite", "one.json", "two.json"):
        shutil.copy(_TEMPLATE[0].parent / name, d / name)
    return path


def _make_filled_register(d: Path) -> Path:
    from fha_studio.logic.register import Register

    path = d / "r.sqlite"
    write_session(d / "one.json")
    write_session(d / "two.json", parameters={"values": {"rotary_direction": 0, "in_position_range": 10},
                                              "read_utc": "2026-11-29T11:00:00+00:00"})
    with Register(path) as reg:
        reg.add_machine("Press 7")
        reg.add_axis("Press 7", "feed", ACTUATOR, "HA-655-2-200", "/dev/ttyUSB0", 1.5)
    for name in ("one.json", "two.json"):
        done = subprocess.run([sys.executable, "-m", "fha_studio", "register", "--register", str(path),
                               "import", str(d / name), "--machine", "Press 7", "--axis", "feed"],
                              env=_env(False), capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, done.stderr
    db = sqlite3.connect(path)  # no WAL beside it: the read-only cases read the file alone
    db.execute("PRAGMA wal_checkpoint(TRUNCATE)")
    db.close()
    return path


def register_setup(d: Path) -> dict[str, object]:
    filled_register(d)
    return {}


def damaged_setup(d: Path) -> dict[str, object]:
    shutil.copy(CORPUS / "register" / "damaged.sqlite", d / "r.sqlite")
    write_session(d / "one.json")
    return {}


def lock_setup(d: Path) -> dict[str, object]:
    filled_register(d)
    holder = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent("""
            import sqlite3, sys
            db = sqlite3.connect(sys.argv[1], isolation_level=None)
            db.execute("BEGIN EXCLUSIVE")
            db.execute("INSERT INTO machine (name, site, notes, created_utc) VALUES ('x', '', '', '')")
            print("holding", flush=True)
            sys.stdin.read()
        """), str(d / "r.sqlite")], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    assert holder.stdout is not None and holder.stdout.readline() == "holding\n"
    return {"holder": holder}


def deep_toml(depth: int = 5000) -> str:
    return "a = " + "[" * depth + "]" * depth + "\n"


def files_setup(d: Path) -> dict[str, object]:
    (d / "afile").write_text("a regular file")
    return {}


def pty_setup(d: Path) -> dict[str, object]:
    master, slave = os.openpty()
    return {"master": master, "slave": slave, "pty": os.ttyname(slave)}


def listener_setup(full: bool) -> Callable[[Path], dict[str, object]]:
    def setup(d: Path) -> dict[str, object]:
        server = socket.socket()
        server.bind(("127.0.0.1", 0))
        server.listen(0)
        opened = [server]
        if full:
            opened.append(socket.create_connection(server.getsockname(), timeout=5))
        return {"sockets": opened, "url": f"socket://127.0.0.1:{server.getsockname()[1]}"}

    return setup


def machine_file(d: Path, **axis_changes: object) -> Path:
    axis = {"name": "feed", "actuator_code": "FHA-17C-50-US250", "port_url": "sim://FHA-17C-50-US250?paced=0"}
    axis.update(axis_changes)
    path = d / "press9.json"
    path.write_text(json.dumps({"format": "fha-machine/1", "name": "Press 9", "axes": [axis]}))
    return path


# --- checks beyond the common ones ---------------------------------------------------------------------


def register_dump(path: Path) -> list[str]:
    try:
        with sqlite3.connect(f"file:{path}?mode=ro", uri=True) as db:
            return list(db.iterdump())
    except sqlite3.Error as exc:
        return [f"unreadable: {exc}"]


def snapshot(d: Path) -> dict[str, object]:
    files: dict[str, object] = {}
    for path in d.rglob("*"):
        rel = str(path.relative_to(d))
        if path.is_file() and not path.is_symlink():
            if path.suffix == ".sqlite":
                files[rel] = ("register", tuple(register_dump(path)))
            elif rel.endswith(("-wal", "-shm", "-journal")):
                files[rel] = "sidecar"
            else:
                files[rel] = ("bytes", path.read_bytes())
    return files


def half_written(d: Path, before: dict[str, object], case: Case) -> list[str]:
    after = snapshot(d)
    found = []
    for rel, what in after.items():
        name = rel.rsplit("/", 1)[-1]
        if what == "sidecar":
            continue  # SQLite's own files beside a register it opened
        if name.endswith((".tmp", ".partial")):
            found.append(f"{rel} left")
        elif rel not in before and rel not in case.extra_files:
            found.append(f"{rel} new")
        elif rel in before and before[rel] != what and not (case.writes and rel.endswith(".sqlite")):
            found.append(f"{rel} changed")
    found += [f"{rel} gone" for rel in before if rel not in after and before[rel] != "sidecar"]
    if os.path.exists("/dev/zero-journal"):
        found.append("/dev/zero-journal")
    return found


def lines_of(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.strip()]


# --- the cases -----------------------------------------------------------------------------------------


def register_cases() -> list[Case]:
    R = ["register", "--register", "{d}/r.sqlite"]
    imp = [*R, "import", "{d}/one.json", "--machine", "Press 7", "--axis", "feed"]
    cases = []
    for klass_name, setup, read_only in (("read-only", register_setup, True),
                                         ("damaged", damaged_setup, False)):
        cases += [
            Case("1", f"{klass_name}: add-machine", [*R, "add-machine", "Press 8"], setup, read_only),
            Case("1", f"{klass_name}: import", imp, setup, read_only),
            Case("1", f"{klass_name}: report (HTML not written)",
                 [*R, "report", "Press 7", "-o", "{d}/report.html"], setup, read_only),
        ]
        reads = [
            ("axes", [*R, "axes"]),
            ("find", [*R, "find", "rotary_direction"]),
            ("diff", [*R, "diff", "1", "2"]),
            ("export", [*R, "export", "-o", "{home}/export.json" if read_only else "{d}/export.json"]),
        ]
        for what, args in reads:
            if klass_name == "read-only":  # a read-only register answers questions
                cases.append(Case("1", f"{klass_name}: {what}", args, setup, read_only,
                                  answer="answers (a question needs no write)"))
            else:
                cases.append(Case("1", f"{klass_name}: {what}", args, setup, read_only))
    for what, args in (("add-machine", [*R, "add-machine", "Press 8"]), ("import", imp),
                       ("report", [*R, "report", "Press 7", "-o", "{d}/report.html"])):
        cases.append(Case("1", f"locked past the busy timeout: {what}", args, lock_setup))
    cases += [
        Case("1", "zero-byte file asked a question", ["register", "--register", "{d}/empty.sqlite", "axes"],
             lambda d: (d.joinpath("empty.sqlite").touch(), {})[1]),
        Case("1", "--register /dev/zero", ["register", "--register", "/dev/zero", "axes"]),
        Case("1", "--register a pty (a drive's line)",
             ["register", "--register", "{pty}", "add-machine", "M"], pty_setup, check=pty_untouched),
        Case("1", "--register a FIFO", ["register", "--register", "{d}/fifo", "machines"],
             lambda d: (os.mkfifo(d / "fifo"), {})[1]),
        Case("1", "--register a directory", ["register", "--register", "{d}", "machines"]),
        Case("1", "machine window on a read-only register",
             ["gui", "--machine-file", "{d}/press9.json", "--register", "{d}/r.sqlite", "--no-connect",
              "--quit-after-ms", "200"],
             lambda d: (register_setup(d), machine_file(d), {})[2], True,
             answer="opens and says the machine was not recorded (no abort)", check=gui_says_read_only),
    ]
    return cases


def pty_untouched(d: Path, done: subprocess.CompletedProcess[str], state: dict[str, object]) -> str:
    master = int(state["master"])  # type: ignore[call-overload]
    ready, _, _ = select.select([master], [], [], 0.2)
    return "bytes written onto the pty" if ready else ""


def gui_says_read_only(d: Path, done: subprocess.CompletedProcess[str], state: dict[str, object]) -> str:
    return "" if "is read-only" in done.stderr else "no read-only message"


def session_cases() -> list[Case]:
    R = ["register", "--register", "{d}/r.sqlite"]

    def with_session(name: str, bom: bool = False, **changes: object) -> Callable[[Path], dict[str, object]]:
        def setup(d: Path) -> dict[str, object]:
            filled_register(d)
            write_session(d / name, bom=bom, **changes)
            return {}
        return setup

    def imp(name: str) -> list[str]:
        return [*R, "import", f"{{d}}/{name}", "--machine", "Press 7", "--axis", "feed"]

    values5 = with_session("bad.json", parameters={"values": 5})
    huge = with_session("bad.json", parameters={"values": {"rotary_direction": 1e308}})
    return [
        Case("2", 'import "values": 5', imp("bad.json"), values5),
        Case("2", 'procedures report "values": 5',
             ["procedures", "report", "{d}/bad.json", "-o", "{d}/r.html"], values5),
        Case("2", "import a value of 1e308", imp("bad.json"), huge),
        Case("2", "procedures report a value of 1e308",
             ["procedures", "report", "{d}/bad.json", "-o", "{d}/r.html"], huge),
        Case("2", "import rotary_direction 77", imp("bad.json"),
             with_session("bad.json", parameters={"values": {"rotary_direction": 77}})),
        Case("2", "import in_position_range 12.7", imp("bad.json"),
             with_session("bad.json", parameters={"values": {"in_position_range": 12.7}})),
        Case("2", "import a parameter file for FHA-99Z",
             [*R, "import", str(CORPUS / "import" / "unknown-actuator.toml"), "--machine", "Press 7",
              "--axis", "new"], register_setup),
        Case("2", "import a session with a byte-order mark", imp("bom.json"),
             with_session("bom.json", bom=True, created_utc="2026-11-30T09:00:00+00:00"),
             answer="imported as a session (not a parameter file)", check=bom_taken_as_session,
             writes=True),
    ]


def bom_taken_as_session(d: Path, done: subprocess.CompletedProcess[str], state: dict[str, object]) -> str:
    # a session's import counts its checks and procedures; a parameter file's says its snapshot only
    return "" if "new check(s)" in done.stdout else f"stdout: {done.stdout.strip()[:80]}"


def deep_cases() -> list[Case]:
    def deep(d: Path) -> dict[str, object]:
        filled_register(d)
        (d / "deep.toml").write_text(deep_toml())
        (d / "deep.json").write_text("[" * 5000 + "]" * 5000)
        return {}

    return [
        Case("3", "register import a TOML 5000 deep",
             ["register", "--register", "{d}/r.sqlite", "import", "{d}/deep.toml", "--machine", "Press 7",
              "--axis", "feed"], deep),
        Case("3", "register import a JSON 5000 deep",
             ["register", "--register", "{d}/r.sqlite", "import", "{d}/deep.json", "--machine", "Press 7",
              "--axis", "feed"], deep),
        Case("3", "drive params restore a TOML 5000 deep",
             ["drive", "params", "restore", "--url", "sim://FHA-25C-50-US250?paced=0", "{d}/deep.toml"],
             deep),
        Case("3", "training check a TOML 5000 deep", ["training", "check", "{d}/deep.toml"], deep),
        Case("3", "training start a TOML 5000 deep", ["training", "start", "{d}/deep.toml"], deep),
        Case("3", "training start a 10 kB name", ["training", "start", "n" * 10_000]),
        Case("3", "training show a 10 kB name", ["training", "show", "n" * 10_000]),
        Case("3", "procedures report a JSON 5000 deep", ["procedures", "report", "{d}/deep.json"], deep),
        Case("3", "gui --machine-file a JSON 5000 deep",
             ["gui", "--machine-file", "{d}/deep.json", "--register", "{d}/r.sqlite", "--no-connect",
              "--quit-after-ms", "200"], deep),
    ]


def number_cases() -> list[Case]:
    R = ["register", "--register", "{d}/r.sqlite"]
    late = "9999-12-31T23:59:59-05:00"
    size = ["size", "--actuator", ACTUATOR, "--load-inertia", "1", "--speed", "60", "--angle", "120",
            "--cycle", "2"]

    def late_session(d: Path) -> dict[str, object]:
        filled_register(d)
        # no parameters.read_utc: the snapshot is stamped with the session's created_utc
        write_session(d / "late.json", created_utc=late, parameters={"values": {"rotary_direction": 1}})
        return {}

    return [
        Case("4", "history --since past 9999 UTC", [*R, "history", "--since", late, "Press 7/feed"],
             register_setup),
        Case("4", "import a session created past 9999 UTC",
             [*R, "import", "{d}/late.json", "--machine", "Press 7", "--axis", "feed"], late_session),
        Case("4", "diff 1 99999999999999999999999", [*R, "diff", "1", "99999999999999999999999"],
             register_setup),
        Case("4", "diff 1 ²", [*R, "diff", "1", "²"], register_setup),
        Case("4", "diff 1 (5000 digits)", [*R, "diff", "1", "9" * 5000], register_setup),
        Case("4", "find in_position_range=1_5", [*R, "find", "in_position_range=1_5"], register_setup),
        Case("4", "find in_position_range=١ (Arabic-Indic)", [*R, "find", "in_position_range=١"],
             register_setup),
        Case("4", "size --accel-time 1e308", [*size, "--accel-time", "1e308"]),
        Case("4", "drive probe --baud 2147483648 on a pty",
             ["drive", "probe", "--url", "{pty}", "--baud", "2147483648"], pty_setup),
    ]


def name_cases() -> list[Case]:
    R = ["register", "--register", "{d}/r.sqlite"]

    def raw_names(d: Path) -> dict[str, object]:
        """A register that holds raw names (as one written before names were checked)."""
        path = filled_register(d)
        db = sqlite3.connect(path)
        with db:
            for name in ("x" * 10_000, "two\nlines", "Press\x1b[2J 7"):
                db.execute("INSERT INTO machine (name, site, notes, created_utc) VALUES (?, '', '', "
                           "'2026-11-29T09:00:00+00:00')", (name,))
        db.execute("PRAGMA wal_checkpoint(TRUNCATE)")
        db.close()
        return {}

    return [
        Case("5", "add-machine a 10 kB name", [*R, "add-machine", "n" * 10_000], register_setup),
        Case("5", "add-machine a name with a line break", [*R, "add-machine", "two\nlines"], register_setup),
        Case("5", "add-machine a name with an escape sequence", [*R, "add-machine", "Press\x1b[2J 7"],
             register_setup),
        Case("5", "add-axis a 3000-character --port",
             [*R, "add-axis", "Press 7", "spindle", "--actuator", ACTUATOR, "--port", "p" * 3000],
             register_setup),
        Case("5", "'no machine called' among raw stored names", [*R, "axes", "Press 99"], raw_names,
             check=refusal_bounded),
    ]


def refusal_bounded(d: Path, done: subprocess.CompletedProcess[str], state: dict[str, object]) -> str:
    if len(done.stderr) > 1000:
        return f"a refusal of {len(done.stderr)} characters"
    if "\x1b" in done.stderr:
        return "escape bytes in the refusal"
    return ""


# class 6: the real command, stopped in its write and killed (tests/support/killed_writer.py)


def kill_cases() -> list[Case]:
    R = ["register", "--register", "{d}/r.sqlite"]
    return [
        Case("6", "register export killed mid-write, then a start", [*R, "export", "-o", "{d}/export.json"],
             register_setup, killed=True),
        Case("6", "register report killed mid-write, then a start",
             [*R, "report", "Press 7", "-o", "{d}/report.html"], register_setup, killed=True),
        Case("6", "drive params backup killed mid-write, then a start",
             ["drive", "params", "backup", "--url", "sim://FHA-25C-50-US250?paced=0&eeprom={d}/eeprom.json",
              "--out", "{d}/backup.toml"], killed=True, extra_files=("eeprom.json",)),
    ]


def option_cases() -> list[Case]:
    def model_file(d: Path) -> dict[str, object]:
        (d / "rec.csv").write_text("t,pos\n0,0\n")
        (d / "model.toml").write_text("# the user's model\n")
        return {}

    return [
        Case("7", "discrepancy --model FILE (not --model-out)",
             ["discrepancy", "{d}/rec.csv", "--model", "{d}/model.toml"], model_file),
        Case("7", "drive probe --u (a prefix of --url)", ["drive", "probe", "--u", "sim://FHA-25C-50-US250"]),
        Case("7", "register --d (a prefix of --db)", ["register", "--d", "{d}/r.sqlite", "machines"]),
        Case("7", "size --act (a prefix of --actuator)",
             ["size", "--act", ACTUATOR, "--load-inertia", "1", "--speed", "60", "--angle", "120",
              "--cycle", "2"]),
    ]


def also_cases() -> list[Case]:
    def eeprom_scenario(d: Path) -> dict[str, object]:
        text = (CORPUS / "scenario" / "eeprom-in-drive.toml").read_text(encoding="utf-8")
        (d / "s.toml").write_text(text.replace('"written-by-check.json"', f'"{d}/written.json"'))
        return {}

    return [
        Case("also", "drive probe: a listener that never accepts (backlog free)",
             ["drive", "probe", "--url", "{url}"], listener_setup(False), check=within_5_s, timeout=30),
        Case("also", "drive probe: a listener that never accepts (backlog full)",
             ["drive", "probe", "--url", "{url}"], listener_setup(True), check=within_5_s, timeout=30),
        Case("also", "drive probe: a pty that never answers", ["drive", "probe", "--url", "{pty}"], pty_setup,
             check=within_5_s, timeout=30),
        Case("also", "training check [drive] eeprom = PATH", ["training", "check", "{d}/s.toml"],
             eeprom_scenario),
        Case("also", "procedures run UNKNOWN --session new.json",
             ["procedures", "run", "UNKNOWN", "--session", "{d}/new.json", "--actuator", ACTUATOR]),
        Case("also", 'gui --machine-file with "axes": 5',
             ["gui", "--machine-file", "{d}/m.json", "--register", "{d}/r.sqlite", "--no-connect"],
             lambda d: (d.joinpath("m.json").write_text(
                 json.dumps({"format": "fha-machine/1", "name": "Press 9", "axes": 5})), {})[1]),
        Case("also", "gui --machine-file with a load inertia of 1e308",
             ["gui", "--machine-file", "{d}/press9.json", "--register", "{d}/r.sqlite", "--no-connect"],
             lambda d: (machine_file(d, load_inertia_kgm2=1e308), {})[1]),
        Case("also", "gui --machine-file with a load inertia of -5",
             ["gui", "--machine-file", "{d}/press9.json", "--register", "{d}/r.sqlite", "--no-connect"],
             lambda d: (machine_file(d, load_inertia_kgm2=-5), {})[1]),
    ]


def within_5_s(d: Path, done: subprocess.CompletedProcess[str], state: dict[str, object]) -> str:
    seconds = float(state["seconds"])  # type: ignore[arg-type]
    return "" if seconds <= 5.0 else f"took {seconds:.1f} s"


def all_cases() -> list[Case]:
    return [*register_cases(), *session_cases(), *deep_cases(), *number_cases(), *name_cases(),
            *kill_cases(), *option_cases(), *also_cases()]


# --- running one ---------------------------------------------------------------------------------------


def shown_command(args: list[str]) -> str:
    text = " ".join(a if len(a) <= 40 else f"{a[:20]}…({len(a)} chars)" for a in args)
    return ("fha-studio " + text).encode("unicode_escape").decode("ascii")


def run_case(case: Case, number: int) -> Row:
    d = BASE / f"case-{number:03d}"
    d.mkdir()
    d.chmod(0o755)
    state: dict[str, object] = case.setup(d) if case.setup else {}
    values = {"d": str(d), "home": str(READ_ONLY_HOME), "pty": state.get("pty", ""),
              "url": state.get("url", "")}
    args = [a.format(**values) if "{" in a and len(a) < 300 else a for a in case.args]
    if case.read_only:
        seal(d)
    before = snapshot(d)
    try:
        if case.killed:
            done, seconds, notes = run_killed(args, d)
        else:
            prefix = without_overrides() if case.read_only else []
            command = [*prefix, sys.executable, "-m", "fha_studio", *args]
            started = time.monotonic()
            try:
                done = subprocess.run(command, cwd=READ_ONLY_HOME if case.read_only else d,
                                      env=_env(case.read_only), capture_output=True, text=True,
                                      timeout=case.timeout, stdin=subprocess.DEVNULL)
            except subprocess.TimeoutExpired as exc:
                done = subprocess.CompletedProcess(command, -1, "", f"TIMEOUT after {exc.timeout} s")
            seconds = time.monotonic() - started
            notes = []
        state["seconds"] = seconds
        left = half_written(d, before, case)
        extra = case.check(d, done, state) if case.check else ""
    finally:
        for key in ("master", "slave"):
            if key in state:
                os.close(int(state[key]))  # type: ignore[call-overload]
        for sock in state.get("sockets", []):  # type: ignore[attr-defined]
            sock.close()
        holder = state.get("holder")
        if holder is not None:
            holder.communicate("")  # type: ignore[attr-defined]
        if case.read_only:
            unseal(d)
    err = lines_of(done.stderr)
    traceback = "Traceback" in done.stderr
    problems = [*notes]
    if case.killed:  # caught halfway, killed, and its temporary gone after the next start
        good = not left and not traceback and not notes
    elif case.answer:
        good = done.returncode == 0 and not traceback and len(err) <= 2
        if not good:
            problems.append(f"expected: {case.answer}")
    else:
        good = 0 < done.returncode < 128 and 1 <= len(err) <= 2 and not traceback
    if left:
        good = False
        problems.append("half-written: " + ", ".join(left))
    if extra:
        good = False
        problems.append(extra)
    if not good and err:
        problems.append("stderr: " + err[-1][:160])
    verdict = "good" if good else "BAD"
    if good and case.answer:
        verdict = f"good ({case.answer})"
    if good and case.killed:
        verdict = "good (the next start removed the temporary)"
    return Row(case.klass, case.name, shown_command(case.args), done.returncode, len(err), traceback,
               "yes" if left else "no", verdict, good, seconds, problems)


def run_killed(args: list[str], d: Path) -> tuple[subprocess.CompletedProcess[str], float, list[str]]:
    """The command stopped in its write and killed (SIGKILL); then a start of the program, once the
    temporary is a minute old (its mtime set back: the minute a start waits for)."""
    started = time.monotonic()
    output = Path(args[args.index(next(a for a in args if a in ("-o", "--out"))) + 1]).name
    proc = subprocess.Popen([sys.executable, "-c", KILLED_WRITER, *args], cwd=d,
                            env={**_env(False), "HOLD": output},
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stdout is not None
    ready, _, _ = select.select([proc.stdout], [], [], 120)
    line = proc.stdout.readline() if ready else ""
    notes = []
    temporaries = sorted(d.glob(f".{output}.*.tmp"))
    if line != "writing\n" or not temporaries:
        notes.append("the write was not caught halfway")
    proc.send_signal(signal.SIGKILL)
    _, err = proc.communicate(timeout=60)
    for tmp in temporaries:
        then = time.time() - 120
        os.utime(tmp, (then, then))
    fresh = subprocess.run([sys.executable, "-m", "fha_studio", "--help"], cwd=d, env=_env(False),
                           capture_output=True, text=True, timeout=120)
    if fresh.returncode != 0:
        notes.append(f"the next start: exit {fresh.returncode}")
    return (subprocess.CompletedProcess(args, proc.returncode, "", err), time.monotonic() - started, notes)


# --- the table -----------------------------------------------------------------------------------------


def table(rows: list[Row], markdown: bool) -> str:
    heads = ["class", "case", "command", "exit", "stderr lines", "traceback", "half-written", "verdict"]
    cells = [[r.klass, r.name, r.command[:70], str(r.code), str(r.lines), "yes" if r.traceback else "no",
              r.half_written, r.verdict] for r in rows]
    if markdown:
        out = ["| " + " | ".join(heads) + " |", "|" + "---|" * len(heads)]
        out += ["| " + " | ".join(c.replace("|", "\\|") for c in row) + " |" for row in cells]
        return "\n".join(out)
    widths = [max(len(h), *(len(row[i]) for row in cells)) for i, h in enumerate(heads)]
    out = ["  ".join(h.ljust(w) for h, w in zip(heads, widths, strict=True))]
    out += ["  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)) for row in cells]
    return "\n".join(out)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--only", help="run the cases whose name holds this text")
    parser.add_argument("--markdown", action="store_true", help="the table in Markdown")
    options = parser.parse_args()
    cases = [c for c in all_cases() if not options.only or options.only in c.name]
    rows = []
    try:
        for number, case in enumerate(cases):
            row = run_case(case, number)
            rows.append(row)
            mark = "." if row.good else "F"
            print(mark, end="", file=sys.stderr, flush=True)
    finally:
        print(file=sys.stderr)
        shutil.rmtree(BASE, ignore_errors=True)
        shutil.rmtree(READ_ONLY_HOME, ignore_errors=True)
        shutil.rmtree(HOME, ignore_errors=True)
    print(table(rows, options.markdown))
    bad = [r for r in rows if not r.good]
    for r in bad:
        print(f"\nBAD [{r.klass}] {r.name}: {r.command}\n    " + "\n    ".join(r.notes))
    print(f"\n{len(rows)} cases: {len(rows) - len(bad)} good, {len(bad)} bad")
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
