"""Capture files streamed through ``sigrok-cli``'s input modules, as an instrument streams. No Qt.

``sigrok-cli -i FILE [-I FORMAT[:OPTIONS]]`` plays a file back through libsigrok as if a device
sent it; :class:`FileAcquisition` runs it as :class:`~.sigrok.Acquisition` runs a device and
yields :class:`~.capture.SampleBlock` as they come. The channels keep the names and kinds the
file gives them (``ENC_A: logic``, ``SPD_MON: analog``), never D0-style positions, so roles map
to the file's own names. What sigrok-cli 0.7.2 / libsigrok 0.5.2 does, measured:

- a sigrok session (``.sr``) is found without ``-I``; ``--show`` lists ``- NAME: logic`` /
  ``- NAME: analog`` in bit order (an unnamed bit of a sample shows as its number);
- a VCD (``-I vcd``) is sampled at its ``$timescale`` (1 us: 1 MHz) whatever rate its
  ``$comment`` states; ``downsample=K`` brings it back to the stated rate when that divides;
- a CSV (``-I csv``) is told its columns (``column_formats``: ``l`` logic, ``a`` analog,
  ``-`` skipped), the first data line (``start_line``), the rate (``samplerate``), the separator
  and comment leader; it reads decimal points only, so a ``;`` file with decimal commas is
  refused here (:func:`~.readers.read_capture` reads it). Names come from the file's header (a
  generic CSV) or its ``; Channels`` comment (sigrok's own CSV, whose label row says ``logic``);
- ``-O binary`` writes logic samples, ``unitsize`` bytes each, after a ``META samplerate: N``
  line when the input module states the rate; it also prints every analog sample as text
  (``SPD_MON: 0.02 V DC``), even of channels ``-C`` left out. So logic goes through ``-O binary``
  only where the stream has no analog channel, else through ``-O csv -C <logic channels>``;
- ``-O analog`` prints two decimals (10 mV steps), ``-O csv`` misaligns analog columns, but
  ``-O wav`` streams float32 frames exactly: analog goes through ``-O wav -C <analog channels>``.

A file with both kinds runs two sigrok-cli processes at once, one per kind, and the blocks carry
both, sample by sample.
"""

from __future__ import annotations

import contextlib
import os
import re
import select
import struct
import subprocess
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field

import numpy as np

from fha_studio import fileio
from fha_studio.hardware.bench import readers
from fha_studio.hardware.bench.capture import Capture, SampleBlock, join_blocks, logic_dtype
from fha_studio.hardware.bench.sigrok import SIGROK_CLI, SigrokError, _one_line, executable

#: Bytes of a file's start read to find its form, header and channels.
HEAD_BYTES = 256 * 1024
_READ_BYTES = 1 << 20
_META_LINE = re.compile(rb"^META samplerate: [0-9]+\n")
_SHOW_CHANNEL = re.compile(r"^- (?P<name>.*): (?P<kind>logic|analog)$")


@dataclass(frozen=True)
class InputPlan:
    """How sigrok-cli is to read one file: the ``-I`` argument per kind (None: sigrok finds the
    form itself), the file's logic channels in the order sigrok delivers them and its analog
    channels, each by the file's name, and sigrok's name for each (``-C`` takes those)."""

    path: str
    form: str  # "sigrok session", "VCD", "sigrok CSV", "CSV"
    sample_rate_hz: float
    logic: tuple[str, ...] = ()
    analog: tuple[str, ...] = ()
    logic_format: str | None = None
    analog_format: str | None = None
    select_by_name: bool = False  # the file holds both kinds: -C picks each process's channels
    sigrok_name: dict[str, str] = field(default_factory=dict)
    units: dict[str, str] = field(default_factory=dict)

    @property
    def channels(self) -> tuple[str, ...]:
        return self.logic + self.analog


