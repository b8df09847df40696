"""One look for every report figure: method colours and markers, figure sizes, file output.

A method's look belongs to its *label* alone, whatever else a run holds: the well-known labels
are pinned (:data:`PINNED`); any other label takes its colour, marker and line style each from
its own bytes of the label's SHA-256, so two labels rarely share all three. Every palette colour
is readable on white (WCAG contrast ratio at least 3).

Sizes follow journal columns: :data:`SINGLE_COLUMN` (3.5 in, 89 mm) and :data:`DOUBLE_COLUMN`
(7.2 in, 183 mm) wide, at most :data:`MAX_FIGURE_HEIGHT` tall. :func:`save_figure` writes a
figure as PNG (300 dpi), PDF and SVG, each byte-identical for the same figure.
"""

from __future__ import annotations

import hashlib
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
from matplotlib.font_manager import FontProperties  # noqa: E402

from homebench.fileio import atomic_write  # noqa: E402

#: A4 landscape, inches (text and table pages).
PAGE_SIZE = (11.69, 8.27)
#: Journal column widths and the tallest figure, inches.
SINGLE_COLUMN = 3.5
DOUBLE_COLUMN = 7.2
MAX_FIGURE_HEIGHT = 9.0
#: Resolution of the PNG files (PDF and SVG are vector).
PNG_DPI = 300
#: Width of a character of text, as a share of its font size (for wrapping panel titles).
CHAR_WIDTH_EM = 0.6
#: A legend entry's handle and spacing (inches), and the share of a figure's width a legend
#: may take.
LEGEND_HANDLE_WIDTH = 0.55
LEGEND_WIDTH_SHARE = 0.95
#: Margin around and between the panels of a figure, inches.
LAYOUT_PAD = 0.08
#: Most panels in one row of a page.
MAX_COLUMNS = 4

#: Colour-blind-aware palette (Okabe-Ito, then Tol's), each with contrast >= 3 on white; none
#: near FAILED_COLOUR or GOAL_COLOUR. The first five are the pinned labels'.
PALETTE = (
    "#0072B2",
    "#D55E00",
    "#009E73",
    "#CC79A7",
    "#882255",
    "#117733",
    "#AA4499",
    "#997700",
    "#8C564B",
    "#EE3377",
    "#009988",
    "#999933",
)
MARKERS = ("o", "s", "^", "D", "v", "P", "X", "<", ">", "h")
LINESTYLES = ("-", "--", "-.", ":")
#: Bar hatch of each line style (bars have no line): a second cue beside the colour.
HATCHES = {"-": "", "--": "////", "-.": "....", ":": "xxxx"}

#: Labels whose look is fixed: (palette index, marker, line style). Seed 001's P is sift,
#: W is warping, PN is sift without mismatch elimination.
PINNED = {
    "sift": (0, "o", "-"),
    "P": (0, "o", "-"),
    "warping": (1, "s", "-"),
    "W": (1, "s", "-"),
    "min-warping": (2, "^", "-"),
    "klt-sector": (3, "D", "-"),
    "PN": (4, "v", "--"),
}
#: Palette entries of the labels that are not pinned.
FREE_COLOURS = tuple(c for k, c in enumerate(PALETTE) if k not in {v[0] for v in PINNED.values()})

#: Colours of marks that are not methods (never in the palette).
GOAL_COLOUR = "#E41A1C"
FAILED_COLOUR = "#222222"
MISSING_COLOUR = "#BBBBBB"
OUTBOUND_COLOUR = "#777777"

