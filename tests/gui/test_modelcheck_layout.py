"""The model check page at the small screens a field laptop has: the summary box never shows a
line cut in half, and an empty plot says there is nothing yet instead of a 0 to 1 range."""

from __future__ import annotations

import pytest
from PySide6.QtWidgets import QSplitter

from fha_studio.gui.pages.modelcheck.page import EMPTY_PLOT

LONG_SUMMARY = "\n".join(
    f"Finding {n}: a line long enough to wrap on a small screen, " * (1 + n % 3) for n in range(30))


def _cut_lines(edit) -> list[tuple[float, float]]:
    """The (top, bottom) of every laid-out line that starts inside the viewport and ends below it."""
    height = edit.viewport().height()
    offset = edit.contentOffset()
    block, cut = edit.firstVisibleBlock(), []
    while block.isValid():
        top = edit.blockBoundingGeometry(block).translated(offset).top()
        if top >= height:
            break
        layout = block.layout()
        for i in range(layout.lineCount()):
            line = layout.lineAt(i)
            line_top, line_bottom = top + line.y(), top + line.y() + line.height()
            if 0 <= line_top < height and line_bottom > height + 0.5:
                cut.append((line_top, line_bottom))
        block = block.next()
    return cut


@pytest.mark.parametrize("size", [(1366, 768), (1280, 720)])
def test_the_summary_shows_whole_lines_whatever_its_height(make_window, qtbot, size):
    window = make_window()
    window.resize(*size)
    page = window.show_page("modelcheck")
    qtbot.waitExposed(page)
    page.summary.setPlainText(LONG_SUMMARY)
    split = page.summary.parentWidget()
    assert isinstance(split, QSplitter)
    total = sum(split.sizes())
    for summary_px in (97, 130, 151, 177, 203):  # the window's own split, and a technician's drags
        split.setSizes([summary_px, total - summary_px])
        qtbot.waitUntil(lambda px=summary_px: abs(page.summary.height() - px) <= 1, timeout=5000)
        assert page.summary.viewport().height() >= page.summary.line_height()
        assert _cut_lines(page.summary) == [], f"summary {summary_px} px high at {size}"
        page.summary.verticalScrollBar().setValue(7)  # scrolled: still whole lines
        assert _cut_lines(page.summary) == []
        page.summary.verticalScrollBar().setValue(0)


def test_empty_plots_say_nothing_is_there_yet(make_window, qtbot):
    window = make_window()
    page = window.show_page("modelcheck")
    qtbot.waitExposed(page)
    for plot in (page.torque_plot, page.residual_plot, page.where_plot, page.resim_torque_plot,
                 page.resim_pos_plot):
        assert plot.empty_note is not None and plot.empty_note.toPlainText() == EMPTY_PLOT
        for side in ("left", "bottom"):
            assert not plot.getPlotItem().getAxis(side).style["showValues"]  # no 0 to 1 on show
    assert page.gap_plots == {} and page.gap_empty.text() == EMPTY_PLOT


def _nothing_on_show(page) -> bool:
    plots = (page.torque_plot, page.residual_plot, page.where_plot, page.resim_torque_plot,
             page.resim_pos_plot)
    return (all(p.empty_note is not None and not p.getPlotItem().listDataItems() for p in plots)
            and page.gap_plots == {} and not page.gap_empty.isHidden()
            and page.effects_table.rowCount() == 0 and page.where_channel.count() == 0
            and page.findings.toPlainText() == "" and page.result is None
            and not page.save_report_button.isEnabled())


def test_a_new_recording_or_a_failed_run_takes_the_old_result_off_show(make_window, qtbot, friction_file,
                                                                         tmp_path):
    # the old curves beside "Not run yet" (or a failure) would be read as the new recording's
    window = make_window()
    page = window.show_page("modelcheck")
    window.session.state.set_load_inertia(1.5)
    page.load_recording(friction_file)
    with qtbot.waitSignal(page.sigFinished, timeout=60000):
        page.run()
    assert not _nothing_on_show(page)  # the result is drawn
    assert page.torque_plot.getPlotItem().listDataItems() and page.gap_plots

    page.load_recording(friction_file)  # a new recording (the same file again: still not run)
    assert page.summary.toPlainText().startswith("Not run yet")
    assert _nothing_on_show(page)
    assert page.torque_plot.getPlotItem().titleLabel.text == page.torque_plot.default_words[0]

    with qtbot.waitSignal(page.sigFinished, timeout=60000):
        page.run()
    short = tmp_path / "short.csv"  # reads, but is too short to check
    short.write_text("# format: fha-recording/1\n# actuator: FHA-25C-50-US250\n# load_inertia_kgm2: 1.5\n"
                     "t,pos,current\n"
                     + "".join(f"{n / 1000:.3f},{n * 0.01:.2f},0.{n % 7}\n" for n in range(50)),
                     encoding="utf-8")
    page.load_recording(short)
    with qtbot.waitSignal(page.sigFailed, timeout=60000):
        page.run()
    assert page.summary.toPlainText().startswith("Cannot run the model check")
    assert _nothing_on_show(page)
