"""The figures of a grid run's report, in the order the documents show them.

First what a reader needs: the method x condition heat maps of AHC (where a method abstains,
beside it the AHC with a missing estimate as 90 deg and the share without an estimate), RR and
mean AE (with two or more conditions), AHC against distance and RR per goal of every condition
side by side (the paper's Figures 9 and 10), the time per call; then, as an appendix, the
per-goal figures of each condition: home-vector fields (Figure 7) and AE maps (Figure 8) of
``max_goals`` goals spread over the goal list. A run over more than
:data:`MAX_DETAILED_CONDITIONS` conditions (style x condition) writes its per-goal figures as
files only.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from homebench.analysis.tables import gives_directions, posed_rows
from homebench.config import ReturnRatioConfig
from homebench.report.grid.field_figures import AE_MAX_DEG, ae_figure, field_figure, grid_pages
from homebench.report.grid.figure_data import (
    condition_goals,
    goal_panels,
    image_describe_times,
    pick_goals,
)
from homebench.report.grid.heatmaps import (
    OVERVIEW_SECTION,
    heat_metrics,
    heatmap_columns,
    heatmap_figures,
)
from homebench.report.grid.metric_figures import (
    ConditionPanel,
    RRPanel,
    ahc_bins,
    ahc_figure,
    ahc_pages,
    ahc_range,
    rr_figure,
    rr_pages,
    timing_figure,
)
from homebench.report.host_load import load_note
from homebench.report.run_data import RunData
from homebench.report.style import MethodStyle, method_styles
from homebench.report.tables import (
    DEFAULT_RR,
    RR_NO_ESTIMATE_MEANINGS,
    ahc_header,
    few_goals_note,
    run_order,
)

#: Sections of the figures of all conditions side by side (AHC, RR), and of the time per call.
METRICS_SECTION = "All conditions"
TIMING_SECTION = "Time per call"
#: Start of the heading of a condition's per-goal figures (the appendix).
PER_GOAL_SECTION = "Appendix: per-goal figures"
#: A run with more conditions (style x condition) than this writes its per-goal figures as
#: files only, not into the documents.
MAX_DETAILED_CONDITIONS = 6

#: (file stem, section heading, caption, figure).
SectionFigure = tuple[str, str, str, Figure]


def _page_note(k: int, n: int) -> str:
    return f", part {k} of {n}" if n > 1 else ""


def run_styles(run: RunData) -> dict[str, MethodStyle]:
    """The look of each method label of the run, in the config's order (the drawing order)."""
    return method_styles(run_order(run).methods_of(run.tables.pairs["method"]))


def heatmap_count(run: RunData) -> int:
    """The columns (style x condition) of the run's heat maps."""
    return len(heatmap_columns(run.tables.summary, run.conditions))


def _shown_goals(run: RunData, max_goals: int | None) -> tuple[int, int]:
    """The most goals of a condition the appendix shows with ``max_goals`` (None: all), and
    the most goals of a condition."""
    counts = [len(condition_goals(run.tables.pairs, c)) for c in run.conditions]
    total = max(counts, default=0)
    return (total if max_goals is None else min(total, max_goals)), total


def figures_note(run: RunData, max_goals: int | None) -> str:
    """The title page's line on what the report's figures show."""
    shown, total = _shown_goals(run, max_goals)
    goals = "every goal" if shown == total else f"{shown} of {total} goals (--max-goals)"
    columns = heatmap_count(run)
    labels = [metric.label for metric in heat_metrics(run.tables.summary, run.metrics.ahc)]
    listed = f"{', '.join(labels[:-1])} and {labels[-1]}"
    heat = f"heat maps of {listed} (method x condition); " if columns > 1 else ""
    ahc = ahc_header("AHC", run.metrics.ahc)
    body = f"{heat}{ahc} against distance and RR per goal of every condition; time per call"
    per_goal = f"home-vector fields and AE maps of {goals} per condition"
    posed = _posed_note(run)
    if posed and posed_rows(run.tables.pairs).all():  # no grid: no per-goal figures
        return f"{body}{posed}"
    if columns > MAX_DETAILED_CONDITIONS:
        return (
            f"{body}; the {per_goal} are in the figures folder only ({columns} conditions, "
            f"more than {MAX_DETAILED_CONDITIONS}){posed}"
        )
    return f"{body}; appendix: {per_goal}{posed}"


def _posed_note(run: RunData) -> str:
    """The title page's words on the conditions over posed images (no grid), or ""."""
    pairs = run.tables.pairs
    posed = sorted(set(pairs.loc[posed_rows(pairs), "condition"]))
    if not posed:
        return ""
    return (
        f". Posed images, not a grid ({', '.join(posed)}): AE, AHC and distance bands only; "
        "RR, catchment, home-vector fields and AE maps are n/a (they need a grid)"
    )


