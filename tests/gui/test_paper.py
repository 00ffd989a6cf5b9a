"""The scope's dark plot becomes a light one for the report, each trace keeping its colour."""

from __future__ import annotations

import colorsys

import numpy as np
from PySide6.QtGui import QColor, QImage, QPainter, QPen

from fha_studio.gui.paper import for_paper, save_for_paper


def test_a_dark_plot_prints_light_with_its_colours(qapp, tmp_path):
    image = QImage(200, 100, QImage.Format.Format_RGB32)
    image.fill(QColor("#111111"))
    painter = QPainter(image)
    painter.setPen(QPen(QColor("#f0c419"), 5))  # the scope's first (yellow) trace
    painter.drawLine(10, 50, 190, 50)
    painter.setPen(QPen(QColor("#ffffff"), 1))  # grid and text
    painter.drawLine(10, 10, 190, 10)
    painter.end()
    paper = for_paper(image)
    assert paper.pixelColor(5, 90).lightnessF() > 0.9  # the background is white now
    assert paper.pixelColor(100, 10).lightnessF() < 0.1  # white lines are black
    before, after = QColor("#f0c419"), paper.pixelColor(100, 50)
    h0, l0, s0 = colorsys.rgb_to_hls(before.redF(), before.greenF(), before.blueF())
    h1, l1, s1 = colorsys.rgb_to_hls(after.redF(), after.greenF(), after.blueF())
    assert abs(h1 - h0) < 0.02 and abs(s1 - s0) < 0.05 and abs(l1 - (1 - l0)) < 0.02
    path = tmp_path / "plot.png"
    image.save(str(path))
    save_for_paper(path)
    again = QImage(str(path))
    assert again.pixelColor(5, 90).lightnessF() > 0.9 and not list(tmp_path.glob(".*partial*"))
    data = np.array([again.pixelColor(x, 90).lightnessF() for x in range(0, 200, 10)])
    assert data.min() > 0.9


def test_a_light_plot_is_left_as_it_is(qapp):
    image = QImage(50, 20, QImage.Format.Format_RGB32)
    image.fill(QColor("#ffffff"))
    painter = QPainter(image)
    painter.setPen(QPen(QColor("#1565c0"), 3))
    painter.drawLine(0, 10, 50, 10)
    painter.end()
    paper = for_paper(image)
    assert paper.pixelColor(5, 2) == QColor("#ffffff") and paper.pixelColor(25, 10) == QColor("#1565c0")
