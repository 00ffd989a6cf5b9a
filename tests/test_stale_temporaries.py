"""A write killed halfway leaves ``.NAME.XXXXXXXX.tmp`` beside its target; the next write of that
target removes it (when it is older than a write takes), and leaves a write going on alone."""

from __future__ import annotations

import os
import time

from fha_studio import fileio
from fha_studio.main import main


def _left_over(folder, name, age_s, middle="abcd1234"):
    tmp = folder / f".{name}.{middle}.tmp"
    tmp.write_bytes(b"x" * 1000)
    then = time.time() - age_s
    os.utime(tmp, (then, then))
    return tmp


def test_the_next_write_removes_what_a_killed_write_left(tmp_path):
    stale = _left_over(tmp_path, "export.json", 3600)
    fresh = _left_over(tmp_path, "export.json", 0, "wxyz5678")  # another process writing it now
    other = _left_over(tmp_path, "other.json", 3600)
    fileio.write_text(tmp_path / "export.json", "{}\n")
    assert not stale.exists() and fresh.exists() and other.exists()
    assert (tmp_path / "export.json").read_text() == "{}\n"


def test_register_export_removes_a_stale_temporary(tmp_path, capsys):
    from fha_studio.logic.register import Register

    Register(tmp_path / "r.sqlite").close()
    stale = _left_over(tmp_path, "export.json", 3600)
    out = tmp_path / "export.json"
    assert main(["register", "--register", str(tmp_path / "r.sqlite"), "export", "-o", str(out)]) == 0
    assert not stale.exists() and out.exists()
