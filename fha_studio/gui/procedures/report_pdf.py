"""The commissioning report as PDF, printed by Qt (QTextDocument + QPdfWriter): no other tools."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtCore import QMarginsF, QSizeF, QUrl
from PySide6.QtGui import QPageLayout, QPageSize, QPdfWriter, QTextDocument

from fha_studio.logic.procedures.report import CommissioningReport, render_html


def write_pdf(
    html: str, path: str | Path, title: str = "Commissioning report", base_dir: Path | None = None
) -> Path:
    """Print ``html`` to an A4 PDF at ``path``; images are found relative to ``base_dir``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    writer = QPdfWriter(str(path))
    writer.setTitle(title)
    writer.setCreator("FHA Studio")
    writer.setResolution(150)
    writer.setPageLayout(
        QPageLayout(
            QPageSize(QPageSize.PageSizeId.A4),
            QPageLayout.Orientation.Portrait,
            QMarginsF(15, 15, 15, 15),
            QPageLayout.Unit.Millimeter,
        )
    )
    document = QTextDocument()
    if base_dir is not None:
        document.setBaseUrl(QUrl.fromLocalFile(str(Path(base_dir).resolve()) + "/"))
    document.setHtml(html)
    rect = writer.pageLayout().paintRectPixels(writer.resolution())
    document.setPageSize(QSizeF(rect.width(), rect.height()))
    document.print_(writer)
    del writer  # the file is complete when the writer is gone
    return path


def write_report(
    report: CommissioningReport, html_path: str | Path, pdf_path: str | Path | None = None
) -> tuple[Path, Path | None]:
    """Write the report as HTML and (when ``pdf_path`` is given) as PDF; returns both paths."""
    html = render_html(report)
    html_path = Path(html_path)
    html_path.parent.mkdir(parents=True, exist_ok=True)
    html_path.write_text(html, encoding="utf-8")
    pdf = write_pdf(html, pdf_path, report.title, html_path.parent) if pdf_path is not None else None
    return html_path, pdf
