"""Live bench instruments through ``sigrok-cli`` (the acquisition engine of some 200 logic
analyzers, oscilloscopes and DAQs), run as a streaming subprocess. No Qt.

What sigrok-cli 0.7.2 / libsigrok 0.5.2 does, measured with its ``demo`` driver:

- ``--scan`` prints ``driver[:conn=...] - Vendor Model with N channels: D0 D1 ... A0``.
- ``--continuous`` streams until a byte arrives on its stdin; closing stdin alone does *not*
  stop it, so :meth:`Acquisition.stop` writes a byte, and stdin is held open until then.
- ``-O binary`` streams logic samples, ``unitsize`` bytes each (bit ``i`` = the ``i``-th
  enabled logic channel); ``-O analog`` streams one ``A0: -10.0000 V DC`` line per sample and
  channel (units with SI prefixes: ``mV``). Neither carries the other kind, and the CSV output
  misaligns analog columns when both kinds are enabled, so one acquisition is logic or analog.
- The demo driver packs only the enabled logic channels; real analyzers keep a channel's bit at
  its index. Enabling ``D0`` up to the highest channel asked makes both the same.

An instrument that vanishes (unplugged, or its sigrok-cli dies) ends the stream within
``STALL_S`` (0.75 s, so it is said within 1 s): :class:`DeviceVanished` says so, and every
block delivered before stays valid.
"""

from __future__ import annotations

import contextlib
import os
import re
import select
import shutil
import subprocess
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np

from fha_studio.hardware.bench.capture import SampleBlock, logic_dtype

SIGROK_CLI = "sigrok-cli"
INSTALL_HINT = "sigrok-cli is not installed; on Debian or Ubuntu: sudo apt-get install sigrok-cli"

#: Logic channels as sigrok drivers name them (D0, D1, ...); other names are analog.
_LOGIC_NAME = re.compile(r"^D(\d+)$")
_SCAN_LINE = re.compile(r"^(?P<driver>[\w-]+)(?::(?P<options>\S+))? - (?P<description>.*?)"
                        r"(?: with (?P<count>\d+) channels?: (?P<channels>.*))?$")
_ANALOG_LINE = re.compile(rb"^([^:\n]+): (\S+) ([^\n]*)$", re.MULTILINE)
_SI_PREFIX = {"p": 1e-12, "n": 1e-9, "u": 1e-6, "µ": 1e-6, "m": 1e-3, "k": 1e3, "M": 1e6}
_READ_BYTES = 1 << 20
#: Silence after which a streaming instrument counts as gone: under 1 s with the check's own latency.
STALL_S = 0.75


class SigrokError(RuntimeError):
    """sigrok-cli refused or failed; ``str()`` is one line saying what."""


class SigrokMissing(SigrokError):
    """sigrok-cli is not installed; ``str()`` says how to get it."""

    def __init__(self) -> None:
        super().__init__(INSTALL_HINT)


class DeviceVanished(SigrokError):
    """The instrument went away mid-stream (unplugged, or sigrok-cli died). ``samples``: how
    many samples were delivered before, all of them valid."""

    def __init__(self, message: str, samples: int, silent_s: float = 0.0):
        super().__init__(message)
        self.samples = samples
        self.silent_s = silent_s  # how long the stream had been silent when this was said


def executable(name: str = SIGROK_CLI) -> str:
    """The path of sigrok-cli, or :class:`SigrokMissing`."""
    path = shutil.which(name)
    if path is None:
        raise SigrokMissing()
    return path


def is_logic_channel(name: str) -> bool:
    return _LOGIC_NAME.match(name) is not None


# --- devices ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Device:
    """One instrument ``sigrok-cli --scan`` found."""

    driver: str
    options: str  # "conn=1.5" etc., "" when the driver needs none
    description: str  # vendor and model as sigrok says them
    channels: tuple[str, ...]

    @property
    def spec(self) -> str:
        """The ``--driver`` argument that opens this instrument."""
        return f"{self.driver}:{self.options}" if self.options else self.driver

    @property
    def logic_channels(self) -> tuple[str, ...]:
        return tuple(c for c in self.channels if is_logic_channel(c))

    @property
    def analog_channels(self) -> tuple[str, ...]:
        return tuple(c for c in self.channels if not is_logic_channel(c))


