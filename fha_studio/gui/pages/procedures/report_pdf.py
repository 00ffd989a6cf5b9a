"""The commissioning report as PDF, printed by Qt (QTextDocument + QPdfWriter): no other tools.

Qt's own pagination (``QTextDocument.print_``) cuts table rows and text lines across pages and
prints no page numbers. Here the document is laid out once as one long page, the page breaks are
chosen so that no table row, text line or heading with its first line is cut, and each page is
drawn with a footer that says which report and which page it is.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from PySide6.QtCore import QMarginsF, QPointF, QRectF, Qt, QUrl
from PySide6.QtGui import (
    QAbstractTextDocumentLayout,
    QColor,
    QFont,
    QPageLayout,
    QPageSize,
    QPainter,
    QPdfWriter,
    QTextBlock,
    QTextDocument,
    QTextFormat,
    QTextFrame,
    QTextTable,
)

from fha_studio import fileio
from fha_studio.logic.procedures.report import CommissioningReport, render_html

#: Dots per inch of the PDF's layout: text stays vector; images are placed at this resolution.
PDF_RESOLUTION_DPI = 150
#: Page margins [mm] (A4 portrait).
PAGE_MARGIN_MM = 15.0
#: Height kept at the bottom of each page for the footer [mm].
FOOTER_MM = 8.0


@dataclass(frozen=True)
class _Span:
    """A vertical stretch of the laid-out document that must not be cut by a page break [px]."""

    top: float
    bottom: float


def _mm_to_px(mm: float) -> float:
    return mm / 25.4 * PDF_RESOLUTION_DPI


def _block_spans(block: QTextBlock, layout: QAbstractTextDocumentLayout) -> list[_Span]:
    """One span per text line of ``block`` (a line holding an image is as tall as the image)."""
    rect = layout.blockBoundingRect(block)
    lines = block.layout()
    spans = []
    for i in range(lines.lineCount()):
        line = lines.lineAt(i)
        top = rect.top() + line.y()
        spans.append(_Span(top, top + line.height()))
    if not spans and rect.height() > 0:
        spans.append(_Span(rect.top(), rect.bottom()))
    return spans


def _table_row_spans(table: QTextTable, layout: QAbstractTextDocumentLayout) -> list[_Span]:
    """One span per table row: from the top of its highest cell to the bottom of its lowest."""
    spans = []
    for row in range(table.rows()):
        top, bottom = float("inf"), float("-inf")
        for column in range(table.columns()):
            cell = table.cellAt(row, column)
            block = cell.firstCursorPosition().block()
            last = cell.lastCursorPosition().block()
            while block.isValid():
                rect = layout.blockBoundingRect(block)
                top, bottom = min(top, rect.top()), max(bottom, rect.bottom())
                if block == last:
                    break
                block = block.next()
        if top < bottom:
            spans.append(_Span(top, bottom))
    return spans


def _unbreakable_spans(document: QTextDocument) -> list[_Span]:
    """Every table row, every text line, and every heading together with the line after it."""
    layout = document.documentLayout()
    spans: list[_Span] = []
    tables_done: set[int] = set()
    block = document.begin()
    while block.isValid():
        table = _table_of(block)
        if table is not None:
            key = table.firstPosition()
            if key not in tables_done:
                tables_done.add(key)
                spans.extend(_table_row_spans(table, layout))
        else:
            lines = _block_spans(block, layout)
            spans.extend(lines)
            if block.blockFormat().headingLevel() > 0 and lines:
                # a heading is never the last thing on a page: keep it with what follows
                following = block.next()
                after = _block_spans(following, layout)[:1] if following.isValid() else []
                table = _table_of(following)
                if table is not None:
                    rows = _table_row_spans(table, layout)
                    after = rows[:2]
                if after:
                    spans.append(_Span(lines[0].top, after[-1].bottom))
        block = block.next()
    return spans


def _table_of(block: QTextBlock) -> QTextTable | None:
    frame: QTextFrame | None = block.document().frameAt(block.position()) if block.isValid() else None
    while frame is not None:
        if isinstance(frame, QTextTable):
            return frame
        frame = frame.parentFrame()
    return None


def forced_breaks(document: QTextDocument) -> list[float]:
    """Where the document asks for a new page (``page-break-before: always``) [px from the top]."""
    layout = document.documentLayout()
    tops = []
    block = document.begin()
    while block.isValid():
        if block.blockFormat().pageBreakPolicy() & QTextFormat.PageBreakFlag.PageBreak_AlwaysBefore:
            tops.append(layout.blockBoundingRect(block).top())
        block = block.next()
    return tops


def page_breaks(
    spans: list[_Span], total_height: float, page_height: float, forced: Sequence[float] = ()
) -> list[float]:
    """Top of each page [px]: a page ends where it is full, or earlier, at the top of the first
    span that the full page would cut, or where the document asks for a new page (``forced``).
    A span taller than a page is cut (nothing else can be done)."""
    tops = [0.0]
    top = 0.0
    wanted = sorted(forced)
    while True:
        end = top + page_height
        asked = [f for f in wanted if top + 1.0 < f < min(end, total_height)]
        if asked:
            end = asked[0]
        elif end >= total_height:
            break
        else:
            while True:  # moving the break up can land it inside another span (a heading's): again
                cut = [s.top for s in spans if s.top < end < s.bottom and s.top > top + 1.0]
                if not cut:
                    break
                end = min(cut)
        tops.append(end)
        top = end
    return tops


def write_pdf(
    html: str, path: str | Path, title: str = "Commissioning report", base_dir: Path | None = None
) -> Path:
    """Print ``html`` to an A4 PDF at ``path`` with page numbers; no row or line is cut across
    pages. Images are found relative to ``base_dir``. The file appears only when complete; a
    target that cannot become a regular file raises :class:`fileio.FileProblem` before the work."""
    path = Path(path)
    if not os.path.lexists(path.parent):
        path.parent.mkdir(parents=True, exist_ok=True)
    fileio.check_output_path(path)  # a device or a path under a file: refused, never renamed over
    partial = path.with_name(f".{path.name}.partial")
    writer = QPdfWriter(str(partial))
    writer.setTitle(title)
    writer.setCreator("FHA Studio")
    writer.setResolution(PDF_RESOLUTION_DPI)
    writer.setPageLayout(
        QPageLayout(
            QPageSize(QPageSize.PageSizeId.A4),
            QPageLayout.Orientation.Portrait,
            QMarginsF(PAGE_MARGIN_MM, PAGE_MARGIN_MM, PAGE_MARGIN_MM, PAGE_MARGIN_MM),
            QPageLayout.Unit.Millimeter,
        )
    )
    document = QTextDocument()
    document.setDocumentMargin(0)
    if base_dir is not None:
        document.setBaseUrl(QUrl.fromLocalFile(str(Path(base_dir).resolve()) + "/"))
    document.setHtml(html)
    paint = writer.pageLayout().paintRectPixels(writer.resolution())
    document.setTextWidth(paint.width())  # one long page: the breaks are chosen below
    footer_px = _mm_to_px(FOOTER_MM)
    body_height = paint.height() - footer_px
    total = document.size().height()
    tops = page_breaks(_unbreakable_spans(document), total, body_height, forced_breaks(document))
    ends = [*tops[1:], total]
    painter = QPainter(writer)
    try:
        footer_font = QFont(document.defaultFont())
        footer_font.setPointSizeF(8)
        for number, (top, end) in enumerate(zip(tops, ends, strict=True), start=1):
            if number > 1:
                writer.newPage()
            painter.save()
            painter.translate(QPointF(0, -top))
            clip = QRectF(0, top, paint.width(), end - top)
            painter.setClipRect(clip)
            document.drawContents(painter, clip)
            painter.restore()
            painter.setFont(footer_font)
            painter.setPen(QColor(90, 90, 90))
            footer = QRectF(0, paint.height() - footer_px * 0.7, paint.width(), footer_px * 0.7)
            painter.drawLine(QPointF(0, footer.top()), QPointF(paint.width(), footer.top()))
            painter.drawText(footer, Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignVCenter, title)
            page = f"page {number} of {len(tops)}"
            painter.drawText(footer, Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter, page)
    finally:
        painter.end()
    del writer  # the file is complete when the writer is gone
    partial.replace(path)
    return path


def write_report(
    report: CommissioningReport, html_path: str | Path, pdf_path: str | Path | None = None,
    html_file: bytes | None = None,
) -> tuple[Path, Path | None]:
    """Write the report as HTML and (when ``pdf_path`` is given) as PDF; returns both paths.
    The HTML appears after the PDF is complete, each whole or not at all (:mod:`fha_studio.fileio`).
    ``html_file``: the HTML file's bytes when they are more than the rendering (its signature line)."""
    html = render_html(report)
    html_path = Path(html_path)
    if not os.path.lexists(html_path.parent):
        html_path.parent.mkdir(parents=True, exist_ok=True)
    for target in (html_path, pdf_path):
        if target is not None:
            fileio.check_output_path(target)  # before the work: a target that cannot be written
    pdf = write_pdf(html, pdf_path, report.title, html_path.parent) if pdf_path is not None else None
    fileio.write_bytes(html_path, html_file if html_file is not None else html.encode("utf-8"))
    return html_path, pdf