def _per_goal_section(run: RunData, condition: str) -> str:
    return f"{PER_GOAL_SECTION}, {run.condition_title(condition)}"


def shown_sections(run: RunData) -> frozenset[str] | None:
    """The sections whose figures the documents show: all (None), or with more than
    MAX_DETAILED_CONDITIONS conditions those before the per-goal appendix."""
    if heatmap_count(run) <= MAX_DETAILED_CONDITIONS:
        return None
    return frozenset({OVERVIEW_SECTION, METRICS_SECTION, TIMING_SECTION})


def _goal_figures(
    run: RunData, condition: str, max_goals: int | None, styles: dict[str, MethodStyle]
) -> Iterator[tuple[str, str, Figure]]:
    """(file stem, caption, figure) of one condition: the home-vector fields (the paper's
    Figure 7) and AE maps (Figure 8) of ``max_goals`` goals (None: all), a few a figure."""
    where = run.condition_title(condition)
    pairs = run.tables.pairs[run.tables.pairs["condition"] == condition]
    pairs = pairs[~posed_rows(pairs)]  # posed images: no grid to draw a field or map on
    directed = gives_directions(pairs)
    undirected = [m for m in styles if m in set(pairs.loc[~directed, "method"])]
    pairs = pairs[directed]
    goals = condition_goals(pairs, condition)
    shown = pick_goals(goals, max_goals)
    note = "" if len(shown) == len(goals) else f" ({len(shown)} of {len(goals)} goals shown)"
    absent = f"Not drawn (no home direction): {', '.join(undirected)}. " if undirected else ""
    order = list(styles)
    panels = [(goal, goal_panels(pairs, run.metrics, condition, goal, order)) for goal in shown]
    chunks = grid_pages(panels)
    shows = [", ".join(goal.text for goal, _ in chunk) + note + _page_note(k, len(chunks))
             for k, chunk in enumerate(chunks, start=1)]  # fmt: skip
    for k, (chunk, listed) in enumerate(zip(chunks, shows, strict=True), start=1):
        caption = (
            f"Home-vector fields, {where}, goals {listed}. {absent}Arrows: estimated home "
            "direction from each current position, in the method's colour where the "
            "return-ratio trial from there succeeds, dark where it fails; red square: goal; x: "
            "no estimate."
        )
        yield f"{condition}_fields_{k}", caption, field_figure(chunk, styles)
    for k, (chunk, listed) in enumerate(zip(chunks, shows, strict=True), start=1):
        caption = (
            f"Angular error (AE) per current position, {where}, goals {listed}. {absent}Fixed "
            f"scale 0 to {AE_MAX_DEG:g} deg in every map (larger errors in the top colour); "
            "star: goal; hatched: no estimate."
        )
        yield f"{condition}_ae_{k}", caption, ae_figure(chunk)


def _styles_of(frame: pd.DataFrame) -> list[str]:
    """The swept styles of ``frame``'s rows, sorted; [""] without a sweep."""
    if "style" not in frame.columns or frame["style"].isna().all():
        return [""]
    return sorted(str(s) for s in frame["style"].dropna().unique())


def _of_style(frame: pd.DataFrame, style: str) -> pd.DataFrame:
    return frame[frame["style"] == style] if style else frame


def _metric_panels(run: RunData) -> tuple[list[ConditionPanel], list[RRPanel], list[str]]:
    """The AHC and RR panels of every condition (per swept style) in the config's order, and
    the long title of each."""
    tables = run.tables
    ahc_panels, rr_panels, titles = [], [], []
    for condition in run.conditions:
        ahc = tables.ahc[tables.ahc["condition"] == condition]
        goals = tables.goals[tables.goals["condition"] == condition]
        summary = tables.summary[tables.summary["condition"] == condition]
        for style in _styles_of(ahc):
            title = f"{condition} {style}".strip()
            ahc_panels.append(ConditionPanel(title, _of_style(ahc, style)))
            rr_panels.append(RRPanel(title, _of_style(goals, style), _of_style(summary, style)))
            titles.append(f"{run.condition_title(condition)}{f', {style}' if style else ''}")
    return ahc_panels, rr_panels, titles


def _lettered(chunks: Sequence[Sequence[object]], titles: Sequence[str]) -> Iterator[str]:
    """Per page of ``chunks``: its part note and its panels' ``titles`` lettered (a), (b)..."""
    start = 0
    for k, chunk in enumerate(chunks, start=1):
        page = titles[start : start + len(chunk)]
        start += len(chunk)
        listed = "; ".join(f"({chr(ord('a') + n)}) {t}" for n, t in enumerate(page))
        yield f"{_page_note(k, len(chunks))}: {listed}"


