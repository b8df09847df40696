"""Figure files written by forked processes while the report goes on with the next figure.

Writing a figure as PNG, PDF and SVG draws it three times, most of a report's time. Where the
system has ``fork``, :class:`FigureFiles` lays the figure out and forks: the child, a copy of the
report process holding the laid-out figure, writes the three files and ends, while the report
process captions the figure for the PDF and draws the next one; at most ``workers`` children at
a time. The child draws the very figure the report process would have saved, so the files are
the same bytes. Without ``fork`` (or with ``workers`` 0) the files are written in turn.
"""

from __future__ import annotations

import os
import sys
import traceback
from pathlib import Path
from types import TracebackType

from matplotlib.figure import Figure

from homebench.report.style import figure_paths, freeze_layout, save_figure


def default_workers() -> int:
    """Children writing figure files at once: one per core this process may use."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


class FigureFiles:
    """Writes figures' files, in forked children where possible; a context manager whose exit
    waits for every child and raises RuntimeError naming the figures whose files failed."""

    def __init__(self, workers: int | None = None):
        self.workers = default_workers() if workers is None else workers
        self.forks = self.workers > 0 and hasattr(os, "fork")
        self.running: dict[int, Path] = {}
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
            raise RuntimeError(f"figure files not written: {', '.join(self.failed)} (see above)")

    def save(self, fig: Figure, stem_path: Path) -> list[Path]:
        """Write ``fig`` as :func:`~homebench.report.style.save_figure` does (now, or in a child
        that ends before the context does); the files' paths. ``fig`` is laid out now, so that
        later changes to it (a caption) are not in the files."""
        if not self.forks:
            return save_figure(fig, stem_path)
        freeze_layout(fig)
        while len(self.running) >= self.workers:
            self._reap()
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:  # the child: write the files, then end without the parent's clean-up
            code = 0
            try:
                save_figure(fig, stem_path)
            except BaseException:  # noqa: BLE001  (reported, and the parent fails the report)
                traceback.print_exc()
                code = 1
            finally:
                sys.stderr.flush()
                os._exit(code)
        self.running[pid] = Path(stem_path)
        return figure_paths(stem_path)

    def _reap(self) -> None:
        """Wait for a child to end; note its figure if it failed."""
        pid, status = os.wait()
        stem = self.running.pop(pid, None)
        if stem is not None and os.waitstatus_to_exitcode(status) != 0:
            self.failed.append(stem.name)
