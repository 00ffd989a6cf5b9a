"""What a small screen hides: toolbar actions pushed behind the toolbar's chevron, tabs behind
scroll arrows, and text cut short (a label, button, group title or progress bar's text wider
than the room it has; a wrapped label's lines taller than it is). Used by the fit tests of the
main window and its dialogs."""

from __future__ import annotations

from PySide6 import QtGui
from PySide6.QtCore import Qt
from PySide6.QtGui import QFontMetrics, QTextDocument, QTextLayout, QTextOption
from PySide6.QtWidgets import (
    QAbstractButton,
    QCheckBox,
    QGroupBox,
    QLabel,
    QLineEdit,
    QProgressBar,
    QPushButton,
    QRadioButton,
    QStyle,
    QStyleOptionGroupBox,
    QTabBar,
    QTableView,
    QToolBar,
    QToolButton,
    QWidget,
)


def laid_out(qtbot, top: QWidget) -> None:
    """Waits until ``top`` is laid out: every shown widget's geometry the same on two looks in a
    row (a wrapped label's new height asks its layout once more), not a fixed wait."""
    last: list[object] = []

    def settled() -> bool:
        now = [(w, w.geometry().getRect()) for w in top.findChildren(QWidget) if w.isVisible()]
        same = now == last
        last[:] = now
        return same

    qtbot.waitUntil(settled, timeout=10000)


def _name(widget: QWidget) -> str:
    parent = widget.parentWidget()
    where = widget.objectName() or (type(parent).__name__ if parent is not None else "")
    return f"{type(widget).__name__} {where}".strip()


def _shown(widget: QWidget, top: QWidget) -> bool:
    """Visible, and not outside a scroll area's content that can be scrolled to it."""
    return widget.isVisibleTo(top) and widget.isVisible() and widget.width() > 0


def _plain_lines(label: QLabel) -> list[str]:
    text = label.text()
    if label.textFormat() == Qt.TextFormat.RichText or (
        label.textFormat() == Qt.TextFormat.AutoText and QtGui.Qt.mightBeRichText(text)
    ):
        document = QTextDocument()
        document.setDefaultFont(label.font())
        document.setHtml(text)
        text = document.toPlainText()
    elif label.buddy() is not None or "&" in text:  # a mnemonic's "&" is not drawn ("&&" is one "&")
        text = text.replace("&&", "\0").replace("&", "").replace("\0", "&")
    return [line for line in text.splitlines() if line.strip()]


def hidden_actions(top: QWidget) -> list[str]:
    """Toolbar actions behind the extension (chevron) button, tabs behind scroll arrows."""
    found = []
    for bar in top.findChildren(QToolBar):
        if not bar.isVisible():
            continue
        chevron = bar.findChild(QToolButton, "qt_toolbar_ext_button")
        if chevron is not None and chevron.isVisible():
            found.append(f"toolbar {bar.windowTitle()!r}: the chevron is shown")
        for action in bar.actions():
            if action.isSeparator() or not action.isVisible():
                continue
            widget = bar.widgetForAction(action)
            if widget is not None and not widget.isVisible():
                text = getattr(widget, "text", None)
                what = action.text() or (text() if callable(text) else type(widget).__name__)
                found.append(f"toolbar {bar.windowTitle()!r}: {what!r} is hidden")
    for tabs in top.findChildren(QTabBar):
        if not tabs.isVisible():
            continue
        arrows = [b for b in tabs.findChildren(QToolButton) if b.isVisible()]
        if arrows:
            titles = [tabs.tabText(i) for i in range(tabs.count())]
            found.append(f"tabs {titles}: scroll arrows shown, not every tab in view")
        for i in range(tabs.count()):
            text = tabs.tabText(i).replace("&", "")
            room = tabs.tabRect(i).width() - 16  # the tab's own padding
            if QFontMetrics(tabs.font()).horizontalAdvance(text) > room:
                found.append(f"tab {text!r}: cut ({room} px for its text)")
    return found


def _cut_wrapped(label: QLabel, room: int) -> list[str]:
    """A word-wrapped label is cut when its lines need more height than it has, or when a word
    (a long path, a URL) is wider than its width and cannot be broken."""
    found = []
    need = label.heightForWidth(label.width())
    if need > label.height() + 1:
        text = " ".join(_plain_lines(label))
        found.append(f"{_name(label)}: {text[:80]!r} needs {need} px of height, has {label.height()}")
    for line in _plain_lines(label):  # laid out as the label wraps it (between words)
        layout = QTextLayout(line, label.font())
        option = QTextOption()
        option.setWrapMode(QTextOption.WrapMode.WordWrap)
        layout.setTextOption(option)
        layout.beginLayout()
        while (row := layout.createLine()).isValid():
            row.setLineWidth(room)
            width = row.naturalTextWidth()
            if width > room + 1:
                text = line[row.textStart():row.textStart() + row.textLength()]
                found.append(f"{_name(label)}: {text[:80]!r} cannot wrap: needs {width:.0f} px, has {room}")
        layout.endLayout()
    return found