RC_PARAMS = {
    "font.size": 8,
    "axes.titlesize": 8,
    "axes.labelsize": 8,
    "figure.titlesize": 12,
    "legend.fontsize": 7,
    "legend.title_fontsize": 7,
    "xtick.labelsize": 7,
    "ytick.labelsize": 7,
    # TrueType fonts keep the PDF's text extractable (Type 3 glyphs are not).
    "pdf.fonttype": 42,
    # SVG element ids from a fixed salt, not a random one: the same figure, the same bytes
    "svg.hashsalt": "homebench",
}
#: Tables of an embedded TrueType font that no PDF viewer reads: matplotlib places every glyph
#: itself, so OpenType glyph substitution, positioning and its definitions are dead weight.
PDF_UNUSED_FONT_TABLES = ("GSUB", "GPOS", "GDEF")
#: savefig arguments per format: no dates, no software version stamps.
SAVE_ARGS = {
    "png": {"dpi": PNG_DPI, "metadata": {"Software": None}},
    "pdf": {"metadata": {"CreationDate": None, "Producer": None}},
    "svg": {"metadata": {"Date": None, "Creator": None}},
}


@dataclass(frozen=True)
class MethodStyle:
    colour: str
    marker: str
    linestyle: str

    @property
    def hatch(self) -> str:
        """The bar hatch that stands for the line style."""
        return HATCHES[self.linestyle]


def method_style(label: str) -> MethodStyle:
    """The look of ``label``: pinned, or picked by the label's SHA-256 (bytes 0-3 the colour,
    4-7 the marker, 8-11 the line style)."""
    if label in PINNED:
        colour, marker, linestyle = PINNED[label]
        return MethodStyle(PALETTE[colour], marker, linestyle)
    digest = hashlib.sha256(label.encode("utf-8")).digest()
    colour, marker, line = (int.from_bytes(digest[k : k + 4], "big") for k in (0, 4, 8))
    return MethodStyle(
        FREE_COLOURS[colour % len(FREE_COLOURS)],
        MARKERS[marker % len(MARKERS)],
        LINESTYLES[line % len(LINESTYLES)],
    )


def method_styles(labels: Iterable[str]) -> dict[str, MethodStyle]:
    """:func:`method_style` of each label, once each in the order given: the figures draw and
    list methods in this dict's order (the report passes the config's)."""
    return {label: method_style(label) for label in dict.fromkeys(labels)}


def in_order(styles: dict[str, MethodStyle], labels: Iterable[str]) -> list[str]:
    """The labels of ``labels`` (repeats allowed) once each, in ``styles``' order."""
    present = set(labels)
    return [label for label in styles if label in present]


@contextmanager
def report_style() -> Iterator[None]:
    """The rcParams of every report figure, and lean PDF fonts (:func:`lean_pdf_fonts`), for
    the duration of a block."""
    with plt.rc_context(RC_PARAMS), lean_pdf_fonts():
        yield


@contextmanager
def lean_pdf_fonts() -> Iterator[None]:
    """Within the block, the TrueType subsets matplotlib embeds in PDF files leave out
    :data:`PDF_UNUSED_FONT_TABLES`.

    fontTools parses those tables for every subset: about 0.1 s of CPU per font and document,
    about a tenth of a report's time. matplotlib builds its fontTools options itself, and fontTools
    offers no public default for the tables to drop, so this extends the class default of
    ``fontTools.subset.Options`` and restores it afterwards; a fontTools without that default
    is left alone (the fonts then keep the tables, as before).
    """
    from fontTools import subset

    default = getattr(subset.Options, "_drop_tables_default", None)
    if not isinstance(default, list):
        yield
        return
    extra = [table for table in PDF_UNUSED_FONT_TABLES if table not in default]
    subset.Options._drop_tables_default = default + extra
    try:
        yield
    finally:
        subset.Options._drop_tables_default = default


def new_figure(size: tuple[float, float] = PAGE_SIZE) -> Figure:
    """A figure of ``size`` inches, laid out by the constrained layout engine with a margin
    of LAYOUT_PAD (its default one lets a multi-line panel title touch the edge)."""
    fig = plt.figure(figsize=size, layout="constrained")
    fig.get_layout_engine().set(h_pad=LAYOUT_PAD, w_pad=LAYOUT_PAD)
    return fig


