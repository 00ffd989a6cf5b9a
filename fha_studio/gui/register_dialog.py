"""The register's questions in the GUI, for one machine: the history of an axis, what differs
between two axes (or two snapshots), which axes have a parameter value, what is still open.

The same questions as ``fha-studio register history|diff|find|open``, in the same words. They
are asked through :mod:`fha_studio.gui.register_questions`: a register file answers at once; a
register on a server from a thread of its own, the dialog saying "Asking the server…" meanwhile
and one line when no answer comes (each table keeps what it showed before).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from PySide6.QtCore import Qt, Slot
from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFormLayout,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QPushButton,
    QTableWidget,
    QTableWidgetItem,
    QTabWidget,
    QVBoxLayout,
    QWidget,
)

from fha_studio.gui.register_questions import LocalQuestions, RegisterQuestions, shown_location
from fha_studio.logic.register import Register
from fha_studio.logic.register.words import (
    KIND_WORDS,
    SOURCE_WORDS,
    parameter_item,
    parameter_items,
    parameter_name,
    value_text,
    when_text,
)


def _fill(table: QTableWidget, rows: list[list[str]]) -> None:
    table.setRowCount(len(rows))
    for r, row in enumerate(rows):
        for c, text in enumerate(row):
            item = QTableWidgetItem(text)
            item.setToolTip(text)
            item.setFlags(item.flags() & ~Qt.ItemFlag.ItemIsEditable)
            table.setItem(r, c, item)


def _table(headers: list[str], stretch: int) -> QTableWidget:
    table = QTableWidget(0, len(headers))
    table.setHorizontalHeaderLabels(headers)
    table.verticalHeader().setVisible(False)
    table.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
    table.setSelectionBehavior(QTableWidget.SelectionBehavior.SelectRows)
    header = table.horizontalHeader()
    header.setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
    header.setSectionResizeMode(stretch, QHeaderView.ResizeMode.Stretch)
    return table


class RegisterDialog(QDialog):
    """History, compare, find and open items of one machine's axes."""

    def __init__(
        self,
        register: Register | RegisterQuestions,
        machine: str,
        axis: str | None = None,
        parent: QWidget | None = None,
    ):
        """``register``: an open register file (asked on this thread), or the questions of a
        window (a server's are asked from a thread of their own)."""
        super().__init__(parent)
        self.setObjectName("registerDialog")
        self.setWindowTitle(f"Register — {machine}")
        self.questions = (
            register if isinstance(register, RegisterQuestions) else LocalQuestions(register, self)
        )
        self.machine = machine
        #: the latest question of each kind: an answer to an older one is not shown
        self._latest: dict[str, int] = {}
        self._asked = 0
        self.resize(1100, 620)
        layout = QVBoxLayout(self)
        kind = "Register on the server" if self.questions.on_server else "Register file"
        self.where_label = QLabel(f"{kind}: {shown_location(self.questions.location)}")
        self.where_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        layout.addWidget(self.where_label)
        #: "Asking the server…" while a question waits; one line when an answer did not come
        #: (its line kept for a server's, so that the tables do not jump; none for a file's)
        self.status_label = QLabel("")
        self.status_label.setObjectName("registerStatus")
        self.status_label.setWordWrap(True)
        self.status_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.status_label.setVisible(self.questions.on_server)
        layout.addWidget(self.status_label)
        self.questions.sigBusy.connect(self._on_busy)
        self.tabs = QTabWidget()
        layout.addWidget(self.tabs, 1)
        self.tabs.addTab(self._history_tab(), "&History")
        self.tabs.addTab(self._compare_tab(), "&Compare")
        self.tabs.addTab(self._find_tab(), "&Find")
        self.tabs.addTab(self._open_tab(), "&Open items")
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close)
        buttons.rejected.connect(self.reject)
        refresh = buttons.addButton("&Refresh", QDialogButtonBox.ButtonRole.ActionRole)
        refresh.clicked.connect(self.refresh)
        layout.addWidget(buttons)
        self.refresh(axis)

    # -- tabs ---------------------------------------------------------------------------------------
    def _history_tab(self) -> QWidget:
        tab = QWidget()
        v = QVBoxLayout(tab)
        row = QHBoxLayout()
        self.history_axis = QComboBox()
        self.history_axis.currentIndexChanged.connect(self._show_history)
        row.addWidget(QLabel("Axis:"))
        row.addWidget(self.history_axis, 1)
        v.addLayout(row)
        self.history_table = _table(["When (UTC)", "What", "Who", "Entry"], 3)
        self.history_table.setObjectName("historyTable")
        v.addWidget(self.history_table, 1)
        return tab

    def _compare_tab(self) -> QWidget:
        tab = QWidget()
        v = QVBoxLayout(tab)
        form = QFormLayout()
        self.compare_a = QComboBox()
        self.compare_b = QComboBox()
        for combo in (self.compare_a, self.compare_b):
            combo.currentIndexChanged.connect(self._show_compare)
        form.addRow("A:", self.compare_a)
        form.addRow("B:", self.compare_b)
        v.addLayout(form)
        self.compare_label = QLabel("")
        self.compare_label.setWordWrap(True)
        v.addWidget(self.compare_label)
        self.compare_table = _table(["Parameter", "A", "B"], 0)
        self.compare_table.setObjectName("compareTable")
        v.addWidget(self.compare_table, 1)
        return tab

    def _find_tab(self) -> QWidget:
        tab = QWidget()
        v = QVBoxLayout(tab)
        row = QHBoxLayout()
        self.find_parameter = QComboBox()
        for item in parameter_items():
            self.find_parameter.addItem(parameter_name(item.key), item.key)
        self.find_parameter.currentIndexChanged.connect(self._parameter_chosen)
        self.find_value = QComboBox()
        self.find_value.setEditable(True)
        self.find_button = QPushButton("Fin&d axes")
        self.find_button.clicked.connect(self._show_find)
        row.addWidget(QLabel("Parameter:"))
        row.addWidget(self.find_parameter, 2)
        row.addWidget(QLabel("Value:"))
        row.addWidget(self.find_value, 2)
        row.addWidget(self.find_button)
        v.addLayout(row)
        self.find_label = QLabel("")
        self.find_label.setWordWrap(True)
        v.addWidget(self.find_label)
        self.find_table = _table(["Axis", "Value", "Known from", "When (UTC)"], 1)
        self.find_table.setObjectName("findTable")
        v.addWidget(self.find_table, 1)
        key = "rotary_direction"
        index = self.find_parameter.findData(key)
        self.find_parameter.setCurrentIndex(max(index, 0))
        self._parameter_chosen()
        return tab

    def _open_tab(self) -> QWidget:
        tab = QWidget()
        v = QVBoxLayout(tab)
        self.open_label = QLabel("")
        v.addWidget(self.open_label)
        self.open_table = _table(["Axis", "What", "Open"], 2)
        self.open_table.setObjectName("openTable")
        v.addWidget(self.open_table, 1)
        return tab

    # -- asking ---------------------------------------------------------------------------------------
    def _ask(self, kind: str, what: str, question: Callable[[Register], Any],
             answered: Callable[[Any], None], failed: Callable[[str], None] | None = None) -> None:
        """Asks the register; only the answer to the latest question of ``kind`` is shown (a
        person who chose another axis meanwhile sees that axis's)."""
        self._asked += 1
        number = self._latest[kind] = self._asked

        def take(value: Any) -> None:
            if self._latest.get(kind) == number:
                answered(value)

        def refused(why: str) -> None:
            if self._latest.get(kind) == number:
                (failed or self._say)(why)

        self.questions.ask(what, question, take, refused)

    def _say(self, why: str) -> None:
        self._status(f"Not answered: {why}.", "color: #b00020;")

    def _status(self, text: str, style: str = "") -> None:
        self.status_label.setText(text)
        self.status_label.setStyleSheet(style)
        self.status_label.setVisible(bool(text) or self.questions.on_server)

    @Slot(bool)
    def _on_busy(self, busy: bool) -> None:
        if busy:
            self._status("Asking the server…", "color: #8a5a00; font-weight: bold;")
        elif self.status_label.text() == "Asking the server…":
            self._status("")

    # -- filling ------------------------------------------------------------------------------------
    @Slot()
    def refresh(self, axis: str | None = None) -> None:
        """Reads the register again (another window may have written to it)."""
        chosen = axis or self.history_axis.currentData()
        machine = self.machine

        def axes_and_snapshots(reg: Register) -> tuple[list[Any], dict[str, list[Any]]]:
            axes = reg.axes(machine)
            return axes, {a.ref: reg.snapshots(a) for a in axes}

        self._ask("axes", f"the axes of {machine}", axes_and_snapshots,
                  lambda answer: self._fill_axes(answer[0], answer[1], chosen))

    def _fill_axes(self, axes: list[Any], snapshots: dict[str, list[Any]], chosen: str | None) -> None:
        self.history_axis.blockSignals(True)
        self.history_axis.clear()
        for a in axes:
            self.history_axis.addItem(f"{a.name} — {a.actuator_code or 'actuator not given'}", a.ref)
        self.history_axis.setCurrentIndex(
            max(0, self.history_axis.findData(f"{self.machine}/{chosen}"), self.history_axis.findData(chosen))
        )
        self.history_axis.blockSignals(False)
        self._fill_compare_choices(axes, snapshots, chosen)
        self._show_history()
        self._show_compare()
        self._show_open()

    def _fill_compare_choices(self, axes, snapshots: dict[str, list[Any]], chosen: str | None) -> None:
        current = next((a for a in axes if chosen in (a.name, a.ref)), axes[0] if axes else None)
        # the twin: the next axis with the same actuator, else the next axis
        twin = next(
            (
                a
                for a in axes
                if current and a.ref != current.ref and a.actuator_code == current.actuator_code
            ),
            next((a for a in axes if current and a.ref != current.ref), current),
        )
        for combo, default in ((self.compare_a, current), (self.compare_b, twin)):
            combo.blockSignals(True)
            combo.clear()
            for a in axes:
                combo.addItem(f"{a.name}: latest known values", a.ref)
            for a in axes:
                for s in snapshots.get(a.ref, []):
                    source = SOURCE_WORDS.get(s["source"], s["source"])
                    combo.addItem(
                        f"{a.name}: snapshot {s['id']} ({source}, {when_text(s['at_utc'])})", str(s["id"])
                    )
            if default is not None:
                combo.setCurrentIndex(max(0, combo.findData(default.ref)))
            combo.blockSignals(False)

    @Slot()
    def _show_history(self) -> None:
        ref = self.history_axis.currentData()
        if not ref:
            _fill(self.history_table, [])
            return

        def show(events: list[Any]) -> None:
            rows = [[when_text(e.at_utc), KIND_WORDS[e.kind], e.who, e.text] for e in reversed(events)]
            _fill(self.history_table, rows)  # newest first

        self._ask("history", f"the history of {ref}", lambda reg: reg.history(ref), show)

    @Slot()
    def _show_compare(self) -> None:
        a_ref, b_ref = self.compare_a.currentData(), self.compare_b.currentData()
        if not a_ref or not b_ref:
            return
        self._ask("compare", "the values to compare",
                  lambda reg: (reg.parameter_set(a_ref), reg.parameter_set(b_ref)),
                  lambda sets: self._fill_compare(*sets), self.compare_label.setText)

    def _fill_compare(self, a, b) -> None:
        differences = Register.diff(a, b)
        driver = a.axis.driver_model or b.axis.driver_model
        held = len(set(a.values) | set(b.values))
        if not held:
            self.compare_label.setText(
                "Neither holds a parameter value yet (read the parameters of the axes first)."
            )
        elif not differences:
            self.compare_label.setText(f"No difference in the {held} parameters they hold.")
        else:
            self.compare_label.setText(f"{len(differences)} of the {held} parameters they hold differ.")
        rows = [
            [parameter_name(d.key, driver), value_text(d.key, d.a, driver), value_text(d.key, d.b, driver)]
            for d in differences
        ]
        _fill(self.compare_table, rows)

    @Slot()
    def _parameter_chosen(self) -> None:
        item = parameter_item(self.find_parameter.currentData() or "")
        self.find_value.clear()
        if item is None:
            return
        if item.choices:
            for wire, meaning in item.choices.items():
                self.find_value.addItem(f"{wire}: {meaning}", wire)
            self.find_value.setEditable(False)
        else:
            self.find_value.setEditable(True)
            self.find_value.setEditText("")
            self.find_value.lineEdit().setPlaceholderText(
                f"the drive's value, {item.minimum} … {item.maximum} (empty: every axis)"
            )

    @Slot()
    def _show_find(self) -> None:
        key = self.find_parameter.currentData()
        item = parameter_item(key)
        if item is not None and item.choices:
            value = self.find_value.currentData()
        else:
            text = self.find_value.currentText().strip()
            if not text:
                value = None
            else:
                why = ""
                try:
                    value = int(text)
                except ValueError:
                    why = f"'{text}' is not a whole number"
                else:
                    try:
                        if item is not None:
                            item.check(value)
                    except ValueError as exc:  # outside the item's range: the item says which
                        why = str(exc)
                if why:
                    self.find_label.setText(f"Nothing searched: {why}.")
                    _fill(self.find_table, [])
                    return
        name = item.name if item is not None else key
        wanted = f" = {value_text(key, value)}" if value is not None else ""
        machine = self.machine

        def show(found: list[Any]) -> None:
            axes = "axis has" if len(found) == 1 else "axes have"
            self.find_label.setText(f"{len(found)} {axes} {name}{wanted} (the latest known value of each).")
            rows = [
                [
                    f.axis.name,
                    value_text(key, f.value.value, f.axis.driver_model),
                    SOURCE_WORDS[f.value.source],
                    when_text(f.value.at_utc),
                ]
                for f in found
            ]
            _fill(self.find_table, rows)

        self._ask("find", f"which axes have {name}{wanted}",
                  lambda reg: reg.find(key, value, machine=machine), show,
                  lambda why: self.find_label.setText(f"Not searched: {why}."))

    @Slot()
    def _show_open(self) -> None:
        def show(items: list[Any]) -> None:
            self.open_label.setText(
                "Nothing open: every check passed and every report is signed."
                if not items
                else f"{len(items)} open item(s): checks not done or failed, reports missing or not signed, "
                "conflicts between registers to settle."
            )
            rows = [[i.axis.name, i.kind if i.kind in ("report", "conflict") else "check", i.text]
                    for i in items]
            _fill(self.open_table, rows)

        machine = self.machine
        self._ask("open", f"what is open on {machine}", lambda reg: reg.open_items(machine), show)
