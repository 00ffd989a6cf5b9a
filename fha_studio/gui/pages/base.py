"""What the main window expects of a page: the :class:`Page` protocol, and :class:`BasePage`,
a QWidget with nothing to save, restore, stop or follow, that pages derive from and override.

The main window calls the hooks; a page does not look for the window's methods or connect to
the link's connect / disconnect signals itself, so a page built after the link came up (the
pages with plots are built when first shown) hears of the link exactly as the others do.
"""

from __future__ import annotations

from enum import StrEnum
from typing import Protocol, runtime_checkable

from PySide6.QtCore import QSettings
from PySide6.QtWidgets import QWidget

from fha_studio.gui.link import LinkInfo


class PageId(StrEnum):
    """The pages by name (``window.show_page(PageId.SCOPE)`` or ``show_page("scope")``)."""

    CONNECTION = "connection"
    PARAMETERS = "parameters"
    DIRECTION = "direction"
    ALARMS = "alarms"
    JOG = "jog"
    ABSOLUTE = "absolute"
    SIZING = "sizing"
    SCOPE = "scope"
    PROCEDURES = "procedures"
    MODELCHECK = "modelcheck"
    TUNING = "tuning"


@runtime_checkable
class Page(Protocol):
    """A page of the main window (also a QWidget: the tab's contents)."""

    def restore_settings(self, settings: QSettings) -> None:
        """Take what :meth:`save_settings` stored (called once, after the page is built)."""

    def save_settings(self, settings: QSettings) -> None:
        """Store what the person set up, under the page's own keys, for the next start."""

    def shutdown(self) -> None:
        """The window closes: release held buttons, stop threads (idempotent)."""

    def release_held(self) -> None:
        """Let go of whatever the page holds down (a hold-to-run jog): STOP does it on every page."""

    def link_connected(self, info: LinkInfo) -> None:
        """A drive is connected (or was already, when the page is built later)."""

    def link_disconnected(self, reason: str, lost: bool) -> None:
        """The drive went away: ``lost`` when the link died rather than was closed."""


class PageHost(Protocol):
    """The window a page is on, as the page may use it. A page reaches another page by id and
    narrows what it gets with ``isinstance`` (the window's own lookup, ``pages/lookup.py``, names
    every page's class, which a page cannot import without an import circle)."""

    def page(self, name: PageId) -> Page:
        """The page ``name``, built now if it is a lazy page not yet shown."""

    def built_page(self, name: PageId) -> Page | None:
        """The page ``name`` if it has been built, else None."""

    def show_page(self, name: PageId) -> Page:
        """Shows the page ``name`` and returns it."""


class BasePage(QWidget):
    """A page with every hook of :class:`Page` doing nothing."""

    def restore_settings(self, settings: QSettings) -> None:
        pass

    def save_settings(self, settings: QSettings) -> None:
        pass

    def shutdown(self) -> None:
        pass

    def release_held(self) -> None:
        pass

    def link_connected(self, info: LinkInfo) -> None:
        pass

    def link_disconnected(self, reason: str, lost: bool) -> None:
        pass
