"""Fixtures for every test. No Qt here: the core tests must run without it."""

from __future__ import annotations

import datetime as _dt
import gc
import json
import os
import shutil
import tempfile
import threading
import time

import pytest

from fha_studio import clock
from tests.support.clock import FakeClock

#: Fixtures every test may take: a client on a scripted drive (pipes, scripted, client_for),
#: programs in processes of their own (children) and a throw-away PostgreSQL server
#: (postgres_cluster, started once per session by the first test that asks).
pytest_plugins = ["tests.support.links", "tests.support.processes", "tests.support.postgres"]

# Property tests are the same on every run and every machine: a loaded CI machine is no reason
# to fail (no deadline), and an example that fails here fails again there (derandomize).
from hypothesis import settings as _hypothesis_settings  # noqa: E402

_hypothesis_settings.register_profile("fha", deadline=None, derandomize=True, database=None,
                                      print_blob=True)
_hypothesis_settings.load_profile("fha")

# GUI tests run headless; the environment can override (e.g. xcb under xvfb-run).
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

# Nothing the test process or its children do touches the user's own data or settings, not even
# a session fixture set up before the per-test folders below (_user_data_elsewhere, the GUI's
# settings fixture): the whole session starts in folders of its own, removed at its end.
_SESSION_USER_FOLDERS = tempfile.mkdtemp(prefix="fha-tests-user-")
for _variable in ("XDG_DATA_HOME", "XDG_CONFIG_HOME"):
    os.environ[_variable] = os.path.join(_SESSION_USER_FOLDERS, _variable.lower())

# FHA_TEST_TRAVEL_DAYS=400 (or -400) runs the whole session with the calendar moved that far
# (time.time, datetime.now, date.today; the monotonic clock is untouched): a test that holds only
# on today's date fails.
_travel = None


def pytest_configure(config):
    global _travel
    days = os.environ.get("FHA_TEST_TRAVEL_DAYS", "").strip()
    if days:
        import time_machine

        start = _dt.datetime.now(_dt.UTC) + _dt.timedelta(days=float(days))
        _travel = time_machine.travel(start, tick=True)
        _travel.start()


def pytest_collection_finish(session):
    """Every test module and what it imports stays for the whole session: the garbage collector
    need not walk those objects again (gc.freeze). A window's teardown collects garbage, and so
    does Python itself as tests allocate; each full collection walked some 250 000 objects of
    modules (0.2-0.35 s under load, about 100 times a session), now only what tests made."""
    gc.collect()
    gc.freeze()


def pytest_unconfigure(config):
    global _travel
    shutil.rmtree(_SESSION_USER_FOLDERS, ignore_errors=True)
    if _travel is not None:
        _travel.stop()
        _travel = None


@pytest.hookimpl(tryfirst=True)
def pytest_timeout_set_timer(item, settings):
    """pytest-timeout's thread method, with the hanging test's id in one line before the stacks
    (the plugin's own dump names only the functions on them)."""
    if settings.method != "thread":
        return None
    import pytest_timeout

    def expire() -> None:
        capture = item.config.pluginmanager.getplugin("capturemanager")
        if capture is not None:
            capture.suspend_global_capture(item)  # the line goes to the terminal, not the capture
        terminal = item.config.get_terminal_writer()
        terminal.line(f"\nTIMEOUT: {item.nodeid} ran longer than {settings.timeout:g} s", red=True)
        pytest_timeout.timeout_timer(item, settings)  # the captured output, every stack, exit 1

    timer = threading.Timer(settings.timeout, expire)
    timer.name = f"pytest_timeout {item.nodeid}"

    def cancel() -> None:
        timer.cancel()
        timer.join()

    item.cancel_timeout = cancel
    timer.start()
    return True


def pytest_report_header(config):
    if _travel is not None:
        days = os.environ["FHA_TEST_TRAVEL_DAYS"]
        return f"calendar moved {days} days: today is {_dt.datetime.now(_dt.UTC):%Y-%m-%d}"
    return None


@pytest.fixture
def fixed_clock():
    """The one clock every stamp reads (fha_studio.clock): a FakeClock (tests/support/clock.py)
    standing at 2026-11-30 07:00 UTC until the test sets or advances it; the calendar's clock
    returns afterwards."""
    with clock.use(FakeClock("2026-11-30T07:00:00Z")) as fixed:
        yield fixed


@pytest.fixture(autouse=True)
def _user_data_elsewhere(tmp_path_factory, monkeypatch):
    """No test reads or writes the user's data directory (the register, simulated EEPROMs): the
    per-user data directory is a temporary one, and no site register is chosen."""
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path_factory.mktemp("user-data")))
    monkeypatch.delenv("FHA_STUDIO_REGISTER", raising=False)


@pytest.fixture(autouse=True)
def _no_leaked_threads():
    """Fail a test that leaves a thread running (a link worker, a simulated drive, a reader)."""
    before = set(threading.enumerate())
    yield
    deadline = time.monotonic() + 2.0
    while True:
        leaked = [t for t in threading.enumerate() if t not in before and t.is_alive()]
        if not leaked or time.monotonic() > deadline:
            break
        time.sleep(0.01)
    assert not leaked, f"threads left running: {[t.name for t in leaked]}"


@pytest.fixture
def time_ceiling(request):
    """``time_ceiling(what, seconds, ceiling_s)``: a time a test measured stays below a ceiling
    that only a hang reaches (at least 10 x the typical figure). With FHA_TEST_TIMINGS=FILE the
    figure is appended to FILE (a JSON object a line): benchmarks/timing_ceilings.py runs these
    tests several times and prints the typical figures beside their ceilings."""

    def check(what: str, seconds: float, ceiling_s: float) -> None:
        path = os.environ.get("FHA_TEST_TIMINGS")
        if path:
            fact = {"test": request.node.nodeid, "what": what, "seconds": seconds, "ceiling_s": ceiling_s}
            with open(path, "a", encoding="utf-8") as out:
                out.write(json.dumps(fact) + "\n")
        assert seconds < ceiling_s, f"{what}: {seconds:.2f} s; only a hang takes {ceiling_s:g} s"

    return check
