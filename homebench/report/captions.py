"""The PDF report's figure pages: a figure on an A4 page, as large as the page allows, its
numbered caption below it.

A figure file is sized for a journal column (3.5 or 7.2 in wide, :mod:`~homebench.report.style`):
on a page of its own size, among the report's A4 text pages, it would fill a third of one. A
figure page takes the figure's own PDF file as it is (vector, not drawn again), scales it to the
page's width or height, whichever binds, by at most :data:`MAX_SCALE` (a single-column figure
does not become a poster), in the orientation (landscape, like the text pages, or portrait for a
tall figure) that shows it larger, and sets the caption below it, wrapped to the page's width.
"""

from __future__ import annotations

import io
import textwrap
from dataclasses import dataclass
from pathlib import Path

from matplotlib.figure import Figure
from pypdf import PdfReader, PdfWriter
from pypdf.generic import DictionaryObject, FloatObject, NameObject

from homebench.report.style import PAGE_SIZE, SAVE_ARGS

#: Caption font size (points), its average character width (inches; wraps the text) and the
#: height of a caption line (inches).
CAPTION_FONT_SIZE = 9
CAPTION_CHAR_WIDTH = 0.07
CAPTION_LINE_HEIGHT = CAPTION_FONT_SIZE * 1.25 / 72
#: Page margin and the space between a figure and its caption (inches).
PAGE_MARGIN = 0.45
CAPTION_GAP = 0.15
#: A figure is shown at most this much larger than its file (fonts of 7-8 pt become 10-12 pt).
MAX_SCALE = 1.5
#: The figure's name among the page's resources.
FIGURE_NAME = "/HomebenchFigure"
#: Page sizes tried, in order of preference when a figure shows equally large on both.
ORIENTATIONS = (PAGE_SIZE, PAGE_SIZE[::-1])


def numbered(number: int, caption: str) -> str:
    """A caption with its figure number: "Figure 3. ..."."""
    return f"Figure {number}. {caption}"


@dataclass(frozen=True)
class FigurePlacement:
    """Where a figure page puts a figure (inches from the page's lower left corner): the page
    ``size``, the figure's ``scale``, its lower left corner ``origin``, the caption's wrapped
    ``lines`` and the top of the caption ``caption_top``."""

    size: tuple[float, float]
    scale: float
    origin: tuple[float, float]
    lines: tuple[str, ...]
    caption_top: float

    def figure_box(self, figure: tuple[float, float]) -> tuple[float, float, float, float]:
        """The figure's (left, bottom, right, top) on the page, inches."""
        x, y = self.origin
        return x, y, x + figure[0] * self.scale, y + figure[1] * self.scale

    @property
    def caption_bottom(self) -> float:
        return self.caption_top - len(self.lines) * CAPTION_LINE_HEIGHT


def _placement(
    page: tuple[float, float], figure: tuple[float, float], caption: str
) -> FigurePlacement:
    """``figure`` (width, height, inches) on ``page`` as large as it fits above ``caption``,
    at most MAX_SCALE, centred across and at the top of the text area."""
    width, height = page
    text_width = width - 2 * PAGE_MARGIN
    chars = max(int(text_width / CAPTION_CHAR_WIDTH), 20)
    lines = tuple(textwrap.wrap(caption, chars, break_on_hyphens=False))
    room = height - 2 * PAGE_MARGIN - CAPTION_GAP - len(lines) * CAPTION_LINE_HEIGHT
    scale = min(MAX_SCALE, text_width / figure[0], room / figure[1])
    top = height - PAGE_MARGIN
    origin = ((width - figure[0] * scale) / 2, top - figure[1] * scale)
    return FigurePlacement(page, scale, origin, lines, origin[1] - CAPTION_GAP)


def place_figure(figure: tuple[float, float], caption: str) -> FigurePlacement:
    """The placement of a figure of ``figure`` inches with ``caption`` on the A4 page
    (landscape or portrait) that shows it larger; landscape when both show it alike."""
    placements = [_placement(page, figure, caption) for page in ORIENTATIONS]
    return max(placements, key=lambda p: round(p.scale, 3))  # max keeps the first of a tie


def _caption_pdf(placement: FigurePlacement) -> bytes:
    """A page of ``placement.size`` holding only the caption, as PDF."""
    fig = Figure(figsize=placement.size)
    width, height = placement.size
    fig.text(PAGE_MARGIN / width, placement.caption_top / height, "\n".join(placement.lines),
             ha="left", va="top", fontsize=CAPTION_FONT_SIZE, linespacing=1.25)  # fmt: skip
    buffer = io.BytesIO()
    fig.savefig(buffer, format="pdf", **SAVE_ARGS["pdf"])
    return buffer.getvalue()


def write_figure_page(
    figure_pdf: Path, figure: tuple[float, float], caption: str, out: Path
) -> None:
    """Write the figure page of the one-page PDF ``figure_pdf`` (a figure of ``figure``
    inches) with ``caption`` below it to ``out`` (no dates: the report sets them when it joins
    the pages).

    The figure's content stream becomes a form XObject, drawn on the caption page scaled into
    place: its bytes are copied as they are, not parsed (pypdf's page merging parses them,
    which takes seconds for a figure of many arrows), and it keeps its own resources (fonts,
    hatches), whose names may repeat the caption page's."""
    placement = place_figure(figure, caption)
    writer = PdfWriter(clone_from=io.BytesIO(_caption_pdf(placement)))
    drawing = PdfReader(figure_pdf).pages[0]
    form = drawing.raw_get("/Contents").clone(writer)
    form.get_object().update({
        NameObject("/Type"): NameObject("/XObject"),
        NameObject("/Subtype"): NameObject("/Form"),
        NameObject("/BBox"): drawing.mediabox,
        NameObject("/Resources"): drawing["/Resources"].clone(writer),
    })  # fmt: skip
    page = writer.pages[0]
    resources = page["/Resources"].get_object()
    xobjects = resources.setdefault(NameObject("/XObject"), DictionaryObject()).get_object()
    xobjects[NameObject(FIGURE_NAME)] = form
    x, y = placement.origin
    matrix = [FloatObject(v) for v in (placement.scale, 0, 0, placement.scale, 72 * x, 72 * y)]
    content = page.get_contents()
    content.operations += [([], b"q"), (matrix, b"cm"), ([NameObject(FIGURE_NAME)], b"Do"),
                           ([], b"Q")]  # fmt: skip
    page.replace_contents(content)
    with open(out, "wb") as f:
        writer.write(f)
