"""The Procedures page's steps that a move seen on the bench answers (``bench = KIND`` in the
procedure file, :mod:`fha_studio.logic.procedures.bench_steps`).

While the Scope's Bench tab streams the encoder outputs and the command lines (a file or a live
instrument), such a step says so and what to do; the checks the Bench tab takes of the next move
that settles (the same that go to the DGR checks page) answer it, recorded with the operator and
the time like any answer, and so into the report. A move that cannot answer it (a REV command,
parameter 8 not known) is said in one line and nothing is recorded.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Protocol

from fha_studio.gui.pages.base import PageHost, PageId
from fha_studio.logic.bench.checks import BenchCheck
from fha_studio.logic.procedures import Observation, ProcedureRun, Step
from fha_studio.logic.procedures.bench_steps import PROMPTS, answer_from_bench, bench_kind, parameter_8_of_run


class _Page(Protocol):
    """What the watch uses of the Procedures page."""

    main_window: PageHost | None
    run: ProcedureRun | None
    state: Any  # the axis's state: value_of(mode, number)

    def current_step(self) -> Step | None: ...
    def axis_mismatch(self) -> str: ...
    def answer(self, value: Any, detail: str = "") -> bool: ...
    def show_message(self, text: str) -> None: ...
    def bench_changed(self, *_args: object) -> None: ...
    def bench_move(self, checks: Sequence[BenchCheck]) -> None: ...


class BenchWatch:
    """Listens to the Scope's Bench tab (once that page is built) for the page."""

    def __init__(self, page: _Page):
        self.page = page
        self._panel: Any = None  # the Bench tab listened to

    def _scope(self) -> Any:
        from fha_studio.gui.pages.scope.page import ScopePage

        window = self.page.main_window
        scope = window.built_page(PageId.SCOPE) if window is not None else None
        return scope if isinstance(scope, ScopePage) else None

    def attach(self) -> None:
        """Listen to the Bench tab's moves and its stream's start and stop (the Scope page is
        built when the technician opens it, after this page may have been)."""
        scope = self._scope()
        if scope is None or scope.bench is self._panel:
            return
        self._panel = scope.bench
        # the page's own methods: Qt lets go of them with the page
        scope.bench.sigChecks.connect(self.page.bench_move)
        scope.bench.source.sigStarted.connect(self.page.bench_changed)
        scope.bench.source.sigStopped.connect(self.page.bench_changed)

    def watching(self) -> str:
        """``sim-cn2 (encoder ENC_A,ENC_B, command CMD_A,CMD_B)`` while the Bench tab streams both,
        else ""."""
        scope = self._scope()
        return scope.bench_watching() if scope is not None else ""

    def note(self) -> str:
        """What the step on show says about the bench ("" for a step no bench move answers)."""
        page = self.page
        kind = bench_kind(page.current_step())
        if not kind or page.run is None or page.run.stopped:
            return ""
        source = self.watching()
        if not source:
            return ("A bench instrument on CN2 can answer this step while the servo is on: start it on the "
                    "Scope's Bench tab with the encoder (A,B) and the command lines mapped.")
        return f"The bench watches CN2 on {source}: {PROMPTS[kind]}."

    def parameter_8(self) -> int | None:
        """Parameter 8 as this run recorded it, else as the axis knows it (read or from the panel)."""
        run = self.page.run
        if run is not None:
            recorded = parameter_8_of_run(run.procedure, run.state)
            if recorded is not None:
                return recorded
        value = self.page.state.value_of("system", 8)
        return int(value) if value in (0, 1) else None

    def answer_steps(self, checks: Sequence[BenchCheck]) -> None:
        """A move's checks from the Bench tab: answer the step on show, and the one after it, as
        long as the move answers them (the 1-10 check's FWD move, then which way the flange
        turned)."""
        page = self.page
        said = ""
        taken: list[str] = []
        while page.run is not None and not page.run.stopped and not page.axis_mismatch():
            step = page.current_step()
            if step is None or not bench_kind(step):
                break
            answer = answer_from_bench(step, checks, self.parameter_8())
            if not answer.answers:
                said = answer.detail
                break
            if not page.answer(answer.value, answer.detail):
                return
            value = answer.value
            taken.append(f"{value.value if isinstance(value, Observation) else value}")
        if taken and not (page.run is not None and page.run.stopped):
            said = (f"Recorded from the move on the bench: {', then '.join(taken)} (each record says where "
                    "from)" + (f"; {said}" if said else ""))
        if said:
            page.show_message(said)
