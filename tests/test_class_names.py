"""A class name means one class: no two modules of fha_studio define a class of the same name, so a
reader (and a traceback) never has to ask which one."""

from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

import fha_studio

PACKAGE = Path(fha_studio.__file__).parent


def test_no_two_modules_define_a_class_of_the_same_name():
    where: dict[str, list[str]] = defaultdict(list)
    for path in sorted(PACKAGE.rglob("*.py")):
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if isinstance(node, ast.ClassDef):
                where[node.name].append(str(path.relative_to(PACKAGE)))
    shared = {name: files for name, files in where.items() if len(files) > 1}
    assert not shared, f"class names defined more than once: {shared}"
