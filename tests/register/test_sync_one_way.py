"""A sync that only sends (``sync_registers(..., send_only=True)``, ``register sync --send-only``):
what the source has and the target lacks goes to the target, each fact once by its stable id, and
nothing comes back (the GUI's queue for a server delivers so: a window on a large plant register
does not copy the plant's history to this computer). What both changed while apart is still a
conflict; what the target knew before is not."""

from __future__ import annotations

from pathlib import Path

import pytest

from fha_studio.cli import main
from fha_studio.logic.register.sync import BATCH_FACTS

README = Path(__file__).resolve().parents[2] / "README.md"


def test_the_batch_size_is_said_as_the_code_has_it(capsys):
    with pytest.raises(SystemExit):
        main(["register", "sync", "--help"])
    assert f"(default {BATCH_FACTS};" in " ".join(capsys.readouterr().out.split())
    assert f"each batch of facts ({BATCH_FACTS}, `--batch N`)" in " ".join(README.read_text("utf-8").split())