def parse_scan(text: str) -> list[Device]:
    """The devices in ``sigrok-cli --scan``'s output (none when it found none)."""
    devices = []
    for line in text.splitlines():
        line = line.strip()
        if not line or line.startswith("The following devices"):
            continue
        match = _SCAN_LINE.match(line)
        if match is None:
            continue
        channels = tuple((match["channels"] or "").split())
        devices.append(Device(match["driver"], match["options"] or "", match["description"].strip(),
                              channels))
    return devices


def _one_line(stderr: bytes, fallback: str) -> str:
    lines = [line.strip() for line in stderr.decode("utf-8", "replace").splitlines() if line.strip()]
    # libsigrok's glib assertions are noise after the real message
    lines = [line for line in lines if "assertion" not in line] or lines
    return lines[-1].rstrip(".") if lines else fallback


def scan(driver: str | None = None, timeout_s: float = 20.0, program: str = SIGROK_CLI) -> list[Device]:
    """The instruments sigrok-cli finds (every driver, or only ``driver`` with its options)."""
    args = [executable(program)]
    if driver:
        args += ["--driver", driver]
    try:
        done = subprocess.run([*args, "--scan"], capture_output=True, timeout=timeout_s, check=False)
    except subprocess.TimeoutExpired as exc:
        raise SigrokError(f"sigrok-cli --scan did not answer within {timeout_s:g} s") from exc
    if done.returncode != 0:
        raise SigrokError(f"sigrok-cli --scan: {_one_line(done.stderr, 'failed')}")
    return parse_scan(done.stdout.decode("utf-8", "replace"))


# --- streaming ----------------------------------------------------------------------------------------


def _scale_of(unit: str) -> tuple[float, str]:
    """(factor to the base unit, base unit) of a sigrok unit such as ``mV DC``."""
    head = unit.split(" ", 1)[0]
    if len(head) > 1 and head[0] in _SI_PREFIX and head[1].isupper():
        return _SI_PREFIX[head[0]], head[1:]
    return 1.0, head


class _AnalogParser:
    """Cuts ``-O analog`` text into per-channel float32 arrays (whole lines only)."""

    def __init__(self, channels: Sequence[str]):
        self.channels = tuple(channels)
        self._rest = b""
        self._pending: dict[str, list[np.ndarray]] = {c: [] for c in self.channels}
        self.units: dict[str, str] = {}

    def feed(self, data: bytes) -> None:
        data = self._rest + data
        cut = data.rfind(b"\n") + 1
        self._rest = data[cut:]
        rows = _ANALOG_LINE.findall(data[:cut])
        if not rows:
            return
        names = np.array([r[0] for r in rows])
        values = np.array([r[1] for r in rows]).astype(np.float32)
        units = np.array([r[2] for r in rows])
        for unit in np.unique(units):
            factor, base = _scale_of(unit.decode("utf-8", "replace"))
            if factor != 1.0:
                values[units == unit] *= np.float32(factor)
            for name in np.unique(names[units == unit]):
                self.units.setdefault(name.decode(), base)
        for name in self.channels:
            picked = values[names == name.encode()]
            if picked.size:
                self._pending[name].append(picked)

    def take(self) -> dict[str, np.ndarray] | None:
        """As many samples as every channel has, or None."""
        joined = {c: (np.concatenate(v) if len(v) > 1 else v[0]) if v else np.zeros(0, np.float32)
                  for c, v in self._pending.items()}
        n = min(len(v) for v in joined.values())
        if n == 0:
            self._pending = {c: [v] if len(v) else [] for c, v in joined.items()}
            return None
        self._pending = {c: [v[n:]] if len(v) > n else [] for c, v in joined.items()}
        return {c: v[:n] for c, v in joined.items()}


