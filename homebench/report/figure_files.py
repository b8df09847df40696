"""Figures drawn by forked processes while the report goes on with the next figure.

Each figure is drawn four times: laid out, written as PNG, PDF and SVG (the PDF report's page
takes the PDF file as it is); most of a report's time. Where the system has ``fork``,
:class:`FigureFiles` forks once the report process has built a figure: the child, a copy of the
report process holding the figure, lays it out, writes its three files and (when asked) its
captioned page as a one-page PDF, and ends, while the report process builds the next figure; at
most ``workers`` children at a time. The child draws the very figure the report process would
have drawn, so the files are the same bytes. Without ``fork`` (or with ``workers`` 0) the same
work is done in turn. :func:`assemble_pdf` joins the pages into the report.
"""

from __future__ import annotations

import os
import sys
import traceback
from collections.abc import Callable, Sequence
from datetime import datetime
from functools import partial
from pathlib import Path
from types import TracebackType
from typing import IO

# the SVG backend is imported here, once, rather than by every forked child at its first SVG
import matplotlib.backends.backend_svg  # noqa: F401
from matplotlib.figure import Figure
from pypdf import PdfReader, PdfWriter

from homebench.report.captions import write_figure_page
from homebench.report.style import figure_paths, save_figure


def default_workers() -> int:
    """Children drawing figures at once: one per core this process may use."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


def draw_figure(fig: Figure, stem_path: Path, page: tuple[Path, str] | None = None) -> None:
    """Write ``fig``'s files (:func:`~homebench.report.style.save_figure`), then, with
    ``page = (path, caption)``, its PDF with ``caption`` below it as a one-page A4 PDF at
    ``path`` (:func:`~homebench.report.captions.write_figure_page`)."""
    _, pdf, _ = save_figure(fig, stem_path)
    if page is not None:
        path, caption = page
        width, height = fig.get_size_inches()
        write_figure_page(pdf, (float(width), float(height)), caption, path)


class FigureFiles:
    """Draws figures (:func:`draw_figure`) and other drawings, in forked children where
    possible; a context manager whose exit waits for every child and raises RuntimeError
    naming the drawings that failed."""

    def __init__(self, workers: int | None = None):
        self.workers = default_workers() if workers is None else workers
        self.forks = self.workers > 0 and hasattr(os, "fork")
        self.running: dict[int, str] = {}
        self.failed: list[str] = []

    def __enter__(self) -> FigureFiles:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        while self.running:
            self._reap()
        if self.failed and kind is None:
            raise RuntimeError(f"report drawings failed: {', '.join(self.failed)} (see above)")

    def save(
        self, fig: Figure, stem_path: Path, page: tuple[Path, str] | None = None
    ) -> list[Path]:
        """Draw ``fig`` as :func:`draw_figure` does (now, or in a child that ends before the
        context does); the paths of the figure's files."""
        self.run(Path(stem_path).name, partial(draw_figure, fig, stem_path, page))
        return figure_paths(stem_path)

    def run(self, name: str, work: Callable[[], object]) -> None:
        """Call ``work`` (a drawing named ``name`` in errors) now, or in a child."""
        if not self.forks:
            work()
            return
        while len(self.running) >= self.workers:
            self._reap()
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:  # the child: draw, then end without the parent's clean-up
            code = 0
            try:
                work()
            except BaseException:  # noqa: BLE001  (reported, and the parent fails the report)
                traceback.print_exc()
                code = 1
            finally:
                sys.stderr.flush()
                os._exit(code)
        self.running[pid] = name

    def _reap(self) -> None:
        """Wait for a child to end; note its figure if it failed."""
        pid, status = os.wait()
        name = self.running.pop(pid, None)
        if name is not None and os.waitstatus_to_exitcode(status) != 0:
            self.failed.append(name)


def pdf_date(moment: datetime) -> str:
    """A PDF date string (``D:YYYYMMDDHHmmSS`` and the UTC offset) of ``moment``."""
    text = moment.strftime("D:%Y%m%d%H%M%S")
    offset = moment.utcoffset()
    if offset is None:
        return text
    minutes = int(offset.total_seconds()) // 60
    if minutes == 0:
        return text + "Z"
    sign = "+" if minutes > 0 else "-"
    return text + f"{sign}{abs(minutes) // 60:02d}'{abs(minutes) % 60:02d}'"


def assemble_pdf(
    parts: Sequence[Path | IO[bytes]],
    out: IO[bytes],
    metadata: dict[str, str | datetime],
    outline: dict[int, str] | None = None,
) -> None:
    """Write the pages of the PDF documents ``parts`` (paths or binary streams), in order, as
    one PDF to ``out`` with ``metadata`` (keys as in the document information dictionary
    without the slash; dates as datetimes) and a bookmark to the first page of each part
    ``outline`` names (part index -> title). The same parts give the same bytes."""
    writer = PdfWriter()
    for k, part in enumerate(parts):
        first = len(writer.pages)
        for page in PdfReader(part).pages:
            writer.add_page(page)
        if outline and k in outline:
            writer.add_outline_item(title=outline[k], page_number=first)
    writer.add_metadata(
        {
            f"/{key}": pdf_date(value) if isinstance(value, datetime) else value
            for key, value in metadata.items()
        }
    )
    writer.write(out)