def panel_axes(fig: Figure, n: int, columns: int = MAX_COLUMNS, sharex: bool = True) -> list[Axes]:
    """``n`` axes side by side in rows of at most ``columns``, sharing y (and x if ``sharex``)."""
    columns = min(n, columns)
    rows = math.ceil(n / columns)
    axes = fig.subplots(rows, columns, sharex=sharex, sharey=True, squeeze=False).ravel()
    for ax in axes[n:]:
        ax.set_visible(False)
    return list(axes[:n])


def outer_panel(k: int, n: int, columns: int = MAX_COLUMNS) -> tuple[bool, bool]:
    """Whether panel ``k`` of :func:`panel_axes` is in the first column, and has none below."""
    columns = min(n, columns)
    return k % columns == 0, k + columns >= n


def wrap_to(text: str, width_in: float, fontsize: float) -> str:
    """``text`` wrapped to lines of about ``width_in`` inches at ``fontsize`` points."""
    chars = max(8, int(72.0 * width_in / (CHAR_WIDTH_EM * fontsize)))
    return "\n".join(textwrap.fill(line, chars) for line in text.split("\n"))


def legend_right(ax: Axes, title: str | None = None) -> None:
    """The legend of ``ax`` beside it, right of the data, top aligned."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, title=title,
              frameon=False)  # fmt: skip


def font_points(key: str) -> float:
    """The size in points of the rcParams font size ``key`` ("xtick.labelsize", ...)."""
    return FontProperties(size=plt.rcParams[key]).get_size_in_points()


def legend_below(fig: Figure, handles: list, columns: int | None = None) -> None:
    """One legend for the whole figure, below its panels, in as many columns as fit the
    figure's width (at most ``columns``): entries as wide as the longest label."""
    size = font_points("legend.fontsize")
    longest = max((len(str(h.get_label())) for h in handles), default=1)
    entry = longest * CHAR_WIDTH_EM * size / 72.0 + LEGEND_HANDLE_WIDTH
    fit = max(1, int(LEGEND_WIDTH_SHARE * fig.get_figwidth() // entry))
    fig.legend(handles=handles, loc="outside lower center",
               ncols=min(fit, columns or len(handles)), frameon=False)  # fmt: skip


def save_figure(fig: Figure, stem_path: Path) -> list[Path]:
    """Write ``fig`` as ``<stem_path>.png`` (PNG_DPI), ``.pdf`` and ``.svg`` atomically.

    The PNG is drawn first, and its draw lays the figure out (constrained layout); the layout
    engine then stops (:func:`stop_layout`), so the PDF and SVG show the same picture (the
    constrained layout moves things a little at every draw) and no draw is spent on layout
    alone. No dates or random ids in the files: the same figure always gives the same bytes.
    """
    png, *vector = figure_paths(stem_path)
    written = [_save(fig, png, "png")]
    stop_layout(fig)
    return written + [_save(fig, path, path.suffix[1:]) for path in vector]


def stop_layout(fig: Figure) -> None:
    """Remove ``fig``'s layout engine, keeping its layout. (The "none" engine leaves a
    placeholder engine, which makes every savefig draw the figure once more before drawing
    it.)"""
    with plt.rc_context({"figure.autolayout": False, "figure.constrained_layout.use": False}):
        fig.set_layout_engine(None)


def figure_paths(stem_path: Path) -> list[Path]:
    """The files :func:`save_figure` writes for ``stem_path``, in order (PNG first)."""
    stem = Path(stem_path)
    return [stem.parent / f"{stem.name}.{suffix}" for suffix in SAVE_ARGS]


def _save(fig: Figure, path: Path, suffix: str) -> Path:
    with plt.rc_context({"svg.hashsalt": RC_PARAMS["svg.hashsalt"]}), atomic_write(path) as f:
        fig.savefig(f, format=suffix, **SAVE_ARGS[suffix])
    return path
