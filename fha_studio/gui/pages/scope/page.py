"""The scope as a page of the main window, wired to the link worker's thread.

The driver is moved to the link thread and gets the worker's ``DriveClient`` through the
worker's CALL command (the function runs in the link thread, where the driver lives), so
the scope never opens a port and every exchange is serialised with the worker's own.
"""

from __future__ import annotations

from functools import partial

from PySide6.QtWidgets import QVBoxLayout

from fha_studio.catalog import DEFAULT_ACTUATOR
from fha_studio.gui.link import POLL_INTERVAL_MS, Call, LinkInfo, SetPollInterval
from fha_studio.gui.motion_controls import MotionControls, MotionLayout
from fha_studio.gui.pages.base import BasePage
from fha_studio.gui.widgets import space_jogs_only

from .bench_panel import BenchPanel
from .driver import ScopeCmd, ScopeController, ScopeRequest
from .view import ScopeContext, ScopeView

#: The worker's status poll while the scope is live [ms]: the line is the scope's (its own
#: channels carry position, speed, current and the I/O bits); the lamps update twice a second.
STATUS_POLL_WHILE_LIVE_MS = 500


def _attach_in_link_thread(controller: ScopeController, ratio: int | None, client) -> None:
    """Runs in the link thread (worker CALL): give the driver the worker's client."""
    controller.driver.handle(ScopeRequest(ScopeCmd.SET_CLIENT, (client, ratio)))


