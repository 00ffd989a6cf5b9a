"""The malformed-input corpus (tests/corpus/expected.toml): each file and command line is refused
whole with the expected line, exit status 2 on the command line, no traceback; what a write killed
halfway leaves is gone after the next start."""

from __future__ import annotations

import os
import tomllib
from pathlib import Path

import pytest
from corpus_readers import READERS

from fha_studio.main import main as cli_main
from tests.support.killed_writer import KILLED_WRITER
from tests.support.processes import Child

CORPUS = Path(__file__).parent / "corpus"
MANIFEST = tomllib.loads((CORPUS / "expected.toml").read_text(encoding="utf-8"))


def test_every_corpus_file_has_its_expected_message():
    listed = {case["path"] for case in MANIFEST["file"]}
    on_disk = {str(p.relative_to(CORPUS)) for p in CORPUS.rglob("*")
               if p.is_file() and p.name != "expected.toml"}
    assert on_disk == listed


@pytest.mark.parametrize("case", MANIFEST["file"], ids=[c["path"] for c in MANIFEST["file"]])
def test_a_malformed_file_is_refused_with_one_line_naming_it(case):
    path = CORPUS / case["path"]
    reader = READERS[case["path"].split("/")[0]]
    with pytest.raises(ValueError) as err:
        reader(path)
    message = str(err.value)
    assert case["expect"] in message
    assert str(path) in message
    assert "\n" not in message and "Traceback" not in message


@pytest.fixture
def scratch(tmp_path):
    (tmp_path / "afile").write_text("a regular file")
    os.mkfifo(tmp_path / "fifo")
    from fha_studio.logic.register import Register

    Register(tmp_path / "r.sqlite").close()  # the register the register cases ask (it must exist)
    return tmp_path


@pytest.mark.parametrize("case", MANIFEST["cli"], ids=[" ".join(c["args"])[:70] for c in MANIFEST["cli"]])
def test_a_malformed_command_line_is_refused_with_one_line(case, scratch, capsys):
    values = {"corpus": str(CORPUS), "tmp": str(scratch), "long": "n" * 300}
    args = [a.format(**values) for a in case["args"]]
    before = _corpus_bytes()
    try:
        code = cli_main(args)
    except SystemExit as exc:  # argparse refuses an option value
        code = exc.code
    assert code == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert case["expect"] in err
    # "fha-studio COMMAND: error: ...", or "fha-studio: error: ..." for what no command took
    assert err.count("\n") == 1 and err.startswith(("fha-studio ", "fha-studio: "))
    # nothing half-written (a register file may have been opened: it is the input, not an output)
    # (and SQLite's -wal and -shm files beside it)
    assert sorted(p.name for p in scratch.iterdir() if not p.name.startswith("r.sqlite")) == ["afile", "fifo"]
    # and a refused input is left as it was: a question on a damaged register of an older schema
    # was upgraded first (WAL switched on, the file changed) before the damage was found
    assert _corpus_bytes() == before


def _corpus_bytes() -> dict[str, bytes]:
    return {str(p.relative_to(CORPUS)): p.read_bytes() for p in CORPUS.rglob("*") if p.is_file()}


@pytest.mark.parametrize("case", MANIFEST["killed"], ids=[c["output"] for c in MANIFEST["killed"]])
def test_what_a_killed_write_left_is_gone_after_the_next_start(case, tmp_path, children):
    import subprocess
    import sys

    from fha_studio.logic.register import Register

    with Register(tmp_path / "r.sqlite") as register:
        register.add_machine("M")
    args = [a.format(tmp=tmp_path) for a in case["args"]]
    env = {**os.environ, "PYTHONPATH": str(CORPUS.parents[1])}
    writer = children(Child.python, "-c", KILLED_WRITER, *args, cwd=tmp_path, env={"HOLD": case["output"]},
                      text=True)
    try:
        assert writer.first_line("the killed writer", within_s=120) == "writing"
        (temporary,) = tmp_path.glob(f".{case['output']}.*.tmp")
    finally:
        writer.kill()
    assert not (tmp_path / case["output"]).exists()
    then = temporary.stat().st_mtime - 120  # the minute a start leaves a temporary for
    os.utime(temporary, (then, then))
    fresh = subprocess.run([sys.executable, "-m", "fha_studio", "--help"], cwd=tmp_path, env=env,
                           capture_output=True, text=True, timeout=120)
    assert fresh.returncode == 0 and fresh.stderr == ""
    assert not temporary.exists() and not (tmp_path / case["output"]).exists()
