"""Figures drawn by forked children: the files the report process would write, and the
captioned pages joined into the report's PDF."""

from __future__ import annotations

import io
from datetime import UTC, datetime, timedelta, timezone
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pypdf
import pytest
from matplotlib.figure import Figure

from homebench.report.figure_files import FigureFiles, assemble_pdf, pdf_date
from homebench.report.style import PAGE_SIZE, report_style


def _figure() -> Figure:
    fig, ax = plt.subplots(layout="constrained")
    ax.plot(np.arange(10), np.arange(10) ** 2, label="squares")
    ax.set_title("a figure")
    ax.legend()
    return fig


@pytest.mark.parametrize("workers", [1, 2])
def test_forked_files_are_the_files_written_in_turn(tmp_path: Path, workers: int) -> None:
    written = {}
    with report_style():
        for name, count in (("turn", 0), ("forked", workers)):
            (tmp_path / name).mkdir()
            with FigureFiles(count) as files:
                paths = [files.save(_figure(), tmp_path / name / f"f{k}") for k in range(3)]
            written[name] = [path for group in paths for path in group]
    assert [p.name for p in written["turn"]] == [p.name for p in written["forked"]]
    assert [p.suffix for p in written["turn"][:3]] == [".png", ".pdf", ".svg"]
    for turn, forked in zip(written["turn"], written["forked"], strict=True):
        assert turn.read_bytes() == forked.read_bytes(), turn.name


def test_a_figure_whose_files_fail_fails_the_report(tmp_path: Path) -> None:
    (tmp_path / "taken").write_text("a file where the figures' folder should be")
    failing = pytest.raises(RuntimeError, match="report drawings failed: f0")
    with failing, FigureFiles(2) as files:
        files.save(_figure(), tmp_path / "taken" / "f0")
        files.save(_figure(), tmp_path / "f1")
    assert (tmp_path / "f1.svg").is_file()


def test_captioned_pages_are_joined_in_order_with_the_reports_dates(tmp_path: Path) -> None:
    """Pages drawn by children (a caption below each figure) join into one PDF: in the given
    order, with the metadata given, and the same bytes every time."""
    pages = [tmp_path / f"page{k}.pdf" for k in range(3)]
    with report_style(), FigureFiles(2) as files:
        for k, page in enumerate(pages):
            files.save(_figure(), tmp_path / f"f{k}", (page, f"Figure {k + 1}. Caption {k}."))
    started = datetime(2026, 11, 22, 8, 30, tzinfo=UTC)
    joined = []
    for order in (pages, pages):
        out = io.BytesIO()
        assemble_pdf(order, out, {"Title": "a report", "CreationDate": started})
        joined.append(out.getvalue())
    assert joined[0] == joined[1]
    reader = pypdf.PdfReader(io.BytesIO(joined[0]))
    texts = [" ".join(p.extract_text().split()) for p in reader.pages]
    for k, text in enumerate(texts):
        assert f"Figure {k + 1}. Caption {k}." in text and "a figure" in text
    assert reader.metadata.title == "a report"
    assert reader.metadata.creation_date == started
    (single,) = pypdf.PdfReader(pages[0]).pages  # the figure file on an A4 page
    size = (float(single.mediabox.width) / 72, float(single.mediabox.height) / 72)
    assert size == pytest.approx(PAGE_SIZE)


def test_pdf_dates_carry_the_offset() -> None:
    moment = datetime(2026, 1, 2, 3, 4, 5)
    assert pdf_date(moment) == "D:20260102030405"
    assert pdf_date(moment.replace(tzinfo=UTC)) == "D:20260102030405Z"
    east = timezone(timedelta(hours=5, minutes=30))
    assert pdf_date(moment.replace(tzinfo=east)) == "D:20260102030405+05'30'"


def _embedded_fonts(path: Path) -> list[set[str]]:
    """The table tags of every TrueType font embedded in the PDF at ``path``."""
    from fontTools.ttLib import TTFont

    fonts = []
    for page in pypdf.PdfReader(path).pages:
        for font in page["/Resources"]["/Font"].values():
            descendant = font.get_object()["/DescendantFonts"][0].get_object()
            data = descendant["/FontDescriptor"]["/FontFile2"].get_object().get_data()
            fonts.append(set(TTFont(io.BytesIO(data)).keys()))
    return fonts


def test_report_pdfs_embed_fonts_without_the_layout_tables_no_viewer_reads(
    tmp_path: Path,
) -> None:
    """Inside report_style the embedded subsets leave out GSUB, GPOS and GDEF (if fontTools
    renames the default this relies on, this test says so); outside it they keep them, and the
    text reads the same."""
    with report_style(), FigureFiles(0) as files:
        files.save(_figure(), tmp_path / "lean")
    with plt.rc_context({"pdf.fonttype": 42}):  # the report's font type, outside the block
        _figure().savefig(tmp_path / "plain.pdf")
    lean, plain = _embedded_fonts(tmp_path / "lean.pdf"), _embedded_fonts(tmp_path / "plain.pdf")
    assert lean and all(not font & {"GSUB", "GPOS", "GDEF"} for font in lean)
    assert {"GSUB", "GPOS"} <= plain[0]  # DejaVu Sans has them: the test can fail
    assert all({"glyf", "cmap", "hmtx"} <= font for font in lean)
    texts = [pypdf.PdfReader(tmp_path / f"{name}.pdf").pages[0].extract_text()
             for name in ("lean", "plain")]  # fmt: skip
    assert texts[0] == texts[1]