def _ahc_goal_counts(panels: Sequence[ConditionPanel], centres: np.ndarray) -> list[float]:
    """The goals each drawn AHC band rests on: per method and bin shown (``centres``, cm)
    that holds a pair."""
    rows = pd.concat([panel.rows for panel in panels], ignore_index=True)
    drawn = rows[(rows["bin"] != "all") & (rows["n"] > 0) & rows["centre_cm"].isin(centres)]
    return drawn["n_goals"].tolist() if "n_goals" in drawn else []


def _rr_goal_counts(panels: Sequence[RRPanel]) -> list[float]:
    """The goals each drawn mean-RR interval rests on: per panel and method, the goals with
    an RR."""
    return [n for panel in panels for n in panel.goals.groupby("method")["rr"].count()]


def _caption_note(n_goals: Sequence[float]) -> str:
    """A caption's sentence on intervals from few goals (:func:`~homebench.report.tables.
    few_goals_note`) after a space, or "" when it needs none."""
    note = few_goals_note(n_goals)
    return f" {note}" if note else ""


def _rr_walks(rr: ReturnRatioConfig) -> str:
    """The RR caption's words on what a goal's RR is: the success radius (grid units) and,
    when not the default, how a walk ending on a position without an estimate counts."""
    said = (
        f"the share of start positions whose walk reaches within {rr.success_radius:g} grid "
        "units of the goal"
    )
    if rr.no_estimate == DEFAULT_RR.no_estimate:
        return said
    return (
        f"{said} (a walk ending on a position without an estimate counts "
        f"{RR_NO_ESTIMATE_MEANINGS[rr.no_estimate]})"
    )


def _bins_note(centres: np.ndarray) -> str:
    """The caption's words on the distance bins shown (cm), or ""."""
    if not len(centres):
        return ""
    return f"; distance bins {centres[0]:g} to {centres[-1]:g} cm (up to the farthest pair's bin)"


def _metric_figures(
    run: RunData, styles: dict[str, MethodStyle]
) -> Iterator[tuple[str, str, Figure]]:
    """(file stem, caption, figure): AHC against distance (the paper's Figure 9) and RR per
    goal (Figure 10), every condition side by side, on one scale each."""
    ahc_panels, rr_panels, titles = _metric_panels(run)
    limits, centres = ahc_range(run.tables.ahc), ahc_bins(run.tables.ahc)
    chunks = ahc_pages(ahc_panels)
    label = ahc_header("AHC", run.metrics.ahc)
    for k, (chunk, panels) in enumerate(zip(chunks, _lettered(chunks, titles), strict=True)):
        caption = (
            f"{label} against the distance between current and goal position{panels}. Lines: "
            "AHC per distance bin; bands: 95 % goal-bootstrap CI; top axis: pairs per bin; AHC "
            f"axis {limits[0]:g} to {limits[1]:g} in every panel{_bins_note(centres)}."
            f"{_caption_note(_ahc_goal_counts(chunk, centres))}"
        )
        yield f"ahc_{k + 1}", caption, ahc_figure(chunk, styles, limits, label, centres)
    chunks, rr_walks = rr_pages(rr_panels), _rr_walks(run.metrics.return_ratio)
    for k, (chunk, panels) in enumerate(zip(chunks, _lettered(chunks, titles), strict=True)):
        caption = (
            f"Return ratio (RR) per goal, {rr_walks}{panels}. Right of the dotted line: each "
            "method's mean RR over the goals with its 95 % goal-bootstrap CI; n/a: the field "
            "does not cover the grid (or the images are posed, not on a grid), or the method "
            f"gives no home direction.{_caption_note(_rr_goal_counts(chunk))}"
        )
        yield f"rr_{k + 1}", caption, rr_figure(chunk, styles)


def grid_figures(run: RunData, max_goals: int | None) -> Iterator[SectionFigure]:
    """Every figure of a grid run's report in order: heat maps (two or more conditions), AHC
    and RR of all conditions, the time per call, then each condition's per-goal figures."""
    styles = run_styles(run)
    if heatmap_count(run) > 1:
        ordered = run_order(run).sort(run.tables.summary)
        seeds_pooled = run.tables.pairs["seed"].nunique(dropna=False) > 1
        yield from heatmap_figures(ordered, run.conditions, seeds_pooled, run.metrics.ahc)
    for stem, caption, fig in _metric_figures(run, styles):
        yield stem, METRICS_SECTION, caption, fig
    caption = (
        "Time per call, all conditions: describe per image, home per pair (log scale; box: "
        f"quartiles, line: median). {load_note(run.environment)}"
    )
    pairs = run.tables.pairs
    yield "timing", TIMING_SECTION, caption, timing_figure(image_describe_times(pairs), pairs,
                                                           styles)  # fmt: skip
    for condition in run.conditions:
        section = _per_goal_section(run, condition)
        for stem, caption, fig in _goal_figures(run, condition, max_goals, styles):
            yield stem, section, caption, fig
