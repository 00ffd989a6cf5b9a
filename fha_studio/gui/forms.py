"""Loading Qt Designer forms from ui/ at run time."""

from __future__ import annotations

from PySide6.QtCore import QFile, QIODevice
from PySide6.QtUiTools import QUiLoader
from PySide6.QtWidgets import QWidget

from fha_studio.paths import ui_dir


def load_form(name: str, parent: QWidget | None = None) -> QWidget:
    """Builds the widget described by ui/NAME.ui; children are found with findChild by name."""
    path = ui_dir() / name
    file = QFile(str(path))
    if not file.open(QIODevice.OpenModeFlag.ReadOnly):
        raise FileNotFoundError(f"form not found: {path}")
    try:
        widget = QUiLoader().load(file, parent)
    finally:
        file.close()
    if widget is None:
        raise RuntimeError(f"form could not be loaded: {path}")
    return widget


def child(form: QWidget, cls: type, name: str):
    """The child `name` of a loaded form; a clear error when the form lacks it."""
    found = form.findChild(cls, name)
    if found is None:
        raise LookupError(f"the form {form.objectName()} has no {cls.__name__} named {name!r}")
    return found
