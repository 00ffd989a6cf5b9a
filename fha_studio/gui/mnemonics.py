"""Alt + a letter must reach one thing: the window's page tabs and toolbar actions own their
letters on every page; inside a page the first widget to claim a letter keeps it. A page built
later (or a label written by someone who did not know the window's letters) cannot take a page's
letter and make Alt+R read all parameters instead of showing the Rotary direction page."""

from __future__ import annotations

import re

from PySide6.QtWidgets import QAbstractButton, QGroupBox, QLabel, QTabBar, QToolButton, QWidget

_MNEMONIC = re.compile(r"&([^&\s])")


def mnemonic(text: str) -> str | None:
    """The letter after a single '&' in ``text`` (lower case), or None ('&&' is a literal &)."""
    match = _MNEMONIC.search(text.replace("&&", ""))
    return match.group(1).lower() if match else None


def _without_mnemonic(text: str) -> str:
    return text.replace("&&", "\0").replace("&", "").replace("\0", "&&")


def resolve_mnemonics(page: QWidget, reserved: set[str]) -> list[str]:
    """Removes the '&' from every button, buddy label or group box in ``page`` whose letter is in
    ``reserved`` or already taken earlier in the page (in creation order). Returns what changed,
    as plain texts, for the log."""
    taken = set(reserved)
    changed = []

    def check(text: str, setter) -> None:
        letter = mnemonic(text)
        if letter is None:
            return
        if letter in taken:
            setter(_without_mnemonic(text))
            changed.append(_without_mnemonic(text))
        else:
            taken.add(letter)

    for widget in page.findChildren(QWidget):
        if isinstance(widget, QToolButton) and widget.defaultAction() is not None:
            continue
        button = isinstance(widget, QAbstractButton) and not isinstance(widget.parent(), QTabBar)
        labelled = isinstance(widget, QLabel) and widget.buddy() is not None
        if (isinstance(widget, QAbstractButton) and button) or (isinstance(widget, QLabel) and labelled):
            check(widget.text(), widget.setText)
        elif isinstance(widget, QGroupBox):
            check(widget.title(), widget.setTitle)
    return changed


__all__ = ["mnemonic", "resolve_mnemonics"]
