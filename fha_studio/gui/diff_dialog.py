"""Loading a parameter file: drive, file and default side by side, a choice per row, and nothing
applied until the user confirms."""

from __future__ import annotations

from PySide6.QtGui import QBrush, QColor, QGuiApplication
from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QHeaderView,
    QLabel,
    QPlainTextEdit,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from fha_studio.gui.parameter_text import MODE_WORDS, value_text
from fha_studio.gui.session import Session

CHOICES = ("drive", "file", "default")
DIFF_BRUSH = QBrush(QColor("#ffe0b2"))


class ParameterDiffDialog(QDialog):
    """Rows: items known to the drive or the file. `chosen_values()` gives what to apply."""

    def __init__(self, session: Session, loaded, file_name: str, parent: QWidget | None = None):
        super().__init__(parent)
        self.setWindowTitle(f"Compare {file_name} with the drive")
        self.session = session
        self.loaded = loaded
        layout = QVBoxLayout(self)
        driver_model = self.session.state.driver_model
        head = (
            f"<b>{file_name}</b>: actuator {loaded.actuator or '?'}, driver {loaded.driver_model or '?'}, "
            f"saved {loaded.saved or '?'}."
        )
        warnings = []
        axis_code = self.session.state.actuator_code
        if axis_code and loaded.actuator and loaded.actuator != axis_code:
            warnings.append(
                f"The file was made for {loaded.actuator}, this axis is {axis_code}."
            )
        if loaded.driver_model and driver_model and loaded.driver_model.upper() != driver_model:
            warnings.append(
                f"The file was made on a {loaded.driver_model}, this drive is a {driver_model}."
            )
        if warnings:
            head += "<br><span style='color:#b00020'>⚠ " + " ".join(warnings) + " Check every row.</span>"
        label = QLabel(head)
        label.setWordWrap(True)
        layout.addWidget(label)

        self.rows: list[tuple[tuple[str, int], QComboBox, dict]] = []
        items = session.editable_items()
        self.table = QTableWidget(len(items), 6)
        self.table.setObjectName("diffTable")
        self.table.setHorizontalHeaderLabels(["Item", "Drive", "File", "Default", "Differs", "Apply"])
        self.table.verticalHeader().setVisible(False)
        self.table.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        header = self.table.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        header.setSectionResizeMode(0, QHeaderView.ResizeMode.Stretch)
        self.differing = 0
        for row, item in enumerate(items):
            key = (item.mode, item.number)
            values = {
                # read over the link, else as entered from the drive's front panel
                "drive": session.state.value_of(*key),
                "file": loaded.values.get(key),
                "default": item.default,
            }
            # what loading the file would change: the drive against the file (a value that only
            # differs from the default is the drive's setting, not a difference to act on)
            drive, in_file = values["drive"], values["file"]
            differs = drive is not None and in_file is not None and drive != in_file
            self.differing += differs
            cells = [
                f"{MODE_WORDS.get(str(item.mode))} {item.number}: {item.name}",
                value_text(item, values["drive"]) if values["drive"] is not None else "not known",
                value_text(item, values["file"]) if values["file"] is not None else "not in file",
                value_text(item, values["default"]),
                "yes" if differs else "",
            ]
            for col, text in enumerate(cells):
                cell = QTableWidgetItem(text)
                cell.setToolTip(item.description)
                if differs:
                    cell.setBackground(DIFF_BRUSH)
                self.table.setItem(row, col, cell)
            combo = QComboBox()
            for choice in CHOICES:
                if values[choice] is not None:
                    combo.addItem(f"{choice}", choice)
            preferred = (
                "file"
                if values["file"] is not None
                else "drive"
                if values["drive"] is not None
                else "default"
            )
            combo.setCurrentIndex(max(0, combo.findData(preferred)))
            combo.setAccessibleName(f"Apply for {item.name}")
            self.table.setCellWidget(row, 5, combo)
            self.rows.append((key, combo, values))
        layout.addWidget(self.table, 1)

        summary = QLabel(
            f"{self.differing} of {len(items)} items differ between the drive and the file (orange). "
            "Choose per row what to apply; nothing is written before <b>Apply</b>."
        )
        summary.setWordWrap(True)
        layout.addWidget(summary)
        if loaded.not_mapped:
            layout.addWidget(
                QLabel(f"<b>Not mapped ({len(loaded.not_mapped)})</b>: in the file, but not applicable here:")
            )
            self.not_mapped_view: QPlainTextEdit | None = QPlainTextEdit("\n".join(loaded.not_mapped))
            self.not_mapped_view.setReadOnly(True)
            self.not_mapped_view.setMaximumHeight(90)
            layout.addWidget(self.not_mapped_view)
        else:
            self.not_mapped_view = None
        if loaded.missing:
            layout.addWidget(
                QLabel(f"<b>Not in the file ({len(loaded.missing)})</b>: the drive keeps its value "
                       "(a file cut short, or made on another driver):")
            )
            self.missing_view: QPlainTextEdit | None = QPlainTextEdit("\n".join(loaded.missing))
            self.missing_view.setReadOnly(True)
            self.missing_view.setMaximumHeight(90)
            layout.addWidget(self.missing_view)
        else:
            self.missing_view = None
        self.buttons = QDialogButtonBox(
            QDialogButtonBox.StandardButton.Apply | QDialogButtonBox.StandardButton.Cancel
        )
        self.apply_button = self.buttons.button(QDialogButtonBox.StandardButton.Apply)
        self.apply_button.setText("&Apply the chosen values")
        self.apply_button.clicked.connect(self.accept)
        self.buttons.rejected.connect(self.reject)
        layout.addWidget(self.buttons)
        self._fit_to_screen()

    def _fit_to_screen(self) -> None:
        """Wide enough for every column (the Apply and Differs columns in view without scrolling),
        within the screen; on a narrow screen the item and value columns give up room (their
        texts elided, whole in the tooltip), never Differs and Apply."""
        table = self.table
        header = table.horizontalHeader()
        hints = [max(table.sizeHintForColumn(c), header.sectionSizeHint(c))
                 for c in range(table.columnCount())]
        chrome = table.verticalScrollBar().sizeHint().width() + 2 * table.frameWidth()
        margins = self.layout().contentsMargins()
        outside = margins.left() + margins.right() + chrome + 4
        width, height = sum(hints) + outside, 560
        screen = self.screen() or QGuiApplication.primaryScreen()
        if screen is not None:
            available = screen.availableGeometry()
            width = min(width, int(available.width() * 0.95))
            height = min(640, int(available.height() * 0.9))
        width = max(640, width)
        self.resize(width, height)
        room = width - outside
        if sum(hints) > room:
            fixed = hints[4] + hints[5]
            shrink = max(0.2, (room - fixed) / max(1, sum(hints[:4])))
            for column in range(4):
                header.setSectionResizeMode(column, QHeaderView.ResizeMode.Interactive)
                table.setColumnWidth(column, int(hints[column] * shrink) - 1)

    def set_choice(self, key: str, choice: str) -> None:
        """Picks drive/file/default for the item called `key` (tests and keyboard users)."""
        for (mode, number), combo, _values in self.rows:
            if self.session.parameter_model.item(mode, number).key == key:
                index = combo.findData(choice)
                if index < 0:
                    raise ValueError(f"{key}: no {choice} value to choose")
                combo.setCurrentIndex(index)
                return
        raise KeyError(key)

    def chosen_values(self) -> dict[tuple[str, int], int]:
        """{(mode, number): wire} of the rows whose chosen value differs from the drive's."""
        chosen = {}
        for key, combo, values in self.rows:
            value = values.get(combo.currentData())
            if value is not None and value != values["drive"]:
                chosen[key] = value
        return chosen
