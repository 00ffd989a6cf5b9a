"""Where the data directories (resources/, ui/) are, installed or in a checkout."""

from __future__ import annotations

import os
import sys
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


#: Names the GUI gives Qt (QCoreApplication organisation and application): its per-user data
#: directory is built from them, and the Qt-free code finds the same directory here.
ORGANISATION = "FHA Studio"
APPLICATION = "fha-studio"


def user_data_dir() -> Path:
    """The per-user data directory, the same one the GUI gets from Qt's ``AppDataLocation``:
    ``$XDG_DATA_HOME/FHA Studio/fha-studio`` (``~/.local/share/...``) on Linux,
    ``~/Library/Application Support/...`` on macOS, ``%APPDATA%\\...`` on Windows. Not created here."""
    if sys.platform == "win32":
        base = Path(os.environ.get("APPDATA") or Path.home() / "AppData" / "Roaming")
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Application Support"
    else:
        base = Path(os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share")
    return base / ORGANISATION / APPLICATION
