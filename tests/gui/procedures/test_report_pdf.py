"""The report printed to PDF by Qt holds what was checked (read back with pdftotext when there)."""

from __future__ import annotations

import shutil
import subprocess

import pytest

from fha_studio.gui.pages.procedures.report_pdf import write_report
from fha_studio.logic.procedures import ProcedureRun, ProcedureSession, load_procedure
from fha_studio.logic.procedures.context import build_context
from fha_studio.logic.procedures.report import build_report
from tests.procedures.walk import walk

CODE = "FHA-32C-100-US250-B"


def test_report_prints_to_pdf(qapp, tmp_path):
    context = build_context(CODE)
    session = ProcedureSession(actuator_code=CODE, operator="T. Trainee", site="Hall 2")
    session.driver = {"model": "HA-655-4-200", "adjusted_for": CODE, "version": "sim"}
    from PySide6.QtGui import QColor, QImage

    image = QImage(400, 300, QImage.Format.Format_RGB32)
    image.fill(QColor(200, 30, 30))
    image.save(str(tmp_path / "plot.png"))
    session.add_plot("A plot", tmp_path / "plot.png")
    for procedure_id in ("receiving-inspection", "installation"):
        walk(ProcedureRun(session, load_procedure(procedure_id, context), autosave=False))
    html_path, pdf_path = write_report(
        build_report(session, context), tmp_path / "r.html", tmp_path / "r.pdf"
    )
    data = pdf_path.read_bytes()
    assert data.startswith(b"%PDF") and len(data) > 5000
    assert b"/Image" in data  # the plot is in the PDF, not only named
    assert "16-M6 depth: 12" in html_path.read_text()
    if shutil.which("pdftotext") is None:
        pytest.skip("pdftotext is not installed: the PDF text is not checked")
    text = subprocess.run(
        ["pdftotext", "-layout", str(pdf_path), "-"], capture_output=True, text=True, check=True
    ).stdout
    for wanted in (
        "Commissioning report",
        CODE,
        "HA-655-4-200",
        "Receiving inspection",
        "16-M6",
        "T. Trainee",
        "Not signed",
    ):
        assert wanted in text, wanted


def test_page_breaks_never_cut_a_row_and_every_page_is_numbered(qapp, tmp_path):
    """A long checklist spans pages: each break falls between table rows (Qt's own printing cuts
    rows in half), and every page says 'page k of n'."""
    from PySide6.QtGui import QTextDocument

    from fha_studio.gui.pages.procedures.report_pdf import _unbreakable_spans, page_breaks

    context = build_context(CODE)
    session = ProcedureSession(actuator_code=CODE, operator="T. Trainee", site="Hall 2")
    for procedure_id in ("receiving-inspection", "installation", "wiring"):
        walk(ProcedureRun(session, load_procedure(procedure_id, context), autosave=False))
    report = build_report(session, context)
    from fha_studio.logic.procedures.report import render_html

    document = QTextDocument()
    document.setDocumentMargin(0)
    document.setHtml(render_html(report))
    document.setTextWidth(1062)  # A4 at 150 dpi less 15 mm margins
    spans = _unbreakable_spans(document)
    tops = page_breaks(spans, document.size().height(), 1500)
    assert len(tops) >= 2
    for top in tops[1:]:
        cut = [s for s in spans if s.top < top < s.bottom]
        assert not cut, f"a break at {top:.0f} px cuts {cut}"
    assert page_breaks(spans, 100.0, 1500) == [0.0]

    _, pdf_path = write_report(report, tmp_path / "r.html", tmp_path / "r.pdf")
    assert not list(tmp_path.glob(".*partial"))
    if shutil.which("pdftotext") is None:
        pytest.skip("pdftotext is not installed: the page footers are not checked")
    pages = subprocess.run(
        ["pdftotext", "-layout", str(pdf_path), "-"], capture_output=True, text=True, check=True
    ).stdout.split("\f")
    pages = [p for p in pages if p.strip()]
    assert len(pages) >= 2
    for number, page in enumerate(pages, start=1):
        assert f"page {number} of {len(pages)}" in page
    assert "True" not in "".join(pages)  # yes/no, never a Python bool


def test_a_page_starts_where_the_document_asks_for_one():
    from fha_studio.gui.pages.procedures.report_pdf import _Span, page_breaks

    # a break asked for at 100 px and 2000 px; the pages between end when full
    assert page_breaks([], 3000.0, 1500.0, forced=[100.0, 2000.0]) == [0.0, 100.0, 1600.0, 2000.0]
    # a break asked for at the very top or beyond the end makes no empty page
    assert page_breaks([], 1000.0, 1500.0, forced=[0.0, 1200.0]) == [0.0]
    # a full page still never cuts a span
    assert page_breaks([_Span(1400.0, 1600.0)], 3000.0, 1500.0) == [0.0, 1400.0, 2900.0]


def test_a_report_aimed_at_a_folder_is_refused_before_anything_is_written(qapp, tmp_path):
    from fha_studio.fileio import FileProblem

    context = build_context(CODE)
    session = ProcedureSession(actuator_code=CODE, operator="T. Trainee", site="Hall 2")
    (tmp_path / "r.html").mkdir()  # the HTML's name is taken by a folder
    with pytest.raises(FileProblem, match=r"r\.html: is a directory"):
        write_report(build_report(session, context), tmp_path / "r.html", tmp_path / "r.pdf")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.html"]  # no PDF, no partial file


def test_a_report_that_cannot_be_written_is_refused_before_anything_is_written(qapp, tmp_path):
    """A device-like target (a FIFO stands for /dev/full) or a path under a file: refused with the
    file named, and neither the HTML nor the PDF nor a temporary file is left."""
    import os

    from fha_studio.fileio import FileProblem

    os.mkfifo(tmp_path / "device")
    (tmp_path / "afile").write_text("")
    report = build_report(ProcedureSession(actuator_code=CODE), build_context(CODE))
    for html, pdf, words in ((tmp_path / "r.html", tmp_path / "device", "not a regular file"),
                             (tmp_path / "r.html", tmp_path / "afile" / "r.pdf", "not a directory"),
                             (tmp_path / "device", tmp_path / "r.pdf", "not a regular file")):
        with pytest.raises(FileProblem, match=words):
            write_report(report, html, pdf)
        assert sorted(p.name for p in tmp_path.iterdir()) == ["afile", "device"]
