"""The pages by id, each as its own class: ``window.page(PageId.DIRECTION)`` is a
:class:`~fha_studio.gui.pages.direction.DirectionPage` to the type checker, so code above the pages
(the main window, the machine window, training) uses a page's attributes without ``getattr``.

:class:`PageLookup` is a mixin of the main window, which says where a page is
(:meth:`PageLookup._find_page`). A page cannot import this module (it names every page's class,
and no import circle is allowed): a page reaches another through
:class:`~fha_studio.gui.pages.base.PageHost` and narrows what it gets with ``isinstance``.
``tests/gui/test_page_registry.py`` checks that every :class:`PageId` has its overload here and
that the page built is of the class it names. The lazy pages' classes are named for the type
checker only, so importing this module imports no plots.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal, overload

from fha_studio.gui.pages.base import Page, PageId

if TYPE_CHECKING:
    from fha_studio.gui.pages.absolute import AbsolutePage
    from fha_studio.gui.pages.alarms import AlarmsPage
    from fha_studio.gui.pages.connection import ConnectionPage
    from fha_studio.gui.pages.direction import DirectionPage
    from fha_studio.gui.pages.jog import JogPage
    from fha_studio.gui.pages.modelcheck.page import ModelCheckPage
    from fha_studio.gui.pages.parameters import ParametersPage
    from fha_studio.gui.pages.procedures.page import ProceduresPage
    from fha_studio.gui.pages.scope.page import ScopePage
    from fha_studio.gui.pages.sizing import SizingPage
    from fha_studio.gui.pages.tuning import TuningPage


class PageLookup:
    """``page(id)`` (built now if it is a lazy page not yet shown) and ``built_page(id)`` (None
    until then), typed by id."""

    def _find_page(self, name: PageId | str, build: bool) -> Page | None:
        """The page ``name``; built when ``build``, else None for a lazy page not yet built."""
        raise NotImplementedError

    @overload
    def page(self, name: Literal[PageId.CONNECTION]) -> ConnectionPage: ...
    @overload
    def page(self, name: Literal[PageId.PARAMETERS]) -> ParametersPage: ...
    @overload
    def page(self, name: Literal[PageId.DIRECTION]) -> DirectionPage: ...
    @overload
    def page(self, name: Literal[PageId.ALARMS]) -> AlarmsPage: ...
    @overload
    def page(self, name: Literal[PageId.JOG]) -> JogPage: ...
    @overload
    def page(self, name: Literal[PageId.ABSOLUTE]) -> AbsolutePage: ...
    @overload
    def page(self, name: Literal[PageId.SIZING]) -> SizingPage: ...
    @overload
    def page(self, name: Literal[PageId.SCOPE]) -> ScopePage: ...
    @overload
    def page(self, name: Literal[PageId.PROCEDURES]) -> ProceduresPage: ...
    @overload
    def page(self, name: Literal[PageId.MODELCHECK]) -> ModelCheckPage: ...
    @overload
    def page(self, name: Literal[PageId.TUNING]) -> TuningPage: ...
    @overload
    def page(self, name: PageId | str) -> Page: ...

    def page(self, name: PageId | str) -> Page:
        """The page ``name`` (a :class:`PageId` or its value), built now if it is a lazy page not
        yet shown; ValueError naming the pages otherwise."""
        page = self._find_page(name, build=True)
        assert page is not None
        return page

    @overload
    def built_page(self, name: Literal[PageId.CONNECTION]) -> ConnectionPage | None: ...
    @overload
    def built_page(self, name: Literal[PageId.PARAMETERS]) -> ParametersPage | None: ...
    @overload
    def built_page(self, name: Literal[PageId.DIRECTION]) -> DirectionPage | None: ...
    @overload
    def built_page(self, name: Literal[PageId.ALARMS]) -> AlarmsPage | None: ...
    @overload
    def built_page(self, name: Literal[PageId.JOG]) -> JogPage | None: ...
    @overload
    def built_page(self, name: Literal[PageId.ABSOLUTE]) -> AbsolutePage | None: ...
    @overload
    def built_page(self, name: Literal[PageId.SIZING]) -> SizingPage | None: ...
    @overload
    def built_page(self, name: Literal[PageId.SCOPE]) -> ScopePage | None: ...
    @overload
    def built_page(self, name: Literal[PageId.PROCEDURES]) -> ProceduresPage | None: ...
    @overload
    def built_page(self, name: Literal[PageId.MODELCHECK]) -> ModelCheckPage | None: ...
    @overload
    def built_page(self, name: Literal[PageId.TUNING]) -> TuningPage | None: ...
    @overload
    def built_page(self, name: PageId) -> Page | None: ...

    def built_page(self, name: PageId) -> Page | None:
        """The page ``name`` if it has been built (a lazy page is built when first shown), else None."""
        return self._find_page(name, build=False)
