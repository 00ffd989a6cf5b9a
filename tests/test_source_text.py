"""House style of the source text: a comment or docstring says the reason, never points at an
issue (or ticket) number, which a reader of the code cannot follow."""

from __future__ import annotations

import ast
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


#: The standard serial rates: two of them in one literal make a list of baud rates.
_SERIAL_RATES = {1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200}


def _docstrings(tree: ast.AST) -> set[int]:
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                found.add(id(body[0].value))
    return found


def test_the_baud_rates_are_written_only_in_the_protocol_module():
    """CN3's rate (protocol.BAUDRATE) and the rates a link opens at (protocol.BAUD_RATES) are one
    fact each: no other module writes 19200, nor a list of rates, in its code or its messages."""
    from fha_studio.hardware import protocol

    assert protocol.BAUDRATE == 19200 and protocol.BAUDRATE in protocol.BAUD_RATES
    home = ROOT / "fha_studio" / "hardware" / "protocol.py"
    found = []
    for path in sorted(ROOT.joinpath("fha_studio").rglob("*.py")):
        if path == home:
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        docstrings = _docstrings(tree)
        for node in ast.walk(tree):
            where = f"{path.relative_to(ROOT)}:{getattr(node, 'lineno', '?')}"
            if isinstance(node, ast.Constant) and id(node) not in docstrings:
                if node.value == 19200 and not isinstance(node.value, bool):
                    found.append(f"{where}: 19200")
                elif isinstance(node.value, str) and "19200" in node.value:
                    found.append(f"{where}: {node.value!r}")
            elif isinstance(node, ast.Tuple | ast.List | ast.Set):
                rates = [e.value for e in node.elts
                         if isinstance(e, ast.Constant) and e.value in _SERIAL_RATES]
                if len(rates) >= 2:
                    found.append(f"{where}: a list of baud rates {rates}")
    assert not found, "use protocol.BAUDRATE / protocol.BAUD_RATES:\n" + "\n".join(found)
