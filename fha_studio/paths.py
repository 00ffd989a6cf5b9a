"""Where the data directories (resources/, ui/) are, installed or in a checkout."""

from __future__ import annotations

from pathlib import Path

_PACKAGE_DIR = Path(__file__).resolve().parent


def _data_dir(name: str) -> Path:
    # In a wheel the directory is copied into the package (pyproject force-include);
    # in a checkout or an editable install it sits beside the package.
    for candidate in (_PACKAGE_DIR / name, _PACKAGE_DIR.parent / name):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(f"fha_studio data directory '{name}' not found next to {_PACKAGE_DIR}")


def resources_dir() -> Path:
    """The resources/ directory: catalogue, parameter definitions, checklists, icons."""
    return _data_dir("resources")


def ui_dir() -> Path:
    """The ui/ directory with the Qt Designer forms."""
    return _data_dir("ui")


def resource(*parts: str) -> Path:
    """Path of one file under resources/; raises FileNotFoundError naming it when missing."""
    path = resources_dir().joinpath(*parts)
    if not path.exists():
        raise FileNotFoundError(f"resource not found: {path}")
    return path
