"""The pages of the main window, in tab order: :data:`PAGES`.

A new page is a module (``gui/pages/<name>.py``) or a package (``gui/pages/<name>/``) with a
:class:`~fha_studio.gui.pages.base.BasePage` subclass built as ``Page(session, main_window)``,
a member of :class:`~fha_studio.gui.pages.base.PageId`, and one :class:`PageEntry` here. The
title and mnemonic belong to the entry, not to the page: the tab exists before a lazy page's
module is imported.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from fha_studio.gui.pages.absolute import AbsolutePage
from fha_studio.gui.pages.alarms import AlarmsPage
from fha_studio.gui.pages.base import Page, PageHost, PageId
from fha_studio.gui.pages.connection import ConnectionPage
from fha_studio.gui.pages.direction import DirectionPage
from fha_studio.gui.pages.jog import JogPage
from fha_studio.gui.pages.parameters import ParametersPage
from fha_studio.gui.session import Session


@dataclass(frozen=True)
class PageEntry:
    """One tab: its page's id, its title and the letter of the title that Alt selects it with,
    how the page is built, and whether it is built only when first shown."""

    id: PageId
    title: str
    mnemonic: str
    build: Callable[[Session, PageHost], Page]
    lazy: bool = False

    def __post_init__(self) -> None:
        if len(self.mnemonic) != 1 or self.mnemonic.lower() not in self.title.lower():
            raise ValueError(f"page {self.id}: mnemonic {self.mnemonic!r} is not a letter of {self.title!r}")

    @property
    def tab_text(self) -> str:
        """The title with ``&`` before the mnemonic (and a literal ``&`` doubled), for Qt."""
        at = self.title.find(self.mnemonic)
        if at < 0:
            at = self.title.lower().find(self.mnemonic.lower())
        head, tail = self.title[:at], self.title[at:]
        return head.replace("&", "&&") + "&" + tail.replace("&", "&&")


# pages with plots (pyqtgraph, numpy, scipy) are imported and built when first shown, so that
# start-up stays short
def _sizing(session: Session, window: PageHost) -> Page:
    from fha_studio.gui.pages.sizing import SizingPage

    return SizingPage(session, window)


def _scope(session: Session, window: PageHost) -> Page:
    from fha_studio.gui.pages.scope.page import ScopePage

    return ScopePage(session, window)


def _procedures(session: Session, window: PageHost) -> Page:
    from fha_studio.gui.pages.procedures.page import ProceduresPage

    return ProceduresPage(session, window)


def _modelcheck(session: Session, window: PageHost) -> Page:
    from fha_studio.gui.pages.modelcheck.page import ModelCheckPage

    return ModelCheckPage(session, window)


def _tuning(session: Session, window: PageHost) -> Page:
    from fha_studio.gui.pages.tuning import TuningPage

    return TuningPage(session, window)


#: Every page, in tab order.
PAGES: tuple[PageEntry, ...] = (
    PageEntry(PageId.CONNECTION, "Connection", "o", ConnectionPage),
    PageEntry(PageId.PARAMETERS, "Parameters", "P", ParametersPage),
    PageEntry(PageId.DIRECTION, "Rotary direction", "R", DirectionPage),
    PageEntry(PageId.ALARMS, "Alarms", "A", AlarmsPage),
    PageEntry(PageId.JOG, "Jog & test run", "J", JogPage),
    PageEntry(PageId.ABSOLUTE, "DGR checks", "G", AbsolutePage),
    PageEntry(PageId.SIZING, "Sizing", "z", _sizing, lazy=True),
    PageEntry(PageId.SCOPE, "Scope", "S", _scope, lazy=True),
    PageEntry(PageId.PROCEDURES, "Procedures", "u", _procedures, lazy=True),
    PageEntry(PageId.MODELCHECK, "Model check", "k", _modelcheck, lazy=True),
    PageEntry(PageId.TUNING, "Tuning", "T", _tuning, lazy=True),
)
