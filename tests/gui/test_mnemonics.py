"""Alt + a letter reaches one thing only: every page's tab letter is unique in the whole window
(on every page), and Alt + that letter shows the page at the first press."""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import QAbstractButton, QApplication, QGroupBox, QLabel, QTabBar, QToolButton

from fha_studio.gui.mnemonics import mnemonic


def visible_mnemonics(window) -> dict[str, list[str]]:
    """Letter -> the visible things that claim it (tabs, toolbar actions, buttons, labels with a
    buddy, group boxes), in the window as shown now."""
    found: dict[str, list[str]] = {}

    def claim(text: str, what: str) -> None:
        letter = mnemonic(text)
        if letter:
            found.setdefault(letter, []).append(f"{what} {text.replace('&', '')!r}")

    for i in range(window.tabs.count()):
        claim(window.tabs.tabText(i), "page tab")
    for action in window.findChildren(type(window.connect_action)):
        if action.isVisible() and action.associatedObjects():
            claim(action.text(), "action")
    for button in window.findChildren(QAbstractButton):
        if isinstance(button, QToolButton) and button.defaultAction() is not None:
            continue  # the action is counted
        if button.isVisible() and not isinstance(button.parent(), QTabBar):
            claim(button.text(), "button")
    for label in window.findChildren(QLabel):
        if label.isVisible() and label.buddy() is not None:
            claim(label.text(), "label")
    for box in window.findChildren(QGroupBox):
        if box.isVisible():
            claim(box.title(), "group")
    return found


def test_every_page_letter_is_unique_on_every_page_and_switches_at_the_first_press(make_window, qtbot):
    window = make_window()
    window.resize(1366, 740)
    tab_letters = [mnemonic(window.tabs.tabText(i)) for i in range(window.tabs.count())]
    assert None not in tab_letters, "every page has an Alt+letter"
    assert len(set(tab_letters)) == len(tab_letters)
    problems = []
    for index in range(window.tabs.count()):
        window.tabs.setCurrentIndex(index)
        qtbot.waitUntil(lambda i=index: window.tabs.currentIndex() == i, timeout=10000)
        page = window.tabs.tabText(index).replace("&", "")
        for letter, claims in visible_mnemonics(window).items():
            if len(claims) > 1:
                problems.append(f"on {page}: Alt+{letter.upper()} is {', '.join(claims)}")
    assert not problems, "\n".join(problems)
    window.activateWindow()  # shortcuts act in the active window
    qtbot.waitUntil(window.isActiveWindow, timeout=10000)
    for index, letter in enumerate(tab_letters):
        start = (index + 1) % window.tabs.count()
        window.tabs.setCurrentIndex(start)
        qtbot.keyClick(window.tabs.currentWidget(), getattr(Qt.Key, f"Key_{letter.upper()}"),
                       Qt.KeyboardModifier.AltModifier)
        qtbot.waitUntil(lambda i=index: window.tabs.currentIndex() == i, timeout=10000)


def test_space_jogs_on_the_jog_buttons_only(make_window, qtbot):
    """Space held on FWD jogs; on Move or Servo ON (focus left there) it does nothing."""
    from fha_studio.gui.link import Jog, MoveBy, Servo

    window = make_window(connect="sim://FHA-25C-50-US250?paced=0")
    page = window.show_page("jog")
    motion = page.motion
    qtbot.waitUntil(lambda: motion.move_button.isEnabled() or motion.servo_on_button.isEnabled(),
                    timeout=10000)
    sent = []
    window.link.sigCommand.connect(lambda command: sent.append(type(command.request)))
    for button in (page.motion.move_button, page.motion.servo_on_button):
        button.setFocus()
        qtbot.keyPress(button, Qt.Key.Key_Space)
        qtbot.keyRelease(button, Qt.Key.Key_Space)
    QApplication.processEvents()  # a key is handled as it is delivered: what it sends is sent by now
    assert MoveBy not in sent and Servo not in sent
    page.motion.fwd_button.setEnabled(True)
    page.motion.fwd_button.setFocus()
    qtbot.keyPress(page.motion.fwd_button, Qt.Key.Key_Space)
    qtbot.waitUntil(lambda: Jog in sent, timeout=10000)
    qtbot.keyRelease(page.motion.fwd_button, Qt.Key.Key_Space)
