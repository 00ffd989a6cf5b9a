"""The Tuning page's bench part: tuning a drive whose CN3 is silent while the servo is on (a real
HA-655), from what bench instruments give on CN2.

- *Write excitation file…*: the bounded excitation for SPD-CMD (speed mode), its bounds shown
  before the file is written (``logic/tuning/bench_excitation``);
- a capture (a sigrok session, VCD or CSV) with its channels mapped to SPD-MON, SPD-CMD, the
  encoder outputs and the command pulses, and optionally the excitation file played;
- *Analyse the capture*: the frequency response (SPD-CMD and SPD-MON) or the loop fitted to a move
  (encoder + command pulses), on the page's plots with ``tune analyse``'s figures;
- *Verify the proposal from the capture*: a capture made after typing the worksheet's items,
  compared with what the loop predicts for them.

The analysis runs in a thread of its own (``_AnalysisWorker``): the GUI thread never waits for it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from PySide6.QtCore import QObject, QThread, Signal, Slot
from PySide6.QtWidgets import (
    QComboBox,
    QFileDialog,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QVBoxLayout,
)

from fha_studio.gui.widgets import hint_whole
from fha_studio.hardware.bench.readers import read_capture
from fha_studio.hardware.bench.waveform import form_of, write_waveform
from fha_studio.logic.tuning.bench_excitation import design_excitation
from fha_studio.logic.tuning.bench_move import verify_move
from fha_studio.logic.tuning.bench_session import (
    RoleSignal,
    bench_move_report,
    bench_response_report,
    bench_tuner,
    is_move,
    move_samples,
)
from fha_studio.logic.wording import NO_BREAK_SPACE as NB
from fha_studio.logic.wording import with_unit

#: the roles the panel maps, with their words on CN2
ROLE_WORDS = (("speed_monitor", "SPD-MON"), ("speed_command", "SPD-CMD"), ("encoder_a", "Encoder A"),
              ("encoder_b", "B"), ("command_a", "Command A"), ("command_b", "B"))
#: a channel named so in a capture is taken for the role at first (the virtual instrument's names,
#: and the usual words)
GUESSES = {"speed_monitor": ("spd_mon", "spd-mon", "spdmon", "speed_monitor"),
           "speed_command": ("spd_cmd", "spd-cmd", "spdcmd", "speed_command"),
           "encoder_a": ("enc_a", "encoder_a", "a"), "encoder_b": ("enc_b", "encoder_b", "b"),
           "command_a": ("cmd_a", "command_a", "pulse"), "command_b": ("cmd_b", "command_b", "sign")}
NOT_RECORDED = "(not recorded)"


class _AnalysisWorker(QObject):
    """Runs an analysis in its own thread."""

    sigDone = Signal(str, object)  # what was asked, its result
    sigFailed = Signal(str)

    @Slot(str, object)
    def run(self, what: str, job: Any) -> None:
        try:
            result = job()
        except ValueError as exc:  # every bad capture is one line
            self.sigFailed.emit(str(exc))
            return
        except Exception as exc:  # an analysis bug must not kill the thread silently
            self.sigFailed.emit(f"the analysis failed: {type(exc).__name__}: {exc}")
            return
        self.sigDone.emit(what, result)


class BenchTuningPanel(QGroupBox):
    """See the module docstring; ``page`` is the Tuning page (actuator, load, items, plots)."""

    sigAnalysed = Signal(object)  # tune analyse's dict
    sigVerified = Signal(object)  # the verification's dict
    sigFailed = Signal(str)
    sigRequest = Signal(str, object)

    def __init__(self, page: Any) -> None:
        super().__init__("On the bench (a drive whose CN3 is silent while the servo is on): SPD-CMD from an "
                         "instrument's output in speed mode, SPD-MON recorded; or a move of the controller")
        self.page = page
        self.result: dict[str, Any] | None = None
        self.verification: dict[str, Any] | None = None
        self.excitation_path: str | None = None
        self.capture_path: str | None = None
        self.capture_edit = QLineEdit()
        self.capture_edit.setReadOnly(True)
        self.capture_edit.setPlaceholderText("the CN2 capture (.sr, VCD, CSV)")
        hint_whole(self.capture_edit)
        choose = QPushButton("Capture…")
        choose.setToolTip("Choose the capture of CN2")
        choose.clicked.connect(self._choose_capture)
        self.excitation_edit = QLineEdit()
        self.excitation_edit.setReadOnly(True)
        self.excitation_edit.setPlaceholderText("the excitation file played")
        hint_whole(self.excitation_edit)
        self.excitation_edit.setToolTip("The input when SPD-CMD was not recorded beside SPD-MON")
        choose_exc = QPushButton("Excitation…")
        choose_exc.setToolTip("Choose the excitation file that was played")
        choose_exc.clicked.connect(self._choose_excitation)
        self.combos: dict[str, QComboBox] = {}
        channels = QHBoxLayout()
        channels.addWidget(QLabel("Channels:"))
        for role, words in ROLE_WORDS:
            combo = QComboBox()
            combo.addItem(NOT_RECORDED)
            combo.setSizeAdjustPolicy(QComboBox.SizeAdjustPolicy.AdjustToContents)
            combo.setToolTip(f"The capture's channel of {words}")
            self.combos[role] = combo
            channels.addWidget(QLabel(words))
            channels.addWidget(combo)
        channels.addStretch(1)
        self.write_button = QPushButton("Write excitation file…")
        self.write_button.setToolTip("The excitation for SPD-CMD in speed mode (parameter 0): its bounds "
                                     "are shown before the file is written")
        self.write_button.clicked.connect(self._write_clicked)
        self.analyse_button = QPushButton("Analyse the capture")
        self.analyse_button.clicked.connect(self.analyse)
        self.verify_button = QPushButton("Verify the proposal from the capture")
        self.verify_button.setToolTip("A capture made after typing the worksheet's items, compared with "
                                      "what the loop predicts for them")
        self.verify_button.clicked.connect(self.verify)
        for b in (self.analyse_button, self.verify_button):
            b.setEnabled(False)
        self.status = QLabel("Write the excitation file for a DAQ's or generator's output on SPD-CMD, or "
                             "capture a move of the controller; then choose the capture.")
        self.status.setWordWrap(True)

        files = QHBoxLayout()
        files.addWidget(self.write_button)
        files.addWidget(self.excitation_edit, 2)
        files.addWidget(choose_exc)
        files.addWidget(self.capture_edit, 2)
        files.addWidget(choose)
        files.addWidget(self.analyse_button)
        files.addWidget(self.verify_button)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(6, 4, 6, 4)
        layout.addLayout(files)
        layout.addLayout(channels)
        layout.addWidget(self.status)

        self._thread = QThread(self)
        self._thread.setObjectName("bench tuning")
        self._worker = _AnalysisWorker()
        self._worker.moveToThread(self._thread)
        self.sigRequest.connect(self._worker.run)
        self._worker.sigDone.connect(self._done)
        self._worker.sigFailed.connect(self._failed)
        self._thread.finished.connect(self._worker.deleteLater)
        self._thread.start()

    def shutdown(self) -> None:
        self._thread.quit()
        self._thread.wait(5000)

    # ----- the drive's items, the axis ------------------------------------------------------------
    def _values(self) -> dict[tuple[str, int], int]:
        """The drive's items as (mode, number) -> value: the front panel's (the session's state),
        the rest at their defaults."""
        model = self.page.session.parameter_model
        return {(str(model.by_key(key).mode), model.by_key(key).number): value
                for key, value in self.page._offline_items().items()}

    def _tuner(self, items: dict[str, int] | None = None) -> Any:
        values = self._values()
        model = self.page.session.parameter_model
        for key, value in (items or {}).items():
            item = model.by_key(key)
            values[(str(item.mode), item.number)] = int(value)
        return bench_tuner(self.page._code(), self.page.load_spin.value(), model, values)

    # ----- the excitation file ----------------------------------------------------------------------
    def _write_clicked(self) -> None:
        try:
            excitation = self.plan_excitation()
        except ValueError as exc:
            self.status.setText(f"No excitation: {exc}")
            return
        path, _ = QFileDialog.getSaveFileName(
            self, "Write the excitation file", "excitation.csv",
            "time and volts (*.csv);;WAV, 16 bit (*.wav);;one cycle, normalised (*.txt)")
        if path:
            self.write_excitation(path, excitation)

    def plan_excitation(self) -> Any:
        """The excitation for the page's axis and the drive's items, its bounds shown."""
        excitation = design_excitation(self._tuner(), amplitude_rpm=self.page._amplitude(),
                                       bias=self.page.bias())  # the page's choice, FWD, REV or in place
        self.status.setText(excitation.describe(manual_units=True) + ". Speed mode, the servo on from the "
                            "controller, the axis free to move that far; the file ends at 0 V.")
        return excitation

    def write_excitation(self, path: str, excitation: Any | None = None) -> Path:
        excitation = excitation or self.plan_excitation()
        written = write_waveform(path, excitation.waveform, form_of(path))
        self.excitation_path = str(written)
        self.excitation_edit.setText(str(written))
        self.status.setText(f"{excitation.describe(manual_units=True)}. Written to {written}: play it into "
                            "SPD-CMD (CN2-31, common CN2-32) and record SPD-MON (CN2-23), with SPD-CMD "
                            "beside it if you can.")
        return written

    def _choose_excitation(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "The excitation file played", "",
                                              "CSV or WAV (*.csv *.wav)")
        if path:
            self.excitation_path = path
            self.excitation_edit.setText(path)

    # ----- the capture ---------------------------------------------------------------------------------
    def _choose_capture(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "A capture of CN2", "",
                                              "Captures (*.sr *.vcd *.csv);;All files (*)")
        if path:
            self.load_capture(path)

    def load_capture(self, path: str) -> None:
        """Take a capture: its channels offered for each role (a channel named as the role guessed)."""
        try:
            capture = read_capture(path)
        except ValueError as exc:
            self.status.setText(str(exc))
            return
        self.capture_path = path
        self.capture_edit.setText(path)
        names = list(capture.channels)
        for role, combo in self.combos.items():
            combo.clear()
            combo.addItem(NOT_RECORDED)
            combo.addItems(names)
            guess = next((n for n in names if n.lower() in GUESSES[role]), None)
            combo.setCurrentText(guess or NOT_RECORDED)
        for b in (self.analyse_button, self.verify_button):
            b.setEnabled(True)
        self.status.setText(f"{path}: {capture.samples} samples at {capture.sample_rate_hz:g} Hz, channels "
                            f"{', '.join(names)}. Check the mapping, then analyse.")

    def map_channel(self, role: str, channel: str | None) -> None:
        self.combos[role].setCurrentText(channel or NOT_RECORDED)

    def signals(self) -> list[RoleSignal]:
        if not self.capture_path:
            return []
        path = self.capture_path
        return [RoleSignal(role, path, combo.currentText()) for role, combo in self.combos.items()
                if combo.currentText() != NOT_RECORDED]

    # ----- analysis and verification ------------------------------------------------------------------
    def analyse(self) -> None:
        """The capture's response or move, analysed with the drive's present items."""
        signals = self.signals()
        tuner = self._tuner()
        values = self._values()
        excitation = self.excitation_path

        def job() -> dict[str, Any]:
            if is_move(signals) and not excitation:
                return bench_move_report(tuner, signals, values)
            return bench_response_report(tuner, signals, excitation)

        self.status.setText("Analysing the capture …")
        self.sigRequest.emit("analyse", job)

    def verify(self) -> None:
        """The capture, made after typing the proposal's items, against their prediction."""
        proposal = self.page.proposal
        if proposal is None:
            self.status.setText("Propose gains first: the verification compares a capture with the proposal.")
            return
        items = dict(proposal.proposed.items)
        signals = self.signals()
        tuner = self._tuner(items)
        values = {**self._values()}
        model = self.page.session.parameter_model
        for key, value in items.items():
            values[(str(model.by_key(key).mode), model.by_key(key).number)] = int(value)
        excitation = self.excitation_path

        def job() -> dict[str, Any]:
            if is_move(signals) and not excitation:
                samples = move_samples(tuner, signals, values)
                return {"kind": "move", **verify_move(tuner, items, samples)}
            return {"kind": "response", **bench_response_report(tuner, signals, excitation)}

        self.status.setText("Comparing the capture with the proposal's prediction …")
        self.sigRequest.emit("verify", job)

    def _done(self, what: str, result: dict[str, Any]) -> None:
        if what == "analyse":
            self.result = result
            self.page.show_result(result)
            notes = result.get("notes", [])
            self.status.setText(analysis_words(result) + (f" {notes[0]}" if notes else ""))
            self.sigAnalysed.emit(result)
            return
        self.verification = result
        self.status.setText(verification_words(result))
        if result["kind"] == "response":
            self.page.show_result(result)
        self.sigVerified.emit(result)

    def _failed(self, message: str) -> None:
        self.status.setText(f"Not analysed: {message}")
        self.sigFailed.emit(message)


def _n(value: float | None, unit: str, digits: str = ".3g") -> str:
    return "—" if value is None else with_unit(f"{value:{digits}}", unit, on_page=True)


def analysis_words(result: dict[str, Any]) -> str:
    """What an analysis from the bench gave, in a sentence."""
    load, spread = result.get("load_inertia_estimate_kgm2"), result.get("load_inertia_uncertainty_kgm2")
    inertia = ("the load inertia cannot be told from it" if load is None else
               f"load inertia {load:.3g}{NB}kg·m²" + (f" ± {spread:.2g}" if spread else ""))
    if result.get("kind") == "fitted from a move":
        fit = result["fit"]
        return (f"The loop fitted to the move ({fit['samples']} samples, the position within "
                f"{fit['position_rms_counts']:.2g} counts rms): {inertia}; the plots show the fitted loop.")
    dev = result["deviation"]
    if dev["magnitude_db"] is None:
        return f"Analysed from the bench: no frequency bin was trusted (coherence below 0.9); {inertia}."
    return (f"Analysed from the bench: {dev['trusted_bins']} trusted bins, within {dev['magnitude_db']:.2g}"
            f"{NB}dB and {dev['phase_deg']:.2g}° of the linearised loop (dashed); {inertia}.")


def verification_words(result: dict[str, Any]) -> str:
    """A verification in a sentence: measured against predicted."""
    if result["kind"] == "move":
        m, p = result["measured"], result["predicted"]

        def ms(v: float | None) -> str:
            return "not settled" if v is None else f"{v:.0f}{NB}ms"

        return (f"Verified from the bench (a move with the proposed items): following error at most "
                f"{m['following_error_peak_counts']:.0f} counts (predicted "
                f"{p['following_error_peak_counts']:.0f}), overshoot {m['overshoot_pct']:.2f}{NB}% "
                f"(predicted "
                f"{p['overshoot_pct']:.2f}{NB}%), settling {ms(m['settling_ms'])} (predicted "
                f"{ms(p['settling_ms'])}); the capture is within {result['difference_rms_counts']:.2g} "
                "counts rms of the prediction.")
    dev, predicted = result["deviation"], result["predicted"]
    if dev["magnitude_db"] is None:
        return "Verified from the bench: no frequency bin was trusted (coherence below 0.9)."
    return (f"Verified from the bench (the response with the proposed items): within "
            f"{dev['magnitude_db']:.2g}{NB}dB and {dev['phase_deg']:.2g}° of the prediction over "
            f"{dev['trusted_bins']} trusted bins; phase margin {_n(result['phase_margin_deg'], 'deg')} "
            f"(predicted {_n(predicted['phase_margin_deg'], 'deg')}), crossover "
            f"{_n(result['crossover_hz'], 'Hz')} (predicted {_n(predicted['crossover_hz'], 'Hz')}).")
