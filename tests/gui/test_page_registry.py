"""The page registry: tabs in its order, every page keeps the page protocol, and the main window
gives each page its settings and the link's connect / disconnect, also to a page built late."""

from __future__ import annotations

import pytest
from PySide6.QtCore import QSettings
from PySide6.QtWidgets import QWidget

from fha_studio.gui.main_window import MainWindow
from fha_studio.gui.pages.base import BasePage, Page, PageId
from fha_studio.gui.pages.registry import PAGES, PageEntry
from tests.gui.fake_drive import FakeDriveClient


def test_every_page_has_one_entry_and_its_own_alt_letter():
    assert [e.id for e in PAGES] == list(PageId)
    letters = [e.mnemonic.lower() for e in PAGES]
    assert len(set(letters)) == len(letters), letters
    assert PAGES[4].tab_text == "&Jog && test run"  # a literal & is doubled, the mnemonic marked
    with pytest.raises(ValueError, match="mnemonic 'q'"):
        PageEntry(PageId.JOG, "Jog", "q", BasePage)


def test_tabs_follow_the_registry_and_every_page_keeps_the_protocol(make_window):
    window = make_window(show=False)
    assert [window.tabs.tabText(i) for i in range(window.tabs.count())] == [e.tab_text for e in PAGES]
    for entry in PAGES:
        page = window.page(entry.id)
        assert isinstance(page, Page) and isinstance(page, QWidget), entry.id
    with pytest.raises(ValueError, match="no page 'plots'; pages: connection, parameters"):
        window.show_page("plots")


class _Spy(BasePage):
    def __init__(self, session, main_window=None):
        super().__init__()
        self.calls: list[tuple] = []

    def restore_settings(self, settings: QSettings) -> None:
        self.calls.append(("restore",))

    def link_connected(self, info) -> None:
        self.calls.append(("connected", info.url))

    def link_disconnected(self, reason: str, lost: bool) -> None:
        self.calls.append(("disconnected", lost))


def test_pages_hear_of_the_link_also_when_built_after_it_came_up(make_window, qtbot, monkeypatch):
    spy_for = {PageId.DIRECTION: PageEntry(PageId.DIRECTION, "Eager", "e", _Spy),
               PageId.SCOPE: PageEntry(PageId.SCOPE, "Lazy", "l", _Spy, lazy=True)}
    spies = tuple(spy_for.get(e.id, e) for e in PAGES)
    monkeypatch.setattr("fha_studio.gui.main_window.PAGES", spies)
    window: MainWindow = make_window(open_client=lambda url, baud: FakeDriveClient(), connect="fake://")
    eager = window.built_page(PageId.DIRECTION)
    assert window.built_page(PageId.SCOPE) is None  # not shown yet: not built
    assert eager.calls == [("restore",), ("connected", "fake://")]
    lazy = window.show_page(PageId.SCOPE)
    assert lazy.calls == [("restore",), ("connected", "fake://")]
    with qtbot.waitSignal(window.link.sigDisconnected, timeout=10000):
        window.link.close_link()
    assert eager.calls[-1] == lazy.calls[-1] == ("disconnected", False)


def test_the_page_option_offers_every_page_and_refuses_another(capsys):
    from fha_studio.gui.app import _parser

    assert _parser().parse_args(["--page", "modelcheck"]).page == "modelcheck"
    with pytest.raises(SystemExit):
        _parser().parse_args(["--page", "plots"])
    assert "invalid choice: 'plots'" in capsys.readouterr().err


def test_each_page_id_is_typed_as_the_class_of_the_page_it_gives(make_window):
    """``window.page(PageId.DIRECTION)`` is a DirectionPage to the type checker (the overloads of
    gui/pages/lookup.py) and at run time: one overload per page, each naming the page's class."""
    import typing

    from fha_studio.gui.pages import lookup
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

    names = {**vars(lookup), **{c.__name__: c for c in (
        AbsolutePage, AlarmsPage, ConnectionPage, DirectionPage, JogPage, ModelCheckPage, ParametersPage,
        ProceduresPage, ScopePage, SizingPage, TuningPage)}}
    for method in (lookup.PageLookup.page, lookup.PageLookup.built_page):
        typed = {}
        for overload in typing.get_overloads(method):
            hints = typing.get_type_hints(overload, globalns=names)
            if typing.get_origin(hints["name"]) is typing.Literal:  # not the fallback for any id
                (page_id,) = typing.get_args(hints["name"])
                returned = typing.get_args(hints["return"]) or (hints["return"],)  # X or X | None
                typed[page_id] = returned[0]
        assert set(typed) == set(PageId), method.__name__
    window = make_window(show=False)
    for page_id, cls in typed.items():
        assert type(window.page(page_id)) is cls, page_id
        assert type(window.built_page(page_id)) is cls, page_id