def _run(args: list[str], what: str, timeout_s: float = 60.0) -> str:
    try:
        done = subprocess.run(args, capture_output=True, timeout=timeout_s, check=False,
                              stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired as exc:
        raise SigrokError(f"{what}: sigrok-cli did not answer within {timeout_s:g} s") from exc
    if done.returncode != 0 or b"Failed to load" in done.stderr:
        raise SigrokError(f"{what}: {_one_line(done.stderr, 'sigrok-cli cannot read it')}")
    return done.stdout.decode("utf-8", "replace")


def show(path: str, input_format: str | None = None,
         program: str = SIGROK_CLI) -> tuple[float, list[tuple[str, str]]]:
    """``sigrok-cli -i FILE [-I FORMAT] --show``: the rate and (name, kind) of each channel."""
    args = [executable(program), "-i", path]
    if input_format:
        args += ["-I", input_format]
    text = _run([*args, "--show"], path)
    rate = 0.0
    channels: list[tuple[str, str]] = []
    for line in text.splitlines():
        line = line.strip()
        if line.startswith("Samplerate:"):
            with contextlib.suppress(ValueError):
                rate = float(line.partition(":")[2])
        match = _SHOW_CHANNEL.match(line)
        if match:
            channels.append((match["name"], match["kind"]))
    if not channels:
        raise SigrokError(f"{path}: sigrok-cli finds no channels in it")
    if not rate > 0:
        raise SigrokError(f"{path}: sigrok-cli finds no sample rate in it")
    return rate, channels


def plan_input(path: str | os.PathLike[str], program: str = SIGROK_CLI) -> InputPlan:
    """How to read ``path`` through sigrok-cli, found from its content (as :func:`read_capture`
    finds it); :class:`SigrokError` or :class:`~.capture.CaptureError` in one line naming the
    file."""
    name = os.fspath(path)
    head = fileio.read_head(name, HEAD_BYTES)
    if head.startswith(b"PK\x03\x04"):
        rate, channels = show(name, None, program)
        logic = tuple(n for n, k in channels if k == "logic")
        analog = tuple(n for n, k in channels if k == "analog")
        return InputPlan(name, "sigrok session", rate, logic, analog, select_by_name=bool(logic and analog),
                         sigrok_name={n: n for n in logic + analog}, units={n: "V" for n in analog})
    stripped = head.lstrip()
    if stripped.startswith(b"$"):
        return _plan_vcd(name, stripped, program)
    if b"libsigrok" in stripped[:200] or stripped.startswith(b"; Channels"):
        return _plan_sigrok_csv(name, head)
    return _plan_csv(name, head)


def _plan_vcd(name: str, head: bytes, program: str) -> InputPlan:
    text = head.decode("utf-8", "replace")
    spec = "vcd"
    scale = re.search(r"\$timescale\s+(1|10|100)\s*(s|ms|us|ns|ps|fs)\s*\$end", text)
    stated = re.search(r"\$comment.*?\bat\s+([0-9.]+\s*[kKmMgG]?Hz).*?\$end", text, re.DOTALL)
    if scale and stated:
        timescale_hz = 1.0 / (int(scale.group(1)) * readers._VCD_UNITS[scale.group(2)])
        rate = readers.parse_rate(stated.group(1))
        if rate:
            factor = timescale_hz / rate
            if factor > 1.5 and abs(factor - round(factor)) < 1e-6 * factor:
                spec = f"vcd:downsample={round(factor)}"
    rate, channels = show(name, spec, program)
    logic = tuple(n for n, k in channels if k == "logic")
    return InputPlan(name, "VCD", rate, logic, (), logic_format=spec, sigrok_name={n: n for n in logic})


def _whole_lines(head: bytes) -> bytes:
    cut = head.rfind(b"\n")
    return head[: cut + 1] if cut >= 0 else head


def _formats(kinds: Sequence[str], keep: str) -> str:
    """``column_formats`` for sigrok's CSV input: ``keep`` ('l' or 'a') columns read, others skipped."""
    return ",".join(k if k == keep else "-" for k in kinds)


def _csv_spec(formats: str, start_line: int, rate_hz: float, separator: str = ",",
              comment: str = ";") -> str:
    spec = (f"csv:header=false:start_line={start_line}:samplerate={round(rate_hz)}"
            f":column_formats={formats}")
    if separator != ",":
        spec += f":column_separator={separator}"
    if comment != ";":
        spec += f":comment_leader={comment}"
    return spec


def _plan_sigrok_csv(name: str, head: bytes) -> InputPlan:
    capture = readers.parse_sigrok_csv(_whole_lines(head), name)
    lines = head.split(b"\n")
    start = 0
    for start, raw in enumerate(lines):  # noqa: B007 - the first row of numbers is wanted
        line = raw.strip()
        if line and line[:1] in b"+-.0123456789" and b": " not in line:
            break
    width = len(lines[start].split(b","))
    names = list(capture.channels)  # logic first, then analog: the file's order is needed
    order = _sigrok_csv_order(head)
    kinds = ["l" if n in capture.block.logic_channels else "a" for n in order]
    if width == len(order) + 1:
        kinds.insert(0, "-")  # the time column
    rate = capture.sample_rate_hz
    if abs(rate - round(rate)) > 1e-6 * rate:
        raise SigrokError(f"{name}: a rate of {rate:g} Hz; sigrok-cli's CSV input takes whole hertz")
    logic = tuple(n for n in order if n in capture.block.logic_channels)
    analog = tuple(n for n in order if n in capture.block.analog)
    assert set(names) == set(order)
    return InputPlan(name, "sigrok CSV", rate, logic, analog,
                     logic_format=_csv_spec(_formats(kinds, "l"), start + 1, rate) if logic else None,
                     analog_format=_csv_spec(_formats(kinds, "a"), start + 1, rate) if analog else None,
                     units={n: capture.units.get(n, "V") for n in analog})


def _sigrok_csv_order(head: bytes) -> list[str]:
    for raw in head.split(b"\n"):
        text = raw.decode("utf-8", "replace").lstrip("; ").strip()
        if text.startswith("Channels"):
            return [c.strip() for c in text.partition(":")[2].split(",") if c.strip()]
    return []


def _plan_csv(name: str, head: bytes) -> InputPlan:
    kind = readers.instrument_layout(head)
    if kind is not None:
        raise SigrokError(f"{name}: line 1: a {kind}; sigrok-cli's CSV input cannot take its layout (FHA "
                          "Studio reads this file itself)")
    layout = readers.csv_layout(head, name)
    if layout.decimal_comma:
        raise SigrokError(f"{name}: line {layout.data_start + 1}: decimal commas; sigrok-cli's CSV input "
                          "reads decimal points only (FHA Studio reads this file itself)")
    capture = readers.parse_csv(_whole_lines(head), name)
    if capture.block.logic_channels:
        raise SigrokError(f"{name}: line {layout.data_start + 1}: a logic analyzer's export of changes, not "
                          "samples at one rate; sigrok-cli's CSV input cannot take it (FHA Studio reads this "
                          "file itself)")
    rate = capture.sample_rate_hz
    kinds = []
    logic: list[str] = []
    analog: list[str] = []
    for column in range(layout.width):
        if column >= len(layout.names) or column == layout.time_column:
            kinds.append("-")
            continue
        label = layout.names[column]
        values = capture.block.analog[label]
        if np.all((values == 0) | (values == 1)):  # 0/1 only: a logic line as a controller logs it
            kinds.append("l")
            logic.append(label)
        else:
            kinds.append("a")
            analog.append(label)
    rate_hz = round(rate)
    if abs(rate - rate_hz) > 1e-4 * rate:
        raise SigrokError(f"{name}: a rate of {rate:g} Hz; sigrok-cli's CSV input takes whole hertz")
    comment = "#"
    separator = layout.delimiter
    start = layout.data_start + 1
    return InputPlan(name, "CSV", float(rate_hz), tuple(logic), tuple(analog),
                     logic_format=_csv_spec(_formats(kinds, "l"), start, rate_hz, separator, comment)
                     if logic else None,
                     analog_format=_csv_spec(_formats(kinds, "a"), start, rate_hz, separator, comment)
                     if analog else None,
                     units={n: capture.units.get(n, "V") for n in analog})


# --- the stream ------------------------------------------------------------------------------------


def _after_meta(data: bytes) -> bytes | None:
    """The stream after a leading ``META samplerate: N`` line (sigrok-cli prints it for outputs
    that have no place for the rate); None while it cannot be told yet."""
    if b"\n" not in data[:64] and len(data) < 64 and b"META samplerate: ".startswith(data[:17]):
        return None
    match = _META_LINE.match(data)
    return data[match.end():] if match else data


class _LogicReader:
    """``-O binary`` (after its META line) or ``-O csv`` rows of 0/1 into packed words."""

    def __init__(self, channels: int, as_csv: bool):
        self.channels = channels
        self.as_csv = as_csv
        self.unitsize = max(1, (channels + 7) // 8)
        self.dtype = np.dtype(logic_dtype(max(1, channels)))
        self._rest = b""
        self._in_head = True

    def feed(self, data: bytes) -> np.ndarray | None:
        data = self._rest + data
        if self._in_head:
            if not self.as_csv:
                after = _after_meta(data)
                if after is None:
                    self._rest = data
                    return None
                data = after
                self._in_head = False
            else:
                while True:
                    end = data.find(b"\n")
                    if end < 0:
                        self._rest = data
                        return None
                    if data[:1] in (b"0", b"1"):
                        self._in_head = False
                        break
                    data = data[end + 1:]  # '; comments', 'META samplerate', the label row
        if not self.as_csv:
            whole = len(data) - len(data) % self.unitsize
            self._rest = data[whole:]
            words = np.frombuffer(data, f"<u{self.unitsize}", whole // self.unitsize)
            return words.astype(self.dtype) if words.dtype != self.dtype else words
        width = 2 * self.channels
        whole = len(data) - len(data) % width
        self._rest = data[whole:]
        grid = np.frombuffer(data, np.uint8, whole).reshape(-1, width)
        seps = grid[:, 1::2]
        if grid.size and not (np.all(seps[:, :-1] == ord(",")) and np.all(seps[:, -1] == ord("\n"))):
            raise SigrokError("sigrok-cli's logic rows are not 0/1 in the channels asked for")
        bits = grid[:, 0::2] - np.uint8(ord("0"))
        words = np.zeros(grid.shape[0], self.dtype)
        for i in range(self.channels):
            words |= bits[:, i].astype(self.dtype) << self.dtype.type(i)
        return words


class _WavReader:
    """``-O wav`` (IEEE float32, channels interleaved, sizes left open) into frames."""

    def __init__(self, channels: int):
        self.channels = channels
        self._rest = b""
        self._in_head = True

    def feed(self, data: bytes) -> np.ndarray | None:
        data = self._rest + data
        if self._in_head:
            after = _after_meta(data)
            if after is None:
                self._rest = data
                return None
            data = after
            at = self._data_start(data)
            if at is None:
                self._rest = data
                return None
            data = data[at:]
            self._in_head = False
        frame = 4 * self.channels
        whole = len(data) - len(data) % frame
        self._rest = data[whole:]
        return np.frombuffer(data, "<f4", whole // 4).reshape(-1, self.channels)

    def _data_start(self, data: bytes) -> int | None:
        if len(data) < 12:
            return None
        if data[:4] != b"RIFF" or data[8:12] != b"WAVE":
            raise SigrokError("sigrok-cli's WAV stream does not start as a WAV file")
        at = 12
        while len(data) >= at + 8:
            chunk, size = data[at:at + 4], struct.unpack("<I", data[at + 4:at + 8])[0]
            if chunk == b"data":
                return at + 8
            if len(data) < at + 8 + size:
                return None
            if chunk == b"fmt ":
                tag, channels = struct.unpack("<HH", data[at + 8:at + 12])
                bits = struct.unpack("<H", data[at + 22:at + 24])[0]
                if (tag, channels, bits) != (3, self.channels, 32):
                    raise SigrokError(f"sigrok-cli's WAV stream: format {tag}, {channels} channels of "
                                      f"{bits} bits; float32 in {self.channels} channels expected")
            at += 8 + size + (size & 1)
        return None


class FileAcquisition:
    """A capture file played through sigrok-cli like an instrument: ``blocks()`` yields
    :class:`SampleBlock` (the file's logic channels asked for, packed in their order, and its
    analog ones, float32) as they come; :meth:`stop` ends it from any thread."""

    def __init__(self, path: str | os.PathLike[str], channels: Sequence[str] | None = None, *,
                 program: str = SIGROK_CLI):
        self.path = os.fspath(path)
        self.device = f"file:{os.path.basename(self.path)}"
        self.program = program
        self.requested = tuple(channels) if channels is not None else None
        self.plan: InputPlan | None = None
        self.channels: tuple[str, ...] = ()
        self.logic: tuple[str, ...] = ()
        self.analog: tuple[str, ...] = ()
        self.sample_rate_hz = 0.0
        self.samples = 0
        self.max_samples: int | None = None
        self.units: dict[str, str] = {}
        self._processes: list[subprocess.Popen[bytes]] = []
        self._stop = False

    def start(self) -> None:
        plan = plan_input(self.path, self.program)
        self.plan = plan
        if self.requested is not None:
            missing = [c for c in self.requested if c not in plan.channels]
            if missing:
                raise SigrokError(f"{self.path}: no channel {', '.join(missing)} (it has "
                                  f"{', '.join(plan.channels)})")
            # logic keeps the file's order (its bits); analog the channels asked, in the file's order
            # (a CSV's analog columns all come: sigrok's CSV input names them by number only)
            self.logic = plan.logic
            self.analog = (tuple(c for c in plan.analog if c in self.requested) if plan.sigrok_name
                           else plan.analog)
        else:
            self.logic, self.analog = plan.logic, plan.analog
        self.channels = self.logic + self.analog
        self.sample_rate_hz = plan.sample_rate_hz
        self.units = {c: plan.units.get(c, "V") for c in self.analog}

    def _command(self, kind: str) -> list[str]:
        assert self.plan is not None
        plan = self.plan
        args = [executable(self.program), "-i", self.path]
        spec = plan.logic_format if kind == "logic" else plan.analog_format
        if spec:
            args += ["-I", spec]
        if kind == "logic":
            if plan.select_by_name:
                args += ["-C", ",".join(plan.sigrok_name[c] for c in self.logic), "-O", "csv"]
            else:
                args += ["-O", "binary"]
        else:
            if plan.sigrok_name:
                args += ["-C", ",".join(plan.sigrok_name[c] for c in self.analog)]
            args += ["-O", "wav"]
        return args

    def stop(self) -> None:
        self._stop = True
        for process in self._processes:
            if process.poll() is None:
                with contextlib.suppress(OSError):
                    process.terminate()

    def close(self) -> None:
        self.stop()
        for process in self._processes:
            try:
                process.wait(timeout=1.0)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
            for pipe in (process.stdout, process.stderr):
                if pipe is not None:
                    with contextlib.suppress(OSError):
                        pipe.close()

    def __enter__(self) -> FileAcquisition:
        if self.plan is None:
            self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def blocks(self) -> Iterator[SampleBlock]:
        if self.plan is None:
            self.start()
        readers_of: dict[int, tuple[str, _LogicReader | _WavReader, subprocess.Popen[bytes]]] = {}
        kinds = (["logic"] if self.logic else []) + (["analog"] if self.analog else [])
        if not kinds:
            raise SigrokError(f"{self.path}: no channels to stream")
        for kind in kinds:
            process = subprocess.Popen(self._command(kind), stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                       stderr=subprocess.PIPE)
            self._processes.append(process)
            assert process.stdout is not None
            reader: _LogicReader | _WavReader = (
                _LogicReader(len(self.logic), self.plan is not None and self.plan.select_by_name)
                if kind == "logic" else _WavReader(len(self.analog)))
            readers_of[process.stdout.fileno()] = (kind, reader, process)
        logic_parts: list[np.ndarray] = []
        analog_parts: list[np.ndarray] = []
        open_fds = set(readers_of)
        while open_fds and not self._stop:
            ready, _, _ = select.select(list(open_fds), [], [], 0.25)
            for fd in ready:
                kind, reader, _process = readers_of[fd]
                data = os.read(fd, _READ_BYTES)
                if not data:
                    open_fds.discard(fd)
                    continue
                got = reader.feed(data)
                if got is not None and len(got):
                    (logic_parts if kind == "logic" else analog_parts).append(got)
            block = self._take(logic_parts, analog_parts)
            if block is not None:
                yield block
                if self.max_samples is not None and self.samples >= self.max_samples:
                    self.stop()
        if self._stop:
            return
        for kind, _reader, process in readers_of.values():
            process.wait()
            assert process.stderr is not None
            stderr = process.stderr.read()
            if process.returncode != 0 or (self.samples == 0 and stderr.strip()):
                why = _one_line(stderr, f"ended with code {process.returncode}")
                why = re.sub(r"^sr: [\w/ -]+: ", "", why)  # libsigrok's "sr: input/vcd: " prefix
                raise SigrokError(f"{self.path}: sigrok-cli cannot read the {kind} channels: {why}")
        if self.samples == 0:
            raise SigrokError(f"{self.path}: sigrok-cli gave no samples")

    def _take(self, logic_parts: list[np.ndarray], analog_parts: list[np.ndarray]) -> SampleBlock | None:
        have_logic = sum(len(p) for p in logic_parts) if self.logic else None
        have_analog = sum(len(p) for p in analog_parts) if self.analog else None
        n = min(x for x in (have_logic, have_analog) if x is not None)
        if self.max_samples is not None:
            n = max(0, min(n, self.max_samples - self.samples))
        if n == 0:
            return None
        logic = np.zeros(0, np.uint8)
        analog: dict[str, np.ndarray] = {}
        if self.logic:
            logic = _cut(logic_parts, n)
        if self.analog:
            frames = _cut(analog_parts, n)
            analog = {c: np.ascontiguousarray(frames[:, i], np.float32) for i, c in enumerate(self.analog)}
        block = SampleBlock(self.sample_rate_hz, self.logic, logic, analog, self.samples)
        self.samples += n
        return block


def _cut(parts: list[np.ndarray], n: int) -> np.ndarray:
    """The first ``n`` rows of the parts (the rest stays in ``parts``)."""
    whole = np.concatenate(parts) if len(parts) > 1 else parts[0]
    parts.clear()
    if len(whole) > n:
        parts.append(whole[n:])
    return whole[:n]


def read_through_sigrok(path: str | os.PathLike[str], channels: Sequence[str] | None = None, *,
                        program: str = SIGROK_CLI) -> Capture:
    """The whole file as sigrok-cli streams it, as one :class:`Capture`."""
    with FileAcquisition(path, channels, program=program) as acquisition:
        blocks = list(acquisition.blocks())
    assert acquisition.plan is not None
    return Capture(acquisition.path, join_blocks(blocks), dict(acquisition.units), 0.0,
                   f"{acquisition.plan.form} through sigrok-cli")
