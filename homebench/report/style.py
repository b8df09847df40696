"""One look for every report figure: method colours and markers, page sizes, PNG output.

Colours and markers belong to a method *label* and never depend on which figure draws it: the
well-known methods are pinned, every other label takes the next free palette entry in sorted
label order, so the same set of labels always gets the same styles.
"""

from __future__ import annotations

import itertools
import math
import textwrap
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from homebench.fileio import atomic_write  # noqa: E402

#: A4 landscape, inches.
PAGE_SIZE = (11.69, 8.27)
#: Single-plot figures (inches): half a page, so labels stay readable.
PLOT_SIZE = (9.0, 5.0)
#: Resolution of the PNG files (the PDF is vector).
PNG_DPI = 110
#: Width of a figure title's character, inches (titles wrap to the figure's width).
TITLE_CHAR_WIDTH = 0.095
#: Most panels in one row of a page.
MAX_COLUMNS = 4

#: Colour-blind-safe palette (Okabe-Ito, then Tol's muted), in assignment order; no colour
#: near FAILED_COLOUR (Tol's indigo was dropped: its arrows looked like failed ones).
PALETTE = (
    "#0072B2",
    "#D55E00",
    "#009E73",
    "#CC79A7",
    "#E69F00",
    "#56B4E9",
    "#DDCC77",
    "#882255",
    "#117733",
    "#999933",
    "#AA4499",
    "#44AA99",
)
MARKERS = ("o", "s", "^", "D", "v", "P", "X", "<", ">", "h")
LINESTYLES = ("-", "--", "-.", ":")

#: Labels whose look is fixed whatever else a run holds (palette index, marker index).
PINNED = {"sift": (0, 0), "warping": (1, 1), "min-warping": (2, 2), "klt-sector": (3, 3)}

#: Colours of marks that are not methods (never in the palette).
GOAL_COLOUR = "#E41A1C"
FAILED_COLOUR = "#222222"
MISSING_COLOUR = "#BBBBBB"
OUTBOUND_COLOUR = "#777777"

RC_PARAMS = {
    "font.size": 9,
    "axes.titlesize": 10,
    "axes.labelsize": 9,
    "figure.titlesize": 12,
    "legend.fontsize": 8,
    "xtick.labelsize": 8,
    "ytick.labelsize": 8,
    # TrueType fonts keep the PDF's text extractable (Type 3 glyphs are not).
    "pdf.fonttype": 42,
}


@dataclass(frozen=True)
class MethodStyle:
    colour: str
    marker: str
    linestyle: str


def method_styles(labels: Iterable[str]) -> dict[str, MethodStyle]:
    """Style of each label: pinned names first, the others in sorted order on the free slots."""
    styles = {}
    taken = {slot for slot, _ in PINNED.values()}
    free = (k for k in itertools.count() if k % len(PALETTE) not in taken)
    for label in sorted(set(labels)):
        if label in PINNED:
            colour, marker = PINNED[label]
            styles[label] = MethodStyle(PALETTE[colour], MARKERS[marker], LINESTYLES[0])
            continue
        k = next(free)
        styles[label] = MethodStyle(
            PALETTE[k % len(PALETTE)],
            MARKERS[k % len(MARKERS)],
            LINESTYLES[(k // len(PALETTE)) % len(LINESTYLES)],
        )
    return styles


@contextmanager
def report_style() -> Iterator[None]:
    """The rcParams of every report figure, for the duration of a block."""
    with plt.rc_context(RC_PARAMS):
        yield


def new_figure(size: tuple[float, float] = PAGE_SIZE) -> Figure:
    """A figure of the report's page size, laid out by the constrained layout engine."""
    return plt.figure(figsize=size, layout="constrained")


def panel_axes(fig: Figure, n: int) -> list[Axes]:
    """``n`` axes side by side in rows of at most MAX_COLUMNS, sharing x and y."""
    columns = min(n, MAX_COLUMNS)
    rows = math.ceil(n / columns)
    axes = fig.subplots(rows, columns, sharex=True, sharey=True, squeeze=False).ravel()
    for ax in axes[n:]:
        ax.set_visible(False)
    return list(axes[:n])


def outer_panel(k: int, n: int) -> tuple[bool, bool]:
    """Whether panel ``k`` of :func:`panel_axes` is in the first column, and has none below."""
    columns = min(n, MAX_COLUMNS)
    return k % columns == 0, k + columns >= n


def set_title(fig: Figure, title: str) -> None:
    """The figure's title, wrapped to its width."""
    chars = int(fig.get_figwidth() / TITLE_CHAR_WIDTH)
    fig.suptitle("\n".join(textwrap.wrap(title, chars)))


def legend_right(ax: Axes, title: str | None = None) -> None:
    """The legend of ``ax`` beside it, right of the data, top aligned."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, title=title,
              frameon=False)  # fmt: skip


def save_png(fig: Figure, path: Path) -> Path:
    """Write ``fig`` as a PNG atomically; the same figure always gives the same bytes."""
    with atomic_write(Path(path)) as f:
        fig.savefig(f, format="png", dpi=PNG_DPI, metadata={"Software": None})
    return Path(path)
