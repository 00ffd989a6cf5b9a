"""Signing with a key kept by a register on a real PostgreSQL server: the window asks the server
(the signer's keys, then the signature recorded) from another thread, never its own. The report
signed so verifies; with the server hung (SIGSTOP) or stopped the sign step says one line, the
session stays unsigned, and the GUI thread is never held (its longest block measured)."""

from __future__ import annotations

import time
from urllib.parse import urlsplit

import pytest

from fha_studio.cli import main
from fha_studio.gui import register_questions
from fha_studio.logic.procedures import ProcedureSession
from tests.gui.procedures.test_signed_report import _finished_session
from tests.gui.test_window_register_server import GuiThreadWatch, _hung

SIGNER = "A. Reviewer"


@pytest.fixture
def signing_window(qtbot, tmp_path, monkeypatch, postgres_cluster, make_cli_window):
    """The single-axis window on a new database of the tests' server, whose register keeps the
    signer's key (without a passphrase); its Procedures page with a finished session open (the
    window closed before the settings above are undone: make_cli_window comes after them)."""
    monkeypatch.setattr(register_questions, "SLOW_S", 0.3)
    monkeypatch.setattr(register_questions, "GIVE_UP_S", 1.0)
    url = postgres_cluster.new_database()
    monkeypatch.setenv("FHA_STUDIO_KEY_PASSPHRASE", "")
    assert main(["register", "--register", url, "keys", "add", "--name", SIGNER]) == 0
    _finished_session(tmp_path / "axis1.json")
    window = make_cli_window("--register", url, "--machine", "Line 3", "--axis", "table")
    page = window.show_page("procedures")
    page.open_session(tmp_path / "axis1.json")
    return window, page, url


def _unsigned(path) -> bool:
    return not ProcedureSession.load(path).signature


def test_signing_asks_the_server_from_another_thread(signing_window, qtbot, tmp_path, postgres_cluster,
                                                     time_ceiling):
    window, page, url = signing_window
    session_file = tmp_path / "axis1.json"
    answered: list = []  # the questions' own connection to the server, open before it hangs
    window.register_questions.ask("the register's schema", lambda register: register.version, answered.append)
    qtbot.waitUntil(lambda: bool(answered), timeout=30000)
    watch = GuiThreadWatch()
    try:
        # the server hangs (a new connection too): the sign step says so in one line, nothing is
        # signed
        with _hung(postgres_cluster, urlsplit(url).path.lstrip("/"), postmaster=True):
            started = time.monotonic()
            with qtbot.waitSignal(page.sigSigned, timeout=30000) as ended:
                assert not page.sign(SIGNER)  # asked of the server: the answer comes later
                said = page.message_label.text()
                assert said == "Signing: asking the register on the server for the signer's key…"
                time_ceiling("signing handed to the register's thread", time.monotonic() - started, 1.0)
            assert ended.args == [False]
            said = page.message_label.text()
            assert said.startswith("Not signed: the register postgresql://fha@") and "did not answer" in said
            assert "\n" not in said and "fha-test-password" not in said and _unsigned(session_file)
        # it answers again: signed with the key, recorded on the server; the files verify
        with qtbot.waitSignal(page.sigSigned, timeout=30000) as ended:
            page.sign(SIGNER)
        assert ended.args == [True], page.message_label.text()
        assert page.message_label.text().startswith(f"Signed by {SIGNER} with key ")
        html, pdf = page.write_report(tmp_path / "report.html", tmp_path / "report.pdf")
        assert main(["register", "--register", url, "verify", str(html)]) == 0
        qtbot.waitUntil(lambda: main(["register", "--register", url, "verify", str(pdf)]) == 0, timeout=30000)
        # the server stops: one line at once, the session as it was
        page.session.signature = {}
        page.session.save()
        with watch.paused():
            postgres_cluster.stop()
        try:
            with qtbot.waitSignal(page.sigSigned, timeout=30000) as ended:
                page.sign(SIGNER)
            assert ended.args == [False] and "the server" in page.message_label.text()
            assert _unsigned(session_file)
        finally:
            with watch.paused():
                postgres_cluster.start()
    finally:
        watch.stop()
    time_ceiling("the GUI thread blocked", watch.longest_s, 3.0)
