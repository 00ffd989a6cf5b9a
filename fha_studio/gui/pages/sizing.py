"""Sizing: the selection calculator of Chapter 2 as a page (filled in when the calculator lands)."""

from __future__ import annotations

from PySide6.QtWidgets import QLabel, QVBoxLayout, QWidget

from fha_studio.gui.session import Session


class SizingPage(QWidget):
    def __init__(self, session: Session, main_window=None):
        super().__init__()
        self.session = session
        layout = QVBoxLayout(self)
        layout.addWidget(QLabel("The selection calculator (Chapter 2) appears here."))
        layout.addStretch(1)
