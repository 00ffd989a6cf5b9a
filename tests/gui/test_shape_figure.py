"""Every Appendix 2 shape has a figure whose letters name the fields the sizing page asks for."""

from __future__ import annotations

import inspect

from fha_studio.gui.shape_figure import LETTERS, ShapeFigure
from fha_studio.logic.sizing.inertia import SHAPES


def test_every_shape_has_a_figure_with_a_letter_for_each_dimension(qtbot):
    assert set(LETTERS) == set(SHAPES)
    figure = ShapeFigure()
    qtbot.addWidget(figure)
    figure.resize(400, 130)
    for name, function in SHAPES.items():
        dimensions = [p for p in inspect.signature(function).parameters if p != "density_kg_m3"]
        assert set(LETTERS[name]) == set(dimensions), name
        assert hasattr(figure, f"_draw_{name}"), name
        figure.set_shape(name)
        image = figure.grab().toImage()  # paints the figure: every shape draws without error
        assert not image.isNull()


def test_the_sizing_form_uses_the_figures_letters(make_window, qtbot):
    window = make_window()
    page = window.show_page("sizing")
    page.shape_combo.setCurrentIndex(page.shape_combo.findData("isosceles_triangle_pillar"))
    labels = [page.dims_form.itemAt(i, page.dims_form.ItemRole.LabelRole).widget().text()
              for i in range(page.dims_form.rowCount())]
    assert labels == ["A — length:", "B — base:", "C — height:"]
    assert page.shape_figure.shape == "isosceles_triangle_pillar"
