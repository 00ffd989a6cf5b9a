"""What the converters of the real data sets share: an fha-recording/1 file written gzipped, the
same input giving the same bytes (mtime 0, no file name in the gzip header), and their command
line (``python CONVERTER SOURCE_DIR [OUT_DIR]``)."""

from __future__ import annotations

import gzip
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np

#: The header's first lines: an axis of its own (no catalogue actuator), no load declared apart from
#: its inertia, and the driver voltage the format asks for (not the data set's own supply).
COMMON_HEADER = (
    "# format: fha-recording/1",
    "# actuator: custom",
    "# load_inertia_kgm2: 0",
    "# supply_voltage: 200",
)


def write_recording_gz(out_path: Path, header: Sequence[str], columns: Sequence[str],
                       data: Sequence[np.ndarray], fmt: Sequence[str]) -> None:
    """COMMON_HEADER, then ``header``'s lines, the column names, and one row per sample (each
    column in its ``fmt``), gzipped into ``out_path``."""
    lines = [*COMMON_HEADER, *header, ",".join(columns)]
    body = np.column_stack(data)
    text = "\n".join(lines) + "\n" + "\n".join(",".join(f % v for f, v in zip(fmt, row, strict=True))
                                              for row in body) + "\n"
    with open(out_path, "wb") as raw, gzip.GzipFile("", "wb", 9, raw, mtime=0) as fh:
        fh.write(text.encode("utf-8"))


def main(argv: list[str], runs: Mapping[str, str], convert: Callable[[Path, Path], int],
         here: str) -> int:
    """Converts each of ``runs`` (source name in argv[1] -> file name in argv[2], by default the
    folder of ``here``, the converter's own file), saying each file written."""
    src = Path(argv[1])
    out = Path(argv[2]) if len(argv) > 2 else Path(here).resolve().parent
    for run, name in runs.items():
        rows = convert(src / run, out / name)
        print(f"{run} -> {out / name}: {rows} rows, {(out / name).stat().st_size} bytes")
    return 0