def _cut_inside_a_word(label: QLabel) -> list[str]:
    """A label shortened with an ellipsis (the whole text in its tooltip) must not end inside a
    word: "NOT LIVE: servo on (controller): th…" says nothing; cut between words it still does."""
    text, whole = label.text(), label.toolTip()
    shown = text[:-1]
    if not (text.endswith("…") and shown and whole.startswith(shown) and len(whole) > len(shown)):
        return []
    if shown[-1].isalnum() and whole[len(shown)].isalnum():
        return [f"{_name(label)}: {text[-40:]!r} ends inside a word of {whole[:80]!r}"]
    return []


def cut_texts(top: QWidget) -> list[str]:
    """Texts wider than the room their widget gives them, one line each."""
    found = []
    for label in top.findChildren(QLabel):
        if not _shown(label, top) or not label.text():
            continue
        room = label.contentsRect().width() - 2 * label.margin() - 2 * max(label.indent(), 0)
        metrics = QFontMetrics(label.font())
        if label.wordWrap():
            found += _cut_wrapped(label, room)
            continue
        found += _cut_inside_a_word(label)
        for line in _plain_lines(label):
            width = metrics.horizontalAdvance(line)
            if width > room + 1:
                found.append(f"{_name(label)}: {line[:80]!r} needs {width} px, has {room}")
    for button in top.findChildren(QAbstractButton):
        if not _shown(button, top) or not button.text() or isinstance(button.parentWidget(), QTabBar):
            continue
        if isinstance(button, (QPushButton, QCheckBox, QRadioButton, QToolButton)):
            need = button.sizeHint().width()
            if button.width() < need:
                found.append(f"{_name(button)}: {button.text()!r} needs {need} px, has {button.width()}")
    for box in top.findChildren(QGroupBox):
        if not _shown(box, top) or not box.title():
            continue
        option = QStyleOptionGroupBox()
        box.initStyleOption(option)
        title = box.style().subControlRect(
            QStyle.ComplexControl.CC_GroupBox, option, QStyle.SubControl.SC_GroupBoxLabel, box
        )
        need = QFontMetrics(box.font()).horizontalAdvance(box.title().replace("&", ""))
        if title.right() > box.width() or need > box.width() - 8:
            found.append(f"group {box.title()!r}: its title needs {need} px, the box is {box.width()}")
    for bar in top.findChildren(QProgressBar):
        if not _shown(bar, top) or not bar.isTextVisible() or not bar.text():
            continue
        need = QFontMetrics(bar.font()).horizontalAdvance(bar.text())
        room = bar.contentsRect().width() - 8
        if need > room:
            found.append(f"{_name(bar)}: {bar.text()!r} needs {need} px, has {room}")
    return found



def elided_cells(table: QTableView, margin_px: int = 6) -> list[str]:
    """Cells of ``table`` (its rows, scrolled or not) whose text is wider than their column: the
    view draws them shortened with an ellipsis ("Speed loop integral compensa…")."""
    model, header = table.model(), table.horizontalHeader()
    metrics = QFontMetrics(table.font())
    found = []
    for column in range(model.columnCount()):
        if header.isSectionHidden(column):
            continue
        room = header.sectionSize(column) - margin_px
        for row in range(model.rowCount()):
            text = model.data(model.index(row, column))
            if text is None or not str(text):
                continue
            need = metrics.horizontalAdvance(str(text))
            if need > room:
                found.append(f"row {row}, column {column}: {str(text)[:60]!r} needs {need} px, has {room}")
    return found


def cut_hints(top: QWidget) -> list[str]:
    """Empty fields whose hint (placeholder) is wider than the field: "your name (goes …" no
    longer says why the name is asked."""
    found = []
    for edit in top.findChildren(QLineEdit):  # an empty field's hint: "your name (goes …"
        hint = edit.placeholderText()
        if not _shown(edit, top) or edit.text() or not hint or not edit.isEnabled():
            continue
        need = QFontMetrics(edit.font()).horizontalAdvance(hint)
        room = edit.contentsRect().width() - 8  # the frame's and the text's own margins
        if need > room:
            found.append(f"{_name(edit)}: its hint {hint!r} needs {need} px, has {room}")
    return found
