"""The command line into a closed pipe (`fha-studio catalog ... | head -1`): no traceback."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_a_reader_that_goes_away_ends_the_command_quietly():
    script = """
import os, sys
r, w = os.pipe()
os.close(r)  # the reader is gone before anything is written
sys.stdout = os.fdopen(w, "w")
from fha_studio.cli import main
code = main(["catalog", "FHA-25C-50-US250", "--json"])
sys.stderr.write(f"exit={code}\\n")
"""
    result = subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True, text=True)
    assert "Traceback" not in result.stderr and "Exception ignored" not in result.stderr, result.stderr
    assert "exit=141" in result.stderr