def rate_text(rate_hz: float) -> str:
    """A sample rate as people say it: 200 kHz, 1 MHz, 24 MHz."""
    for factor, unit in ((1e9, "GHz"), (1e6, "MHz"), (1e3, "kHz")):
        if rate_hz >= factor:
            return f"{rate_hz / factor:g} {unit}"
    return f"{rate_hz:g} Hz"


class Acquisition:
    """A continuous acquisition of one instrument's channels, all logic or all analog.

    ``blocks()`` yields :class:`SampleBlock` as they arrive (logic: ``D0`` up to the highest
    channel asked, packed; analog: the channels asked, float32 in their base unit, see
    ``units``); it ends after :meth:`stop` (from any thread) or ``max_samples``, and raises
    :class:`DeviceVanished` within ``stall_s`` when the instrument goes away.
    """

    def __init__(self, device: str, channels: Sequence[str], sample_rate_hz: float | None = None, *,
                 max_samples: int | None = None, stall_s: float = STALL_S, program: str = SIGROK_CLI):
        if not channels:
            raise SigrokError("no channels to record")
        logic = [c for c in channels if is_logic_channel(c)]
        if logic and len(logic) != len(channels):
            raise SigrokError("one acquisition records logic channels (D0, D1, ...) or analog ones, "
                              f"not both: {', '.join(channels)}")
        self.device = device
        self.requested = tuple(channels)
        self.is_logic = bool(logic)
        if self.is_logic:
            highest = max(int(_LOGIC_NAME.match(c)[1]) for c in logic)  # type: ignore[index]
            self.channels: tuple[str, ...] = tuple(f"D{i}" for i in range(highest + 1))
            self.unitsize = (len(self.channels) + 7) // 8
            if self.unitsize not in (1, 2, 4, 8):
                raise SigrokError(f"{len(self.channels)} logic channels: up to 16, 32 or 64 are streamed")
            self._dtype = np.dtype(logic_dtype(len(self.channels)))
        else:
            self.channels = tuple(channels)
            self.unitsize = 0
        self.requested_rate_hz = sample_rate_hz
        self.sample_rate_hz = 0.0
        self.max_samples = max_samples
        self.stall_s = stall_s
        self.program = program
        self.samples = 0  # delivered so far
        self.units: dict[str, str] = {}
        self._process: subprocess.Popen[bytes] | None = None
        self._stop_requested = False
        self._stop_at = 0.0

    # -- life cycle --

    def _command(self) -> list[str]:
        args = [executable(self.program), "--driver", self.device]
        if self.requested_rate_hz:
            args += ["--config", f"samplerate={round(self.requested_rate_hz)}"]
        args += ["--channels", ",".join(self.channels), "--continuous",
                 "-O", "binary" if self.is_logic else "analog"]
        return args

    def _rate_of_device(self) -> float:
        args = [executable(self.program), "--driver", self.device]
        if self.requested_rate_hz:
            args += ["--config", f"samplerate={round(self.requested_rate_hz)}"]
        try:
            done = subprocess.run([*args, "--get", "samplerate"], capture_output=True, timeout=20,
                                  check=False)
        except subprocess.TimeoutExpired as exc:
            raise SigrokError(f"{self.device}: sigrok-cli did not say its sample rate within 20 s") from exc
        if done.returncode != 0:
            raise SigrokError(f"{self.device}: {_one_line(done.stderr, 'sigrok-cli refused')}")
        try:
            return float(done.stdout.split()[0])
        except (IndexError, ValueError) as exc:
            raise SigrokError(f"{self.device}: sigrok-cli gave no sample rate") from exc

    def start(self) -> None:
        """Start sigrok-cli (after checking the channels and asking the instrument its rate)."""
        found = scan(self.device, program=self.program)
        if not found:
            raise SigrokError(f"{self.device}: sigrok-cli finds no such instrument (is it plugged in?)")
        missing = [c for c in self.requested if c not in found[0].channels]
        if missing:
            raise SigrokError(f"{self.device}: no channel {', '.join(missing)} (it has "
                              f"{', '.join(found[0].channels)})")
        self.sample_rate_hz = self._rate_of_device()
        self._process = subprocess.Popen(self._command(), stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                         stderr=subprocess.PIPE)

    def stop(self) -> None:
        """Ask sigrok-cli to end the acquisition (any thread); ``blocks()`` then ends."""
        if not self._stop_requested:
            self._stop_requested = True
            self._stop_at = time.monotonic()
        process = self._process
        if process is not None and process.stdin is not None and not process.stdin.closed:
            try:
                process.stdin.write(b"\n")
                process.stdin.flush()
            except (ValueError, OSError):
                pass  # it has ended already

    def close(self) -> None:
        """Stop and reap sigrok-cli (waits at most a second, then kills it)."""
        process = self._process
        if process is None:
            return
        self.stop()
        try:
            process.wait(timeout=1.0)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
        for pipe in (process.stdin, process.stdout, process.stderr):
            if pipe is not None:
                with contextlib.suppress(OSError):
                    pipe.close()

    def __enter__(self) -> Acquisition:
        if self._process is None:
            self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- the stream --

    def _block(self, logic: np.ndarray | None, analog: dict[str, np.ndarray] | None) -> SampleBlock:
        first = self.samples
        if logic is not None:
            block = SampleBlock(self.sample_rate_hz, self.channels, logic, {}, first)
        else:
            block = SampleBlock(self.sample_rate_hz, (), np.zeros(0, np.uint8), analog or {}, first)
        self.samples += block.samples
        return block

    def _limit(self, n: int) -> int:
        if self.max_samples is None:
            return n
        return max(0, min(n, self.max_samples - self.samples))

    def blocks(self) -> Iterator[SampleBlock]:
        if self._process is None:
            self.start()
        process = self._process
        assert process is not None and process.stdout is not None and process.stderr is not None
        fd = process.stdout.fileno()
        rest = b""
        analog = _AnalogParser(self.channels)
        last_data = None
        while True:
            ready, _, _ = select.select([fd], [], [], 0.05)
            now = time.monotonic()
            if self._stop_requested and now - self._stop_at > 1.0 and process.poll() is None:
                process.kill()  # it did not end when asked
            if not ready:
                if (last_data is not None and not self._stop_requested and now - last_data > self.stall_s
                        and process.poll() is None):
                    process.kill()
                    process.wait()
                    raise DeviceVanished(f"{self.device}: no samples for {self.stall_s:g} s, the instrument "
                                         f"is gone (after {self.samples} samples)", self.samples,
                                         now - last_data)
                continue
            data = os.read(fd, _READ_BYTES)
            if not data:
                break
            last_data = now
            if self.is_logic:
                data = rest + data
                whole = len(data) - len(data) % self.unitsize
                rest = data[whole:]
                n = self._limit(whole // self.unitsize)
                if n:
                    yield self._block(np.frombuffer(data, self._dtype, n), None)
            else:
                analog.feed(data)
                self.units.update(analog.units)
                columns = analog.take()
                if columns is not None:
                    n = self._limit(len(next(iter(columns.values()))))
                    if n:
                        yield self._block(None, {c: v[:n] for c, v in columns.items()})
            if self.max_samples is not None and self.samples >= self.max_samples:
                self.stop()
        process.wait()
        stderr = process.stderr.read()
        if self._stop_requested:
            return
        if self.samples == 0 and process.returncode != 0:
            raise SigrokError(f"{self.device}: {_one_line(stderr, 'sigrok-cli refused')}")
        raise DeviceVanished(f"{self.device}: the instrument stopped sending "
                             f"({_one_line(stderr, f'sigrok-cli ended, code {process.returncode}')}) "
                             f"after {self.samples} samples", self.samples,
                             time.monotonic() - (last_data or time.monotonic()))
