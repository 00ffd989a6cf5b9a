"""The sizing plot's legend hides no curve at the sizes a laptop shows the window."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from PySide6.QtCore import QPointF


def _scene_points(view_box, item) -> list[QPointF]:
    """Points along a curve (each segment sampled) or its symbols, in the scene."""
    x, y = item.getData()
    points = list(zip(x, y, strict=True))
    if item.opts.get("pen") is not None and len(points) > 1:  # a line: along each segment
        points = [(x0 + s * (x1 - x0), y0 + s * (y1 - y0))
                  for (x0, y0), (x1, y1) in itertools.pairwise(points)
                  for s in np.linspace(0.0, 1.0, 200)]
    return [view_box.mapViewToScene(QPointF(float(px), float(py))) for px, py in points]


@pytest.mark.parametrize("size", [(1366, 768), (1280, 720)])
def test_the_legend_hides_no_curve(make_window, qtbot, size):
    window = make_window()
    window.resize(*size)
    page = window.show_page("sizing")
    qtbot.waitExposed(page)
    page.actuator_combo.setCurrentText("FHA-25C-50-US250")
    page.actuator_combo.lineEdit().returnPressed.emit()
    qtbot.waitUntil(lambda: page.result is not None, timeout=10000)
    # the README's duty: the continuous range's top edge ran under the legend's last row
    page.inertia_spin.setValue(1.2)
    page.speed_spin.setValue(40.0)
    page.angle_spin.setValue(120.0)
    page.cycle_spin.setValue(1.5)
    page.calculate()
    plot = page.plot_item
    legend = page.legend
    # the new legend rows are laid out at the next event loop turn: wait for the layout to settle
    qtbot.waitUntil(lambda: legend.mapRectToScene(legend.boundingRect()).bottom()
                    <= plot.mapRectToScene(plot.boundingRect()).top() + 1, timeout=5000)
    names = [label.text for _sample, label in legend.items]
    assert "continuous range" in names and "maximum range" in names
    box = legend.sceneBoundingRect()
    for item in plot.listDataItems():
        inside = [p for p in _scene_points(plot.getViewBox(), item) if box.contains(p)]
        assert not inside, f"the legend covers {item.name()} at {size}"