class ScopePage(BasePage):
    """Page "Scope": live view, trace, built-in tests, recording, a bench instrument."""

    def __init__(self, session, main_window=None):
        super().__init__(main_window)
        self.session = session
        link = session.link
        self.controller = ScopeController(thread=link._thread, parent=self, abort=link.abort_event)
        self.state = session.state
        self.view = ScopeView(self.controller, self._context())
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.view)
        # move and watch at once: the jog panel beside the plot, STOP as the window's
        self.jog_panel = MotionControls(link, main_window.stop_button if main_window is not None else None,
                                        MotionLayout.PANEL)
        self.view.dock_under_channels(self.jog_panel)
        space_jogs_only(self, (self.jog_panel.fwd_button, self.jog_panel.rev_button))
        # a bench instrument on CN2 beside CN3 polling (a real drive's CN3 is silent in motion)
        self.bench = BenchPanel()
        self.view.plots.addTab(self.bench, "Bench")
        self._host = main_window
        self.bench.sigChecks.connect(self._bench_checks)
        self.view.toolbar.sigBackToLive.connect(self.bench.back_to_live)  # the bench's move too
        # its stream on the Time plot too, beside the CN3 channels
        self.bench.source.sigRows.connect(self._bench_on_time_plot)
        self.bench.source.sigStarted.connect(lambda _s: self.view.time_plot.set_bench_curves({}))
        self.view.beside_recording = self._bench_beside  # and in the recording, beside them
        self._bench_axis()
        # the axis's actuator, driver and load decide the scaling and what is recorded, at every moment
        state = self.state
        for signal in (state.sigActuatorChanged, state.sigDriverChanged, state.sigLoadInertiaChanged):
            signal.connect(self._axis_changed)
        for signal in (state.sigActuatorChanged, state.sigDriverChanged, state.sigParametersChanged,
                       state.sigFrontPanelChanged):
            signal.connect(self._bench_axis)
        self.view.sigLoadInertiaEdited.connect(self._load_inertia_edited)
        self.view.sigLiveChanged.connect(self._on_live_changed)

    def _axis_changed(self, *_args) -> None:
        # the ratio goes first, so that a live view restarted here scales DGR counts with it
        self.controller.set_ratio(self.state.ratio)
        was_live = self.view.live_button.isChecked()
        self.view.set_context(self._context())  # another actuator stops live (and a recording)
        if was_live and not self.view.live_button.isChecked() and self.controller.connected:
            self.view.start_live()  # the technician watching goes on watching, at the new scale

    def _bench_axis(self, *_args) -> None:
        """The bench decodes with the axis's counts per output turn and the parameters known
        (read from the drive or entered from its front panel), else the parameters' defaults."""
        from fha_studio.hardware.parameters import load_parameter_model
        from fha_studio.logic.bench.importer import PARAMETERS, DriveSettings

        state = self.state
        try:
            model = load_parameter_model(state.driver or "HA-655")
        except (KeyError, ValueError):
            model = load_parameter_model()
        fallback = {1: 0, 2: 4, 3: 1, 4: 1, 9: 3000}  # where the table gives no default
        values = {}
        for mode, number in PARAMETERS:
            value = state.value_of(mode, number)
            if value is None:
                value = model.item(mode, number).default
            values[(mode, number)] = value if value is not None else fallback[number]
        counts = state.output_resolution_ppr if state.actuator_code else 0
        self.bench.set_axis(int(counts or 0), DriveSettings.from_values(values))
        direction = state.value_of("system", 8)  # rotary direction, read or entered from the panel
        self.bench.parameter_8 = int(direction) if direction is not None else None

    def _bench_on_time_plot(self, _rows) -> None:
        """The newest bench rows on the Time plot while its live view runs (time before now)."""
        from .bench_overlay import COLORS, bench_traces

        started = self.bench.source.started
        plot = self.view.time_plot
        if started is None or not plot.live:
            return
        span = self.view.toolbar.time_base_s()
        # a copy: the whole ring at the longest time base, which the stream's thread writes on
        rows = started.ring.window(int(span * started.row_rate_hz), copy=True)
        plot.set_bench_curves(bench_traces(started, rows, self.bench.counts_per_output_turn,
                                           max(200, plot.plot.width())), COLORS)

    def bench_source_text(self) -> str:
        """`` (with bench sim-cn2 at 250 kHz: sim-cn2:ENC_A, ...)`` while a bench stream is drawn on
        the Time plot beside CN3's channels, else ""."""
        from fha_studio.hardware.bench.sigrok import rate_text

        started = self.bench.source.started
        if started is None or not self.view.time_plot.has_bench_curves:
            return ""
        return (f" (with bench {started.device} at {rate_text(started.sample_rate_hz)}: "
                f"{', '.join(started.labels)})")

    def _bench_beside(self, live_t0: float):
        """The bench stream's columns for a recording started now (None: no stream runs)."""
        from .bench_overlay import recorder_columns

        started = self.bench.source.started
        if started is None or not self.bench.source.running:
            return None
        return recorder_columns(started, live_t0, self.bench.counts_per_output_turn)

    def bench_watching(self) -> str:
        """``sim-cn2 (encoder ENC_A,ENC_B, command CMD_A,CMD_B)`` while the Bench tab streams the
        encoder outputs and the command lines, so a move's checks will come; else ""."""
        started = self.bench.source.started
        decoding = started is not None and {"counts", "command"} <= set(started.extra)
        if started is None or not self.bench.source.running or not decoding:
            return ""
        return (f"{started.device} (encoder {self.bench.encoder_edit.text().strip()}, command "
                f"{self.bench.command_edit.text().strip()})")

    def _bench_checks(self, checks: list) -> None:
        """A move's checks from CN2 go to the DGR checks page's record (and so into the report;
        the Procedures page listens to ``bench.sigChecks`` itself)."""
        from fha_studio.gui.pages.absolute import AbsolutePage
        from fha_studio.gui.pages.base import PageId

        if self._host is None or not checks:
            return
        page = self._host.page(PageId.ABSOLUTE)
        if isinstance(page, AbsolutePage):
            page.record_bench_checks(checks)

    def _load_inertia_edited(self, value_kgm2: float) -> None:
        self.state.set_load_inertia(value_kgm2)

    def _on_live_changed(self, live: bool) -> None:
        if self.session.link.connected:
            interval_ms = STATUS_POLL_WHILE_LIVE_MS if live else POLL_INTERVAL_MS
            self.session.link.send(SetPollInterval(interval_ms))

    def _context(self) -> ScopeContext:
        state = self.state
        return ScopeContext(state.actuator_code or DEFAULT_ACTUATOR,
                            load_inertia_kgm2=state.load_inertia_kgm2, supply_voltage=state.supply_voltage_v,
                            driver=state.driver, actuator_declared=bool(state.actuator_code))

    def release_held(self) -> None:
        """Let go of a jog held on the page's panel (STOP does it on every page)."""
        self.jog_panel.release_jog()

    def link_connected(self, info: LinkInfo) -> None:
        self.jog_panel.link_connected(info)
        self.view.set_context(self._context())
        self.controller.connected = True
        self.session.link.send(Call(partial(_attach_in_link_thread, self.controller, self.state.ratio)))

    def link_disconnected(self, reason: str, lost: bool) -> None:
        self.jog_panel.link_disconnected()
        self.view.stop_live()
        self.controller.attach(None)

    def shutdown(self) -> None:
        self.jog_panel.release_jog()
        self.bench.shutdown()
        self.view.shutdown()
        self.controller.shutdown()
