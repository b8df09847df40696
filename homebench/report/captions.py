"""Numbered captions below the figures of the PDF report.

A figure is laid out at its own size first (as its PNG shows it); then the layout is frozen,
the figure grows by a band at the bottom and everything it holds moves up by the band's
height, so axes, titles and legends keep their size and place relative to each other, and the
caption, wrapped to the figure's width, sits in the band: it cannot overlap the figure.
"""

from __future__ import annotations

import textwrap

from matplotlib.figure import Figure
from matplotlib.layout_engine import PlaceHolderLayoutEngine
from matplotlib.text import Text
from matplotlib.transforms import Bbox

#: Caption font size (points) and its average character width (inches; wraps the text).
CAPTION_FONT_SIZE = 9
CAPTION_CHAR_WIDTH = 0.07
#: Space left and right of the caption, and above and below it (inches).
CAPTION_MARGIN = 0.4
CAPTION_PAD = 0.12


def numbered(number: int, caption: str) -> str:
    """A caption with its figure number: "Figure 3. ..."."""
    return f"Figure {number}. {caption}"


def _moved(box: Bbox, height: float, band: float) -> Bbox:
    """``box`` (figure fractions of a figure ``height`` inches tall) on the figure grown by
    ``band`` inches at the bottom."""
    total = height + band
    return Bbox.from_extents(
        box.x0, (box.y0 * height + band) / total, box.x1, (box.y1 * height + band) / total
    )


def _freeze_and_grow(fig: Figure, band: float) -> None:
    """Lay ``fig`` out, stop its layout engine and grow it by ``band`` inches at the bottom,
    moving its axes, texts and legends up by as much (figures made of subfigures are not
    handled). A figure already laid out (its engine stopped: none, or the placeholder that
    ``set_layout_engine("none")`` leaves) is not drawn again."""
    if not isinstance(fig.get_layout_engine(), PlaceHolderLayoutEngine | None):
        fig.draw_without_rendering()
    width, height = fig.get_size_inches()
    axes = [(ax, ax.get_position(original=True).frozen()) for ax in fig.axes]
    to_figure = fig.transFigure.inverted()
    texts = [(t, t.get_position()) for t in fig.texts if t.get_transform() == fig.transFigure]
    legends = [(leg, leg.get_bbox_to_anchor().transformed(to_figure)) for leg in fig.legends]
    fig.set_layout_engine("none")
    fig.set_size_inches(width, height + band)
    for ax, box in axes:
        ax.set_position(_moved(box, height, band))
    for text, (x, y) in texts:
        text.set_position((x, (y * height + band) / (height + band)))
    for legend, box in legends:
        legend.set_bbox_to_anchor(_moved(box, height, band), transform=fig.transFigure)


def add_caption(fig: Figure, caption: str) -> Text:
    """Put ``caption`` below everything ``fig`` shows, wrapped to its width; the figure grows
    by the caption's height. Returns the caption's text artist."""
    width = fig.get_figwidth()
    chars = max(int((width - 2 * CAPTION_MARGIN) / CAPTION_CHAR_WIDTH), 20)
    wrapped = "\n".join(textwrap.wrap(caption, chars, break_on_hyphens=False))
    style = {"ha": "left", "va": "bottom", "fontsize": CAPTION_FONT_SIZE, "in_layout": False}
    probe = fig.text(0.0, 0.0, wrapped, **style)
    band = probe.get_window_extent(fig.canvas.get_renderer()).height / fig.dpi + 2 * CAPTION_PAD
    probe.remove()
    _freeze_and_grow(fig, band)
    return fig.text(CAPTION_MARGIN / width, CAPTION_PAD / fig.get_figheight(), wrapped, **style)
