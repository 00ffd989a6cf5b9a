"""Sizing: the selection calculator of FHA-C manual Chapter 2 as a page.

Load parts from the Appendix 2 shapes and materials add up to the load inertia; the duty cycle
goes through the calculator (fha_studio.logic.sizing); the checks are listed with the manual's
section, the duty is drawn on the torque-speed plane against the actuator's continuous and
maximum ranges, and the catalogue actuators the duty passes on are suggested.
"""

from __future__ import annotations

import inspect

import pyqtgraph as pg
from PySide6.QtCore import QSettings, Qt, Slot
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (
    QComboBox,
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QListWidget,
    QPushButton,
    QScrollArea,
    QSplitter,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from fha_studio.gui.connect_dialog import catalogue_codes
from fha_studio.gui.pages.base import BasePage
from fha_studio.gui.session import Session
from fha_studio.gui.shape_figure import LETTERS, ShapeFigure
from fha_studio.logic.sizing import SizingResult
from fha_studio.logic.wording import with_unit

PASS_COLOUR = QColor("#2e7d32")
FAIL_COLOUR = QColor("#b00020")


def _spin(value: float, minimum: float, maximum: float, decimals: int, suffix: str) -> QDoubleSpinBox:
    spin = QDoubleSpinBox()
    spin.setRange(minimum, maximum)
    spin.setDecimals(decimals)
    spin.setValue(value)
    spin.setSuffix(suffix)
    spin.setKeyboardTracking(False)
    return spin


def _words(name: str) -> str:
    return name.replace("_", " ").capitalize()


class SizingPage(BasePage):
    """Load inertia, duty cycle, checks, torque-speed picture, suggestion."""

    def __init__(self, session: Session, main_window=None):
        super().__init__()
        from fha_studio.logic.sizing.inertia import SHAPES, materials

        self.session = session
        self.state = session.state  # the axis: its actuator and declared load inertia are sized here
        self.shapes = SHAPES
        self.materials = materials()
        self.parts: list[tuple[str, float]] = []  # (description, inertia about the output axis)
        self.result: SizingResult | None = None
        self.suggested: list[str] = []
        outer = QHBoxLayout(self)
        splitter = QSplitter(Qt.Orientation.Horizontal)
        splitter.setObjectName("sizingSplitter")
        self.splitter = splitter
        outer.addWidget(splitter)

        # -- left: inputs ------------------------------------------------------------------------
        scroll = QScrollArea()
        scroll.setWidgetResizable(True)
        scroll.setHorizontalScrollBarPolicy(Qt.ScrollBarPolicy.ScrollBarAlwaysOff)
        scroll.setMinimumWidth(440)
        left = QWidget()
        scroll.setWidget(left)
        l_layout = QVBoxLayout(left)

        load_box = QGroupBox("Load inertia from shapes (Appendix 2)")
        form = QFormLayout(load_box)
        self.shape_combo = QComboBox()
        for name in SHAPES:
            self.shape_combo.addItem(_words(name), name)
        self.material_combo = QComboBox()
        for m in self.materials:
            self.material_combo.addItem(f"{m.name} (SG {m.specific_gravity:g})", m.density_kg_m3)
        self.material_combo.setCurrentIndex(
            max(0, self.material_combo.findText("Aluminum", Qt.MatchFlag.MatchStartsWith))
        )
        form.addRow("&Shape:", self.shape_combo)
        self.shape_figure = ShapeFigure()
        form.addRow(self.shape_figure)
        form.addRow("&Material:", self.material_combo)
        self.dims_widget = QWidget()
        self.dims_form = QFormLayout(self.dims_widget)
        self.dims_form.setContentsMargins(0, 0, 0, 0)
        form.addRow(self.dims_widget)
        self.axis_combo = QComboBox()
        self.offset_spin = _spin(0.0, 0.0, 10000.0, 1, " mm")
        self.offset_spin.setToolTip(
            "Distance F from the part's centre of gravity to the output axis: I = Ig + m F²"
        )
        form.addRow("&Axis of rotation:", self.axis_combo)
        form.addRow("&Offset F from the output axis:", self.offset_spin)
        self.part_label = QLabel("")
        form.addRow(self.part_label)
        buttons = QHBoxLayout()
        self.add_part_button = QPushButton("&Add part to the load")
        self.remove_part_button = QPushButton("Remo&ve part")
        buttons.addWidget(self.add_part_button)
        buttons.addWidget(self.remove_part_button)
        form.addRow(buttons)
        self.parts_list = QListWidget()
        self.parts_list.setMaximumHeight(90)
        form.addRow(self.parts_list)
        l_layout.addWidget(load_box)

        duty_box = QGroupBox("Duty cycle (2-4)")
        d_form = QFormLayout(duty_box)
        self.actuator_combo = QComboBox()
        self.actuator_combo.setEditable(True)
        self.actuator_combo.addItems(catalogue_codes())
        self.actuator_combo.setCurrentText(self.state.actuator_code)
        self.actuator_combo.lineEdit().setPlaceholderText("model code, e.g. FHA-25C-50-US250")
        self.actuator_combo.setToolTip("The actuator of the axis (the same as on the Connection page)")
        self.inertia_spin = _spin(self.state.load_inertia_kgm2, 0.0, 10000.0, 4, " kg·m²")
        self.inertia_spin.setToolTip(
            "Load inertia JL about the output axis (the parts above add up here); the axis's declared load "
            "inertia, the same on the Scope and Model check pages"
        )
        self.speed_spin = _spin(30.0, 0.1, 1000.0, 1, " r/min")
        self.angle_spin = _spin(90.0, 0.1, 100000.0, 1, " °")
        self.cycle_spin = _spin(2.0, 0.01, 100000.0, 2, " s")
        self.torque_spin = _spin(0.0, -10000.0, 10000.0, 1, " N·m")
        self.torque_spin.setToolTip(
            "Load torque TL, positive when it opposes the rotation (friction, a load to lift)"
        )
        self.accel_spin = _spin(0.0, 0.0, 1000.0, 3, " s")
        self.accel_spin.setSpecialValueText("at the maximum torque (2-4-4)")
        self.accel_spin.setToolTip(
            "Acceleration (and braking) time the machine needs. Left at the minimum, each actuator "
            "accelerates at its own maximum torque as the manual does: a larger one accelerates harder, "
            "so its effective torque is higher and it can fail where a smaller one passes."
        )
        d_form.addRow("Ac&tuator:", self.actuator_combo)
        d_form.addRow("Load &inertia JL:", self.inertia_spin)
        d_form.addRow("Spee&d N:", self.speed_spin)
        d_form.addRow("Move an&gle θ:", self.angle_spin)
        d_form.addRow("C&ycle time t:", self.cycle_spin)
        d_form.addRow("Load tor&que TL:", self.torque_spin)
        d_form.addRow("Acceleration time ta:", self.accel_spin)
        l_layout.addWidget(duty_box)
        l_layout.addStretch(1)
        # Calculate stays in sight below the inputs, however far they scroll
        left_pane = QWidget()
        lp_layout = QVBoxLayout(left_pane)
        lp_layout.setContentsMargins(0, 0, 0, 0)
        lp_layout.addWidget(scroll, 1)
        self.calculate_button = QPushButton("&Calculate")
        lp_layout.addWidget(self.calculate_button)
        splitter.addWidget(left_pane)

        # -- right: results ----------------------------------------------------------------------
        right = QWidget()
        r_layout = QVBoxLayout(right)
        r_layout.setContentsMargins(0, 0, 0, 0)
        self.verdict = QLabel("")
        self.verdict.setWordWrap(True)
        self.verdict.setObjectName("sizingVerdict")
        r_layout.addWidget(self.verdict)
        self.assumption = QLabel("")
        self.assumption.setWordWrap(True)
        self.assumption.setObjectName("sizingAssumption")
        self.assumption.setStyleSheet("color: #444;")
        r_layout.addWidget(self.assumption)
        self.plot = pg.GraphicsLayoutWidget()
        self.plot.setBackground("w")
        self.plot.setObjectName("torqueSpeedPlot")
        # the legend in a row of its own above the plot (as the scope's and the tuning page's):
        # inside it, at 1280 x 720, its last row sat on the continuous range's edge, and a duty's
        # points can fall anywhere in the plane
        self.legend = pg.LegendItem(colCount=2, labelTextColor="#303030")
        self.legend.layout.setContentsMargins(4, 0, 4, 0)
        self.plot.addItem(self.legend, row=0, col=0)
        self.plot_item = self.plot.addPlot(row=1, col=0)
        self.plot_item.setLabel("bottom", "Output speed", units="r/min")
        self.plot_item.setLabel("left", "Output torque", units="N·m")
        self.plot_item.showGrid(x=True, y=True, alpha=0.25)
        self.plot_item.setMenuEnabled(False)
        self.plot.setMinimumHeight(220)
        r_layout.addWidget(self.plot, 3)
        self.checks_table = QTableWidget(0, 5)
        self.checks_table.setObjectName("checksTable")
        self.checks_table.setHorizontalHeaderLabels(["Check", "Value", "Limit", "", "Section"])
        self.checks_table.verticalHeader().setVisible(False)
        self.checks_table.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        header = self.checks_table.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        header.setSectionResizeMode(0, QHeaderView.ResizeMode.Stretch)
        r_layout.addWidget(self.checks_table, 2)
        self.suggestion = QLabel("")
        self.suggestion.setWordWrap(True)
        self.suggestion.setObjectName("sizingSuggestion")
        r_layout.addWidget(self.suggestion)
        splitter.addWidget(right)
        splitter.setStretchFactor(0, 2)
        splitter.setStretchFactor(1, 3)

        self.dim_spins: dict[str, QDoubleSpinBox] = {}
        self.shape_combo.currentIndexChanged.connect(self._build_dimensions)
        self.material_combo.currentIndexChanged.connect(self._update_part)
        self.axis_combo.currentIndexChanged.connect(self._update_part)
        self.offset_spin.valueChanged.connect(self._update_part)
        self.add_part_button.clicked.connect(self.add_part)
        self.remove_part_button.clicked.connect(self.remove_part)
        self.calculate_button.clicked.connect(self.calculate)
        for spin in (self.speed_spin, self.angle_spin, self.cycle_spin, self.torque_spin, self.accel_spin):
            spin.editingFinished.connect(self.calculate)
        # the actuator and the load inertia are the axis's: edited here, they change for every page,
        # and a change from anywhere sizes again (never the previous actuator's result on show)
        self.inertia_spin.valueChanged.connect(self._inertia_edited)
        self.actuator_combo.activated.connect(lambda _i: self._actuator_edited())
        self.actuator_combo.lineEdit().returnPressed.connect(self._actuator_edited)
        self.state.sigActuatorChanged.connect(self._axis_changed)
        self.state.sigLoadInertiaChanged.connect(self._axis_changed)
        self._build_dimensions()
        self._calculated_once = False

    def showEvent(self, event) -> None:
        # the first calculation (all catalogue actuators for the suggestion) waits until the page
        # is looked at, so that it costs nothing at start-up
        if not self._calculated_once:
            self._calculated_once = True
            self.calculate()
        super().showEvent(event)

    # -- settings ------------------------------------------------------------------------------------
    def restore_settings(self, settings: QSettings) -> None:
        state = settings.value("sizing/splitter")
        if state is not None:
            self.splitter.restoreState(state)
        for key, spin in self._duty_spins().items():
            value = settings.value(f"sizing/{key}")
            if value is not None:
                spin.setValue(float(value))

    def save_settings(self, settings: QSettings) -> None:
        settings.setValue("sizing/splitter", self.splitter.saveState())
        for key, spin in self._duty_spins().items():
            settings.setValue(f"sizing/{key}", spin.value())

    def _duty_spins(self) -> dict[str, QDoubleSpinBox]:
        # the load inertia is not among them: the axis's state keeps it
        return {
            "speed_rpm": self.speed_spin,
            "angle_deg": self.angle_spin,
            "cycle_time_s": self.cycle_spin,
            "load_torque_nm": self.torque_spin,
            "accel_time_s": self.accel_spin,
        }

    # -- load inertia ----------------------------------------------------------------------------------
    @Slot()
    def _build_dimensions(self) -> None:
        while self.dims_form.rowCount():
            self.dims_form.removeRow(0)
        self.dim_spins.clear()
        shape = self.shape_combo.currentData()
        function = self.shapes[shape]
        self.shape_figure.set_shape(shape)
        letters = LETTERS.get(shape, {})
        for name in inspect.signature(function).parameters:
            if name == "density_kg_m3":
                continue
            if name.endswith("_deg"):
                spin = _spin(30.0, 0.0, 90.0, 1, " °")
                label = _words(name[:-4])
            else:
                spin = _spin(100.0, 0.1, 100000.0, 1, " mm")
                label = _words(name[:-2] if name.endswith("_m") else name)
            if name in letters:  # the letter of the figure first: "B — base"
                label = f"{letters[name]} — {label.lower()}"
            if "inner" in name or "wall" in name:
                spin.setValue(20.0)
            spin.valueChanged.connect(self._update_part)
            self.dims_form.addRow(f"{label}:", spin)
            self.dim_spins[name] = spin
        self._update_part()

    def current_part(self):
        """(ShapeInertia, inertia about the output axis in kg m^2) of the part being entered."""
        from fha_studio.logic.sizing.inertia import off_axis_inertia_kgm2

        function = self.shapes[self.shape_combo.currentData()]
        kwargs = {
            name: spin.value() if name.endswith("_deg") else spin.value() / 1000.0
            for name, spin in self.dim_spins.items()
        }
        shape = function(density_kg_m3=float(self.material_combo.currentData()), **kwargs)
        moments = {"x": shape.ix_kgm2, "y": shape.iy_kgm2, "z": shape.iz_kgm2}
        axes = {a: moment for a, moment in moments.items() if moment is not None}
        if [self.axis_combo.itemData(i) for i in range(self.axis_combo.count())] != list(axes):
            self.axis_combo.blockSignals(True)
            self.axis_combo.clear()
            for a in axes:
                self.axis_combo.addItem({"x": "x (long axis)", "y": "y (across)", "z": "z (across)"}[a], a)
            self.axis_combo.blockSignals(False)
        ig = axes[self.axis_combo.currentData() or next(iter(axes))]
        total = off_axis_inertia_kgm2(ig, shape.mass_kg, self.offset_spin.value() / 1000.0)
        return shape, total

    @Slot()
    def _update_part(self) -> None:
        try:
            shape, total = self.current_part()
        except ValueError as exc:
            self.part_label.setText(f"<span style='color:#b00020'>{exc}</span>")
            self.add_part_button.setEnabled(False)
            return
        self.add_part_button.setEnabled(True)
        note = f"<br><i>{shape.note}</i>" if shape.note else ""
        self.part_label.setText(
            f"mass {shape.mass_kg:.3g} kg, I = <b>{total:.4g} kg·m²</b> about the output axis{note}"
        )
        self.part_label.setWordWrap(True)

    @Slot()
    def add_part(self) -> None:
        shape, total = self.current_part()
        text = (
            f"{self.shape_combo.currentText()}, {self.material_combo.currentText().split(' (')[0]}: "
            f"{shape.mass_kg:.3g} kg, {total:.4g} kg·m²"
        )
        self.parts.append((text, total))
        self.parts_list.addItem(text)
        self._parts_changed()

    @Slot()
    def remove_part(self) -> None:
        row = self.parts_list.currentRow()
        if row < 0 and self.parts:
            row = len(self.parts) - 1
        if row >= 0:
            self.parts.pop(row)
            self.parts_list.takeItem(row)
            self._parts_changed()

    def _parts_changed(self) -> None:
        total_kgm2 = sum(i for _, i in self.parts)
        if self.parts and total_kgm2 != self.state.load_inertia_kgm2:
            self.state.set_load_inertia(total_kgm2)  # the axis's load: every page, and sized again
            return
        self.calculate()

    # -- the calculation --------------------------------------------------------------------------------
    @Slot()
    def _actuator_edited(self) -> None:
        code = self.actuator_combo.currentText().strip()
        try:
            changed = self.state.set_actuator(code)
        except ValueError as exc:  # the catalogue says what is wrong; the axis keeps its actuator
            self._clear_result(f"Actuator: {exc}")
            return
        if not changed:
            self.calculate()

    @Slot(float)
    def _inertia_edited(self, value_kgm2: float) -> None:
        self.state.set_load_inertia(value_kgm2)

    def _axis_changed(self, *_args) -> None:
        code = self.state.actuator_code
        if self.actuator_combo.currentText().strip().upper() != code:
            self.actuator_combo.setCurrentText(code)
        if self.inertia_spin.value() != self.state.load_inertia_kgm2:
            self.inertia_spin.blockSignals(True)
            self.inertia_spin.setValue(self.state.load_inertia_kgm2)
            self.inertia_spin.blockSignals(False)
        if self.isVisible():
            self.calculate()
        else:  # sized when next shown; until then nothing of the previous axis is kept
            self._calculated_once = False
            self._clear_result("")

    def _clear_result(self, why: str) -> None:
        self.result = None
        self.assumption.setText("")
        self.verdict.setText(f"<span style='color:#b00020'>{why}</span>" if why else "")
        self.checks_table.setRowCount(0)
        self._clear_plot()

    def duty(self):
        from fha_studio.logic.sizing import DutyCycle

        return DutyCycle(
            load_inertia_kgm2=self.inertia_spin.value(),
            speed_rpm=self.speed_spin.value(),
            angle_deg=self.angle_spin.value(),
            cycle_time_s=self.cycle_spin.value(),
            load_torque_nm=self.torque_spin.value(),
            # the minimum of the field means "not given": at the maximum torque, as the manual does
            accel_time_s=self.accel_spin.value() or None,
        )

    @Slot()
    def calculate(self) -> None:
        from fha_studio.logic.sizing import SizingError, size_axis, suggest_actuators

        code = self.state.actuator_code
        try:
            duty = self.duty()
        except (SizingError, ValueError) as exc:
            self._clear_result(f"Cannot size: {exc}")
            return
        if not code:
            self._clear_result("")
            self.verdict.setText(
                "No actuator on the axis yet: type its model code here (or on the Connection page), "
                "or pick one this duty passes on (below)."
            )
        else:
            try:
                result = size_axis(code, duty)
            except (SizingError, ValueError) as exc:
                self._clear_result(f"Cannot size {code}: {exc}")
                return
            self._show_result(code, result)
        try:
            self.suggested = [r.actuator_code for r in suggest_actuators(duty)]
        except (SizingError, ValueError):
            self.suggested = []
        if self.suggested:
            self.suggestion.setText(
                "<b>Actuators this duty passes on</b> (200 V, incremental; smallest first): "
                + ", ".join(self.suggested[:8])
                + (" …" if len(self.suggested) > 8 else "")
            )
        else:
            self.suggestion.setText(
                "<b style='color:#b00020'>No catalogue actuator passes this duty.</b> "
                "Lengthen the cycle, lower the speed or the load inertia."
            )

    def _show_result(self, code: str, result) -> None:
        self.result = result
        self.assumption.setText(f"<b>Assumption:</b> {code} {result.assumption}.")
        failed = result.failed
        if result.ok:
            self.verdict.setText(
                f"<b style='color:#2e7d32'>{code} passes every check</b> of Chapter 2 for this duty."
            )
        else:
            names = ", ".join(c.name for c in failed)
            self.verdict.setText(
                f"<b style='color:#b00020'>{code} fails {len(failed)} check(s)</b>: {names}."
            )
        self._fill_checks(result)
        self._draw(result)

    def _fill_checks(self, result) -> None:
        checks = list(result.checks)
        self.checks_table.setRowCount(len(checks))
        for row, check in enumerate(checks):
            comparison = {"<=": "≤", ">=": "≥"}.get(check.comparison, check.comparison)
            cells = [
                check.name,
                with_unit(f"{check.value:.4g}", check.unit),
                with_unit(f"{comparison} {check.limit:.4g}", check.unit),
                "pass" if check.ok else "FAIL",
                check.section,
            ]
            for col, text in enumerate(cells):
                item = QTableWidgetItem(text)
                item.setToolTip(check.note)
                if col == 3:
                    item.setForeground(PASS_COLOUR if check.ok else FAIL_COLOUR)
                    font = item.font()
                    font.setBold(True)
                    item.setFont(font)
                self.checks_table.setItem(row, col, item)

    def _clear_plot(self) -> None:
        self.plot_item.clear()
        self.legend.clear()

    def _curve(self, *args, **kwargs) -> None:
        """A curve on the plot, named in the legend above it."""
        item = self.plot_item.plot(*args, **kwargs)
        self.legend.addItem(item, kwargs["name"])

    def _draw(self, result) -> None:
        env = result.envelope()
        self._clear_plot()
        tm, nm = env["max_torque_nm"], env["max_speed_rpm"]
        tc, nc = env["continuous_torque_nm"], env["continuous_speed_rpm"]
        self._curve(
            [0, nm, nm, 0],
            [tm, tm, -tm, -tm],
            pen=pg.mkPen("#c62828", width=2, style=Qt.PenStyle.DashLine),
            name="maximum range",
        )
        self._curve(
            [0, nc, nc, 0], [tc, tc, -tc, -tc], pen=pg.mkPen("#1565c0", width=2), name="continuous range"
        )
        points = result.operating_points()
        duty = [p for p in points if p.phase != "effective"]
        self._curve(
            [p.speed_rpm for p in duty],
            [p.torque_nm for p in duty],
            pen=pg.mkPen("#555", width=1.5),
            symbol="o",
            symbolSize=7,
            symbolBrush="#555",
            name="duty: accelerate, run, brake",
        )
        eff = [p for p in points if p.phase == "effective"]
        if eff:
            ok = result.effective_torque_nm <= tc and result.average_speed_rpm <= nc
            self._curve(
                [eff[0].speed_rpm],
                [eff[0].torque_nm],
                pen=None,
                symbol="star",
                symbolSize=16,
                symbolBrush="#2e7d32" if ok else "#b00020",
                name="effective torque at average speed",
            )
        self.plot_item.setXRange(0, max(nm, self.speed_spin.value()) * 1.1, padding=0)
        self.plot_item.setYRange(-tm * 1.15, tm * 1.15, padding=0)
