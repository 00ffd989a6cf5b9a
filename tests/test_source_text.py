"""House style of the source text: a comment or docstring says the reason, never points at an
issue (or ticket) number, which a reader of the code cannot follow."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ISSUE_REFERENCE = re.compile(r"\b(issue|ticket)\s*#?\d+|\(#\d+\)|\bgh-\d+", re.IGNORECASE)


def test_no_source_text_points_at_an_issue_number():
    files = [*ROOT.joinpath("fha_studio").rglob("*.py"), *ROOT.joinpath("tests").rglob("*.py"),
             *ROOT.joinpath("docs").rglob("*.md"), ROOT / "README.md"]
    found = [
        f"{path.relative_to(ROOT)}:{number}: {line.strip()}"
        for path in files
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if ISSUE_REFERENCE.search(line)
    ]
    assert not found, "say the reason instead of an issue number:\n" + "\n".join(found)
