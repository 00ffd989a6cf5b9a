"""The Jog page and the scope's Move panel are one widget (gui/motion_controls.py): the same
rules, said once."""

from __future__ import annotations

from PySide6.QtCore import Qt

from fha_studio.gui.link import Jog, Servo
from fha_studio.gui.motion_controls import NOT_CONNECTED_TEXT, MotionControls, MotionLayout


def test_the_jog_page_and_the_scope_panel_show_one_widget_that_says_why_nothing_moves(make_window):
    window = make_window()
    jog, panel = window.show_page("jog").motion, window.show_page("scope").jog_panel
    assert isinstance(jog, MotionControls) and isinstance(panel, MotionControls)
    assert (jog.motion_layout, panel.motion_layout) == (MotionLayout.PAGE, MotionLayout.PANEL)
    for controls in (jog, panel):
        assert controls.message.text() == NOT_CONNECTED_TEXT
        assert not any(w.isEnabled() for w in (controls.servo_on_button, controls.fwd_button,
                                                 controls.move_button, controls.speed_spin))
    assert jog.stop_button is None and panel.stop_button is not None  # the page's STOP is the toolbar's


def test_a_held_jog_on_the_jog_page_is_let_go_when_the_servo_goes_off(make_window, qtbot):
    window = make_window(connect="sim://FHA-25C-50-US250?paced=0")
    motion = window.show_page("jog").motion
    window.link.send(Servo(True))
    qtbot.waitUntil(lambda: motion.fwd_button.isEnabled(), timeout=10000)
    qtbot.mousePress(motion.fwd_button, Qt.MouseButton.LeftButton)
    qtbot.waitUntil(lambda: (window.link.status.speed_rpm or 0) > 1.0, timeout=10000)
    jogs: list[float] = []
    window.link.sigCommand.connect(lambda c: isinstance(c.request, Jog) and jogs.append(c.request.speed_rpm))
    window.link.send(Servo(False))
    qtbot.waitUntil(lambda: not motion.fwd_button.isEnabled(), timeout=10000)
    assert not motion.jog_held and jogs == [0.0]  # let go once: the lease is not renewed
