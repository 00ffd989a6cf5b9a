"""The register's questions in the GUI, for one machine: the history of an axis, what differs
between two axes (or two snapshots), which axes have a parameter value, what is still open, and
the conflicts between registers synced after they were apart, settled here by a person.

The same questions as ``fha-studio register history|diff|find|open|conflicts``, in the same words. They
are asked through :mod:`fha_studio.gui.register_questions`: a register file answers at once; a
register on a server from a thread of its own, the dialog saying "Asking the server…" meanwhile
and one line when no answer comes (each table keeps what it showed before). A settlement is the
fact ``register resolve`` records (``Register.resolve_conflict``), handed to the window's register
writer as every fact it records: a server's goes through this computer's queue, never from here.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from PySide6.QtCore import Qt, Slot
from PySide6.QtWidgets import (
    QButtonGroup,
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QPushButton,
    QRadioButton,
    QTableWidget,
    QTableWidgetItem,
    QTabWidget,
    QVBoxLayout,
    QWidget,
)

from fha_studio.gui.register_questions import LocalQuestions, RegisterQuestions, shown_location
from fha_studio.gui.register_worker import ServerState, ServerWriter
from fha_studio.gui.register_writer import DirectWriter, RegisterWriter
from fha_studio.logic.register import EventKind, Register
from fha_studio.logic.register.conflicts import SUBJECTS, Conflict, side_name
from fha_studio.logic.register.facts_from_session import SettlementFact, settlement_fact
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


#: The conflicts tab's title (with how many are open).
CONFLICTS_TAB = "Co&nflicts"


class RegisterDialog(QDialog):
    """History, compare, find, open items and conflicts of one machine's axes."""

    def __init__(
        self,
        register: Register | RegisterQuestions,
        machine: str,
        axis: str | None = None,
        parent: QWidget | None = None,
        writer: RegisterWriter | None = None,
        operator: Callable[[], str] | None = None,
    ):
        """``register``: an open register file (asked on this thread), or the questions of a
        window (a server's are asked from a thread of their own). ``writer``: where a settlement
        goes, the window's writer for the register (None: one of the dialog's own for a register
        file; on a server without one nothing is settled here). ``operator``: who the window says
        works at it (the settlement's name, which the person may change)."""
        super().__init__(parent)
        self.setObjectName("registerDialog")
        self.setWindowTitle(f"Register — {machine}")
        self.questions = (
            register if isinstance(register, RegisterQuestions) else LocalQuestions(register, self)
        )
        self.machine = machine
        self.operator = operator or (lambda: "")
        local = self.questions.register if isinstance(self.questions, LocalQuestions) else None
        if writer is None and local is not None:
            writer = DirectWriter(local, self)
        self.writer = writer
        #: settlements handed to a server's writer, not on the server yet: conflict uid -> (the
        #: side kept, its axis)
        self.settling: dict[str, tuple[int, str]] = {}
        self._refused = ""
        if writer is not None:
            writer.sigNotRecorded.connect(self._not_recorded)
            if isinstance(writer, ServerWriter):
                writer.sigState.connect(self._delivered)
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
        self.conflicts_index = self.tabs.addTab(self._conflicts_tab(), CONFLICTS_TAB)
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
        self.open_table.cellDoubleClicked.connect(self._open_item_chosen)
        v.addWidget(self.open_table, 1)
        return tab

    def _conflicts_tab(self) -> QWidget:
        tab = QWidget()
        v = QVBoxLayout(tab)
        row = QHBoxLayout()
        self.conflicts_label = QLabel("")
        self.conflicts_label.setWordWrap(True)
        row.addWidget(self.conflicts_label, 1)
        self.show_settled = QCheckBox("Show se&ttled ones too")
        self.show_settled.toggled.connect(lambda _on: self._list_conflicts())
        row.addWidget(self.show_settled)
        v.addLayout(row)
        self.conflicts_table = _table(["Axis", "Found (UTC)", "By", "What differs", "State"], 3)
        self.conflicts_table.setObjectName("conflictsTable")
        self.conflicts_table.setMaximumHeight(150)
        self.conflicts_table.setSelectionMode(QTableWidget.SelectionMode.SingleSelection)
        self.conflicts_table.itemSelectionChanged.connect(self._show_conflict)
        v.addWidget(self.conflicts_table)
        self.conflict_title = QLabel("")
        self.conflict_title.setObjectName("conflictTitle")
        self.conflict_title.setWordWrap(True)
        self.conflict_title.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        v.addWidget(self.conflict_title)
        self.sides_table = QTableWidget(0, 1)
        self.sides_table.setObjectName("conflictSidesTable")
        self.sides_table.verticalHeader().setVisible(False)
        self.sides_table.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        self.sides_table.setSelectionMode(QTableWidget.SelectionMode.NoSelection)
        self.sides_table.setWordWrap(True)
        self.sides_table.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.Stretch)
        v.addWidget(self.sides_table, 1)
        box = QGroupBox("Settle it: which side stands")
        box.setObjectName("settleBox")
        form = QVBoxLayout(box)
        self.keep_row = QHBoxLayout()
        self.keep_group = QButtonGroup(self)
        self.keep_group.idToggled.connect(lambda _id, _on: self._settle_ready())
        form.addLayout(self.keep_row)
        fields = QHBoxLayout()
        self.settle_note = QLineEdit()
        self.settle_note.setObjectName("settleNote")
        self.settle_note.setPlaceholderText("why (e.g. checked on the machine: reversed)")
        self.settle_who = QLineEdit()
        self.settle_who.setObjectName("settleWho")
        self.settle_who.setPlaceholderText("your name")
        self.settle_who.setMaximumWidth(220)
        self.settle_button = QPushButton("&Settle")
        self.settle_button.setObjectName("settleButton")
        self.settle_button.clicked.connect(self.settle)
        for text, widget in (("&Why:", self.settle_note), ("&By:", self.settle_who)):
            label = QLabel(text)
            label.setBuddy(widget)
            fields.addWidget(label)
            fields.addWidget(widget, 2 if widget is self.settle_note else 1)
        fields.addWidget(self.settle_button)
        form.addLayout(fields)
        self.settle_label = QLabel("")
        self.settle_label.setObjectName("settleLabel")
        self.settle_label.setWordWrap(True)
        form.addWidget(self.settle_label)
        self.settle_box = box
        v.addWidget(box)
        #: the machine's conflicts as last answered, those listed, and the open ones as recorded
        self._every: list[Conflict] = []
        self._conflicts: list[Conflict] = []
        self._shown: str | None = None  # the uid of the conflict shown
        self._records: dict[str, dict[str, Any]] = {}
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
        self._show_conflicts()

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
            rows = [
                [when_text(e.at_utc), KIND_WORDS[e.kind], e.who, _history_text(e)] for e in reversed(events)
            ]
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

    @Slot(int, int)
    def _open_item_chosen(self, row: int, _column: int) -> None:
        """A conflict among the open items (double-clicked): shown on the conflicts tab."""
        if self.open_table.item(row, 1).text() != "conflict":
            return
        short = self.open_table.item(row, 2).text().removeprefix("conflict ").split(":", 1)[0]
        self.show_conflict(short)

    # -- conflicts ----------------------------------------------------------------------------------
    def show_conflict(self, ref: str) -> bool:
        """Shows the conflicts tab on the conflict ``ref`` (its id or first characters); False when
        the machine has no such conflict."""
        self.tabs.setCurrentIndex(self.conflicts_index)
        for row, c in enumerate(self._conflicts):
            if c.uid.startswith(ref.strip().lower()):
                self.conflicts_table.selectRow(row)
                return True
        return False

    @Slot()
    def _show_conflicts(self) -> None:
        """Asks for the machine's conflicts (and the open ones as recorded, which a settlement
        carries to this computer's queue for a server)."""
        machine = self.machine

        def conflicts(reg: Register) -> tuple[list[Conflict], dict[str, dict[str, Any]]]:
            every = reg.conflicts(open_only=False, machine=machine)
            return every, {c.uid: reg.conflict_record(c.uid) for c in every if c.open}

        self._ask("conflicts", f"the conflicts of {machine}", conflicts,
                  lambda answer: self._fill_conflicts(*answer))

    def _fill_conflicts(self, every: list[Conflict], records: dict[str, dict[str, Any]]) -> None:
        self._every, self._records = every, records
        # a settlement made here is on the server once the server says the conflict is settled
        still_open = {c.uid for c in every if c.open}
        self.settling = {uid: v for uid, v in self.settling.items() if uid in still_open}
        self._list_conflicts()

    def _list_conflicts(self) -> None:
        chosen = self._chosen_conflict()
        open_now = [c for c in self._every if c.open]
        waiting = sum(1 for c in open_now if c.uid in self.settling)
        count = len(open_now) - waiting
        self.tabs.setTabText(self.conflicts_index, f"{CONFLICTS_TAB} ({count})" if count else CONFLICTS_TAB)
        if count:
            self.conflicts_label.setText(
                f"{count} open conflict{'s' if count > 1 else ''}: registers synced after they were apart "
                "disagree on an axis. Look at the axis, choose the side that stands and settle it; both "
                "sides' facts stay in the history."
            )
        else:
            self.conflicts_label.setText("No open conflict: the registers synced agree on every axis.")
        self._conflicts = self._every if self.show_settled.isChecked() else open_now
        rows = []
        for c in self._conflicts:
            rows.append([c.axis.name, when_text(c.at_utc), c.who, c.differs_words(), self._state_words(c)])
        self.conflicts_table.blockSignals(True)
        _fill(self.conflicts_table, rows)
        self.conflicts_table.blockSignals(False)
        if self._conflicts:
            uids = [c.uid for c in self._conflicts]
            self.conflicts_table.selectRow(uids.index(chosen) if chosen in uids else 0)
        self._show_conflict()

    def _state_words(self, c: Conflict) -> str:
        if c.uid in self.settling:
            return f"settled here (kept {self.settling[c.uid][0]}): waits to reach the server"
        if c.open:
            return "open: settled twice differently" if c.resolutions else "open"
        last = c.resolutions[-1]
        return f"settled by {last.who or 'someone'}: kept {last.kept}"

    def _chosen_conflict(self) -> str | None:
        rows = self.conflicts_table.selectionModel().selectedRows() if self._conflicts else []
        if rows and rows[0].row() < len(self._conflicts):
            return self._conflicts[rows[0].row()].uid
        return None

    def current_conflict(self) -> Conflict | None:
        """The conflict on show (None: the machine has none shown)."""
        uid = self._chosen_conflict()
        return next((c for c in self._conflicts if c.uid == uid), None)

    @Slot()
    def _show_conflict(self) -> None:
        """The conflict chosen, side by side. The same conflict shown again (the register read
        again) keeps what the person chose and typed."""
        c = self.current_conflict()
        same = c is not None and c.uid == self._shown
        self._shown = c.uid if c is not None else None
        chose = self.keep_group.checkedId() if same else -1
        for button in self.keep_group.buttons():
            self.keep_group.removeButton(button)
            self.keep_row.removeWidget(button)
            button.deleteLater()
        self.sides_table.clear()
        self.sides_table.setRowCount(0)
        self.sides_table.setColumnCount(1)
        if not same:
            self.settle_note.clear()
            self.settle_label.clear()
        if c is None:
            self.conflict_title.setText("")
            self.settle_box.setEnabled(False)
            return
        found = f"found {when_text(c.at_utc)} UTC" + (f" by {c.who}" if c.who else "")
        self.conflict_title.setText(
            f"<b>{c.axis.ref}</b> — conflict {c.short}, {found}: {SUBJECTS[c.subject]} between "
            f"{' and '.join(side_name(s) for s in c.sides)}."
            + "".join(
                f"<br>Settled by {r.who or 'someone'} at {when_text(r.at_utc)} UTC: kept {r.kept}"
                + (f" ({r.note})" if r.note else "")
                for r in c.resolutions
            )
        )
        kept = c.resolutions[-1].kept if c.resolutions and not c.open else 0
        self.sides_table.setColumnCount(len(c.sides) + 1)
        self.sides_table.setHorizontalHeaderLabels(
            [
                _ITEM_HEADINGS[c.subject],
                *(f"{n}: {side_name(s)}{' — kept' if n == kept else ''}" for n, s in enumerate(c.sides, 1)),
            ]
        )
        header = self.sides_table.horizontalHeader()
        header.setSectionResizeMode(0, QHeaderView.ResizeMode.ResizeToContents)
        items = c.items()
        self.sides_table.setRowCount(len(items))
        for r, key in enumerate(items):
            cells = [self._item_heading(c, key)]
            for side in c.sides:
                held = c.held_words(key, side)
                if held is None:
                    cells.append("(nothing recorded)")
                    continue
                by = ", ".join(t for t in (held.who, f"{held.when} UTC" if held.when else "") if t)
                cells.append("\n".join(t for t in (held.value, " — ".join(x for x in (held.source, by) if x),
                                                    f"recorded in {held.where}") if t))
            for col, text in enumerate(cells):
                item = QTableWidgetItem(text)
                item.setToolTip(text)
                if col == 0:
                    item.setTextAlignment(Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignVCenter)
                self.sides_table.setItem(r, col, item)
        self.sides_table.resizeRowsToContents()
        for n, side in enumerate(c.sides, 1):
            button = QRadioButton(f"Keep &{n}: {side_name(side)}")
            button.setObjectName(f"keep{n}")
            self.keep_group.addButton(button, n)
            self.keep_row.addWidget(button)
            button.setChecked(n == kept or (c.open and n == chose))
        if not self.settle_who.text().strip():
            self.settle_who.setText(self.operator())
        pending = c.uid in self.settling
        self.settle_box.setEnabled(c.open and not pending and self.writer is not None)
        if pending:
            self.settle_label.setText(self._state_words(c) + ".")
        elif self.writer is None:
            self.settle_label.setText("This window records nothing in this register, so it cannot settle "
                                      f"a conflict: fha-studio register resolve {c.short} --keep N does.")
        self._settle_ready()

    def _item_heading(self, c: Conflict, key: str) -> str:
        name = c.item_name(key)
        if c.subject != "parameters":
            return name
        item = parameter_item(key, c.axis.driver_model)
        return f"{name} ({item.unit})" if item is not None and item.unit else name

    @Slot()
    def _settle_ready(self) -> None:
        self.settle_button.setEnabled(self.keep_group.checkedId() > 0)

    @Slot()
    def settle(self) -> bool:
        """Settles the conflict on show by keeping the side chosen: the same fact as ``fha-studio
        register resolve``, through the window's writer (a server's waits on this computer until
        it reaches the server). True when it was handed over."""
        c, keep = self.current_conflict(), self.keep_group.checkedId()
        if c is None or keep < 1 or self.writer is None:
            return False
        # with the conflict as recorded: a server's settlement goes to this computer's queue first
        fact = settlement_fact(c.uid, keep, self.settle_who.text().strip(), self.settle_note.text().strip(),
                               self._records.get(c.uid))
        kept = f"kept {keep}, {side_name(c.sides[keep - 1])}"
        self._refused = ""
        self.writer.record(c.axis.ref, [fact])
        if self._refused:  # a register file says at once (_not_recorded showed why)
            return False
        if isinstance(self.writer, ServerWriter):
            self.settling[c.uid] = (keep, c.axis.ref)
            self._list_conflicts()
            self.settle_label.setText(
                f"Conflict {c.short}: {kept}. Recorded on this computer; it reaches the server with the "
                "next delivery (the message line says when the server does not answer)."
            )
            return True
        self.refresh()  # a register file: answered at once
        self.settle_label.setText(f"Conflict {c.short} settled: {kept}.")
        return True

    @Slot(str, str, str)
    def _not_recorded(self, axis: str, what: str, why: str) -> None:
        if what != SettlementFact.what:
            return
        self._refused = why
        for uid, (_keep, ref) in list(self.settling.items()):  # a server's queue said no: open again
            if ref == axis:
                self.settling.pop(uid)
        if self.isVisible():
            self._show_conflicts()  # it may have been settled meanwhile
            self.settle_label.setText(f"Not settled ({axis}): {why}")

    @Slot(object)
    def _delivered(self, state: ServerState) -> None:
        if self.settling and state.delivered and self.isVisible():
            self.refresh()


#: The first column of a conflict's sides.
_ITEM_HEADINGS = {"parameters": "Parameter", "origin": "What", "axis": "Field"}


def _history_text(event) -> str:
    """A history line as the dialog shows it: an open conflict is settled on the conflicts tab,
    not by the command line the register's own words name."""
    hint = event.data.get("hint") if event.kind == EventKind.CONFLICT else None
    if hint and event.text.endswith(hint):
        return f"{event.text.removesuffix(hint)} — settle it on the Conflicts tab"
    return event.text
