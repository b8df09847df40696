"""A run's tables from its pair table: the goal, summary, AHC, band and start tables and the
method comparisons, pure functions of the pairs (the engine reads them from the job files:
:mod:`homebench.evaluation.results`).

Every metric carries its 95 % goal-bootstrap interval in ``<metric>_lo`` and ``<metric>_hi``
(:mod:`homebench.analysis.statistics`: goals are resampled, a goal being (swept world,
goal_i, goal_j)); each table cell draws its resamples from a seed derived from the cell's
factors, so the tables are identical across runs and job counts.
"""

from __future__ import annotations

import functools
import itertools
import json
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from homebench.analysis.metrics import HomeField, ae_summary, ahc_by_distance, distance_bins
from homebench.analysis.return_ratio import catchment, configured_return_ratio
from homebench.analysis.statistics import (
    GoalResampler,
    Interval,
    ahc_interval,
    ahc_intervals,
    mean_interval,
    mean_intervals,
)
from homebench.config import AhcConfig, MetricsConfig
from homebench.data.synth.spec import STYLES
from homebench.geometry import Grid, Places, holed_grid, is_places, wrap_angle
from homebench.hashing import derived_seed

GROUP = ["condition", "method"]


#: The factors of a pair (every one a column, so tables can group by any), then its position.
#: ``style`` and ``seed`` are the swept world's (empty without a sweep);
#: ``current_database_key`` and ``goal_database_key`` say what the two databases hold (see
#: :class:`~homebench.evaluation.sources.Source`): pairs of two runs are the same pairs only
#: when these are.
LEADING = [
    "style",
    "seed",
    "condition",
    "current_database",
    "goal_database",
    "current_database_key",
    "goal_database_key",
    "method",
    "method_name",
    "goal_i",
    "goal_j",
    "current_i",
    "current_j",
]


#: The factors of a goal's job (the keys of the goal and return-ratio tables; the databases'
#: keys follow from the style, seed and condition).
GOAL_FACTORS = [c for c in LEADING[:-2] if not c.endswith("_database_key")]


#: The factors of a goal in the goal table (``goals.csv``), before its metrics.
GOAL_COLUMNS = ["style", "seed", "condition", "method", "goal_i", "goal_j"]


#: Columns of the per-start return-ratio outcomes (``rr_starts.csv``).
RR_START_COLUMNS = [
    *GOAL_FACTORS,
    "start_i",
    "start_j",
    "steps",
    "success",
    "path_length",
    "no_estimate",
]


def with_rotation_errors(pairs: pd.DataFrame) -> pd.DataFrame:
    """``pairs`` with ``rotation_truth`` (the true heading change from the goal's view to the
    current one, radians, ccw: the current view's heading minus the goal's) and
    ``rotation_error`` (|wrapped difference| of ``rotation_estimate`` and the truth, radians;
    NaN where the method reports no rotation)."""
    truth = wrap_angle(pairs["heading"].astype(float) - pairs["goal_heading"].astype(float))
    error = np.abs(wrap_angle(pairs["rotation_estimate"].astype(float) - truth))
    return pairs.assign(rotation_truth=truth, rotation_error=error)


def _grid_of(group: pd.DataFrame) -> Grid:
    """The grid of a goal's pairs (their job record's), posed places where it lists them."""
    return _grid_from(group["grid"].iloc[0])


@functools.lru_cache(maxsize=64)
def _grid_from(text: str) -> Grid:
    """The grid of a job record's ``grid`` JSON ``text`` (read once per run and grid): posed
    places, or a grid with the positions it misses (if any)."""
    spec = json.loads(text)
    if "places" in spec:
        return Places.of(spec["places"])
    missing = [(i, j) for i, j in spec.get("missing", ())]
    return holed_grid(tuple(spec["shape"]), spec["spacing"], tuple(spec["origin"]), missing)


def posed_rows(pairs: pd.DataFrame) -> pd.Series:
    """Per pair, whether its current database holds posed places, not a grid (bool, (n,))."""
    if "grid" not in pairs:
        return pd.Series(False, index=pairs.index)
    return pairs["grid"].map(_is_posed_spec).astype(bool)


def _is_posed_spec(spec: str) -> bool:
    return is_places(_grid_from(spec))


def goal_fields(
    pairs: pd.DataFrame,
) -> list[tuple[tuple[str | None, int | None, str, str, int, int], HomeField, bool]]:
    """One world-frame home field per (style, seed, condition, method, goal) and whether it
    covers the grid.

    A field covers the grid when every position but the goal has a pair (every position
    present, on a grid with holes: :mod:`~homebench.analysis.return_ratio` says how they are
    treated); return ratios of fields that do not are not comparable with the paper's and are
    reported as NaN.
    """
    fields = []
    for (style, seed, condition, method, gi, gj), group in pairs.groupby(
        ["style", "seed", "condition", "method", "goal_i", "goal_j"], sort=True, dropna=False
    ):
        key = (
            None if pd.isna(style) else str(style),
            None if pd.isna(seed) else int(seed),
            condition,
            method,
            int(gi),
            int(gj),
        )
        fields.append((key, *_field_of(group)))
    return fields


def _field_of(group: pd.DataFrame) -> tuple[HomeField, bool]:
    """The home field of one goal's pairs and whether it covers the grid (never, for posed
    places: they have no grid steps to take, so no return ratio or catchment)."""
    grid = _grid_of(group)
    angles = np.full(grid.shape, np.nan)
    estimates = group["estimate_world"].astype(float).to_numpy()
    angles[group["current_i"].to_numpy(), group["current_j"].to_numpy()] = estimates
    goal = (int(group["goal_i"].iloc[0]), int(group["goal_j"].iloc[0]))
    complete = not is_places(grid) and len(group) == grid.size - 1
    return HomeField(grid, goal, angles), complete


def goal_tables(pairs: pd.DataFrame, metrics: MetricsConfig) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Return ratio per condition, method and goal (the paper's Figure 10), the share of its
    walks that ended on a position without an estimate (``rr_no_estimate_share``: failures,
    or with ``metrics.return_ratio.no_estimate: arrived`` arrivals next to the goal) and the
    catchment; and the outcome of every return-ratio start (columns ``RR_START_COLUMNS``; path
    length in grid units), so that users can test the outcomes themselves.

    A goal whose field does not cover the grid has RR, its share and catchment NaN and no
    starts.
    """
    rows, outcomes = [], []
    for key, group in pairs.groupby(GOAL_FACTORS, sort=True, dropna=False):
        factors = dict(zip(GOAL_FACTORS, key, strict=True))
        factors["seed"] = None if pd.isna(factors["seed"]) else int(factors["seed"])
        factors["style"] = None if pd.isna(factors["style"]) else str(factors["style"])
        home_field, complete = _field_of(group)
        row = {name: factors[name] for name in GOAL_COLUMNS}
        row["rr"] = row["rr_no_estimate_share"] = math.nan
        if metrics.catchment:
            row["catchment"] = catchment(home_field).ratio if complete else math.nan
        if complete:
            result = configured_return_ratio(home_field, metrics.return_ratio)
            row["rr"] = result.rr
            row["rr_no_estimate_share"] = float(np.mean(result.no_estimate[result.started]))
            outcomes.append((factors, result.outcomes()))
        rows.append(row)
    columns = [*GOAL_COLUMNS, "rr", "rr_no_estimate_share",
               *(["catchment"] if metrics.catchment else [])]  # fmt: skip
    return pd.DataFrame(rows, columns=columns), _start_table(outcomes)


def _start_table(outcomes: list[tuple[dict[str, Any], dict[str, np.ndarray]]]) -> pd.DataFrame:
    """The ``rr_starts`` table from each goal's factors and per-start outcomes."""
    if not outcomes:
        return pd.DataFrame(columns=RR_START_COLUMNS)
    factors = pd.DataFrame([goal for goal, _ in outcomes])
    lengths = [len(starts["steps"]) for _, starts in outcomes]
    table = factors.iloc[np.repeat(np.arange(len(outcomes)), lengths)].reset_index(drop=True)
    for name in outcomes[0][1]:
        table[name] = np.concatenate([starts[name] for _, starts in outcomes])
    return table[RR_START_COLUMNS]


def world_codes(frame: pd.DataFrame) -> np.ndarray:
    """The swept world of each row, shape (n,) int: the seed plus 2**20 times the style's
    place in :data:`~homebench.data.synth.spec.STYLES` (plus one); -1 without a sweep."""
    seed = frame["seed"].astype("Float64").fillna(-1).to_numpy(dtype=np.int64)
    if "style" in frame.columns:
        style = frame["style"].map(lambda s: STYLES.index(s) + 1 if isinstance(s, str) else 0)
        seed = seed + (style.to_numpy(dtype=np.int64) << 20)
    return seed


def goal_labels(frame: pd.DataFrame) -> np.ndarray:
    """The goal of each row: (world, goal_i, goal_j), shape (n, 3) int; ``world`` from
    :func:`world_codes`."""
    return np.column_stack([world_codes(frame), frame["goal_i"], frame["goal_j"]]).astype(np.int64)


def cell_resampler(frame: pd.DataFrame, *cell: object) -> GoalResampler:
    """The goal bootstrap of a table cell's rows, seeded by the cell's factors ``cell``."""
    factors = [None if pd.isna(value) else value for value in cell]
    return GoalResampler(goal_labels(frame), seed=derived_seed("goal-bootstrap", *factors))


def _bounds(name: str, interval: Interval) -> dict[str, float]:
    """``name``, ``name_lo``, ``name_hi``: a metric's columns."""
    return {name: interval.estimate, f"{name}_lo": interval.lo, f"{name}_hi": interval.hi}


def band_table(pairs: pd.DataFrame, metrics: MetricsConfig, by: list[str] = GROUP) -> pd.DataFrame:
    """The headline metrics per distance band (``metrics.band_edges_m``: from 0 to the first
    edge, between edges, beyond the last) for each ``by``: the factors, ``band`` (its range
    as text), ``low_m``, ``high_m`` (inf for the last), ``pairs`` and ``n_goals`` in it, then
    with bounds ``no_estimate_share``, ``mean_ae_deg``, ``ahc``, ``ahc_missing90`` (as in
    :func:`summary_table`), ``rotation_error_deg`` and ``rotation_flip_share``. The direction
    columns are NaN for a method that gives no home direction; the resamples are the
    summary's (seeded by the cell)."""
    cfg = metrics.ahc
    edges = [0.0, *metrics.band_edges_m, math.inf]
    rows = []
    for key, group in pairs.groupby(by, sort=True, dropna=False):
        ae = group["ae"].to_numpy(dtype=float)
        distance = group["distance_m"].to_numpy(dtype=float)
        masks = np.stack(
            [(distance >= lo) & (distance < hi) for lo, hi in itertools.pairwise(edges)]
        )
        resampler = cell_resampler(group, *key)
        share = mean_intervals(np.isnan(ae), resampler, masks)
        mean_ae = mean_intervals(ae, resampler, masks)
        ahc = ahc_intervals(ae, resampler, cfg.missing, masks, definition=cfg.definition)
        ahc90 = ahc_intervals(ae, resampler, "orthogonal", masks, definition=cfg.definition)
        errors = group["rotation_error"].to_numpy(dtype=float)
        rotation = mean_intervals(errors, resampler, masks)
        flips = mean_intervals(flipped(errors), resampler, masks)
        directs = gives_directions(group).all()
        for k, (lo, hi) in enumerate(itertools.pairwise(edges)):
            row = {
                **dict(zip(by, key, strict=True)),
                "band": f"{lo:g}-{hi:g} m" if math.isfinite(hi) else f"from {lo:g} m",
                "low_m": lo,
                "high_m": hi,
                "pairs": share[k].n_pairs,
                "n_goals": share[k].n_goals,
                **_bounds("no_estimate_share", share[k]),
                **_bounds("mean_ae_deg", mean_ae[k].transformed(np.degrees)),
                **_bounds("ahc", ahc[k]),
                **_bounds("ahc_missing90", ahc90[k]),
                **_bounds("rotation_error_deg", rotation[k].transformed(np.degrees)),
                **_bounds("rotation_flip_share", flips[k]),
            }
            if not directs:
                row |= {name: math.nan for name in DIRECTION_COLUMNS if name in row}
            rows.append(row)
    return pd.DataFrame(rows)


def ahc_table(pairs: pd.DataFrame, metrics: MetricsConfig, by: list[str] = GROUP) -> pd.DataFrame:
    """AHC per distance bin for each ``by`` (condition and method, with "style" first when a
    run sweeps styles; the paper's Figure 9).

    The columns of :func:`~homebench.analysis.metrics.ahc_by_distance`, then per bin the
    goals with a pair in it (``n_goals``), the AHC's bounds, the share without an estimate and
    the AHC with a missing estimate as 90 deg, each with bounds (resamples shared by the bins).
    """
    cfg = metrics.ahc
    bins = np.arange(cfg.bin_start_cm, cfg.bin_stop_cm + cfg.bin_step_cm / 2, cfg.bin_step_cm)
    frames = []
    for key, group in pairs.groupby(by, sort=True):
        ae = group["ae"].to_numpy(dtype=float)
        distance = group["distance_m"].to_numpy(dtype=float)
        table = ahc_by_distance(ae, distance, bins, cfg.missing, cfg.definition)
        resampler = cell_resampler(group, *key)
        masks = distance_bins(distance, bins)[1]
        table = pd.concat([table, _bin_uncertainty(ae, resampler, masks, cfg)], axis=1)
        for name, value in reversed(list(zip(by, key, strict=True))):
            table.insert(0, name, value)
        frames.append(table)
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()


def _bin_uncertainty(
    ae: np.ndarray, resampler: GoalResampler, masks: np.ndarray, cfg: AhcConfig
) -> pd.DataFrame:
    """The uncertainty columns of :func:`ahc_table`, a row per distance bin (``masks``:
    (n_bins, n_pairs) bool)."""
    share = mean_intervals(np.isnan(ae), resampler, masks)
    ahc = ahc_intervals(ae, resampler, cfg.missing, masks, definition=cfg.definition)
    missing90 = ahc_intervals(ae, resampler, "orthogonal", masks, definition=cfg.definition)
    return pd.DataFrame(
        {
            "n_goals": share[k].n_goals,
            "ahc_lo": ahc[k].lo,
            "ahc_hi": ahc[k].hi,
            **_bounds("no_estimate_share", share[k]),
            **_bounds("ahc_missing90", missing90[k]),
        }
        for k in range(len(masks))
    )


def summary_table(
    pairs: pd.DataFrame, goals: pd.DataFrame, metrics: MetricsConfig, by: list[str] = GROUP
) -> pd.DataFrame:
    """Headline per ``by`` (method x condition; with "seed" first, per world seed too).

    Columns: the factors, ``pairs``, ``n_goals``, then each metric with its bounds
    (``_lo``, ``_hi``): ``no_estimate_share``, ``mean_ae_deg`` (pairs with an estimate),
    ``median_ae_deg`` (no bounds), ``rotation_error_deg`` (mean over the pairs with a
    rotation estimate; NaN for methods that report none), ``ahc`` (missing estimates as
    configured, by default left out as in the paper), ``ahc_missing90`` (a missing estimate
    counts as 90 deg), both by the configured definition, ``rr`` (mean over the goals whose
    field covers the grid), ``catchment`` if configured; times.
    """
    cfg = metrics.ahc
    rows = []
    for key, group in pairs.groupby(by, sort=True, dropna=False):
        factors = dict(zip(by, key, strict=True))
        mask = np.ones(len(goals), dtype=bool)
        for name, value in factors.items():
            column = goals[name]
            mask &= column.isna().to_numpy() if pd.isna(value) else (column == value).to_numpy()
        per_goal = goals[mask]
        resampler = cell_resampler(group, *factors.values())
        by_goal = cell_resampler(per_goal, *factors.values())
        ae = group["ae"].to_numpy(dtype=float)
        describe_ms = pd.concat([group["describe_ms"], group["goal_describe_ms"]])
        row = {
            **factors,
            "pairs": len(group),
            "n_goals": resampler.n_goals,
            **_bounds("no_estimate_share", mean_interval(np.isnan(ae), resampler)),
            **_bounds("mean_ae_deg", mean_interval(ae, resampler).transformed(np.degrees)),
            "median_ae_deg": ae_summary(ae)["median_deg"],
            **_rotation_bounds(group, resampler),
            **_bounds("ahc", ahc_interval(ae, resampler, cfg.missing, definition=cfg.definition)),
            **_bounds(
                "ahc_missing90",
                ahc_interval(ae, resampler, "orthogonal", definition=cfg.definition),
            ),
            **_bounds("rr", mean_interval(per_goal["rr"], by_goal)),
            "describe_ms": describe_ms.mean(),
            "home_ms": group["home_ms"].mean(),
        }
        if metrics.catchment:
            row |= _bounds("catchment", mean_interval(per_goal["catchment"], by_goal))
        if not gives_directions(group).all():
            row |= {name: math.nan for name in DIRECTION_COLUMNS if name in row}
        rows.append(row)
    return pd.DataFrame(rows)


#: Summary columns of the home direction, n/a (NaN) for a method that gives none.
DIRECTION_COLUMNS = [
    f"{metric}{bound}"
    for metric in ("no_estimate_share", "mean_ae_deg", "ahc", "ahc_missing90", "rr", "catchment")
    for bound in ("", "_lo", "_hi")
] + ["median_ae_deg"]


def gives_directions(pairs: pd.DataFrame) -> pd.Series:
    """Per pair, whether its method gives home directions (a pair table without the column,
    made by hand, is taken to)."""
    if "gives_direction" not in pairs:
        return pd.Series(True, index=pairs.index)
    return pairs["gives_direction"].astype(bool)


def _rotation_bounds(group: pd.DataFrame, resampler: GoalResampler) -> dict[str, float]:
    """``rotation_error_deg`` (the mean over the pairs with a rotation estimate, in degrees)
    and ``rotation_flip_share`` (the share of those off by more than :data:`FLIP_DEG`, a view
    taken for its opposite), with their bounds; nothing for a pair table without rotation
    errors (not built by :func:`load_pairs`)."""
    if "rotation_error" not in group:
        return {}
    errors = group["rotation_error"].to_numpy(dtype=float)
    error = mean_interval(errors, resampler).transformed(np.degrees)
    flips = mean_interval(flipped(errors), resampler)
    return _bounds("rotation_error_deg", error) | _bounds("rotation_flip_share", flips)


#: A rotation estimate off by more than this (degrees) is a flip: the view taken for its
#: opposite, as the visual compass does far from the goal.
FLIP_DEG = 150.0


def flipped(rotation_error: np.ndarray) -> np.ndarray:
    """1.0 where a rotation error (radians) exceeds :data:`FLIP_DEG`, 0.0 where not, NaN
    where there is no rotation estimate; shape of ``rotation_error``."""
    return np.where(np.isnan(rotation_error), np.nan, rotation_error > np.radians(FLIP_DEG)).astype(
        float
    )


@dataclass(frozen=True)
class RunTables:
    """The tables of a run; ``summary_by_seed`` is empty unless the run swept world seeds;
    ``rr_starts``: the outcome of every return-ratio start."""

    pairs: pd.DataFrame
    summary: pd.DataFrame
    goals: pd.DataFrame
    ahc: pd.DataFrame
    missing_jobs: tuple[str, ...]
    summary_by_seed: pd.DataFrame = field(default_factory=pd.DataFrame)
    rr_starts: pd.DataFrame = field(default_factory=pd.DataFrame)
    metrics: MetricsConfig = field(default_factory=MetricsConfig)
    bands: pd.DataFrame = field(default_factory=pd.DataFrame)

    @functools.cached_property
    def comparisons(self) -> pd.DataFrame:
        """:func:`method_comparisons` of these tables, worked out once: the tables, the printed
        summary and the report all show them. Read it, do not change it."""
        return method_comparisons(self)


def run_tables(
    pairs: pd.DataFrame, missing_jobs: tuple[str, ...], metrics: MetricsConfig
) -> RunTables:
    """Every table of a run from its pair table (:data:`LEADING` and the rows' columns;
    ``missing_jobs``: the jobs without a result, for the record)."""
    if pairs.empty:
        empty = pd.DataFrame()
        return RunTables(empty, empty, empty, empty, missing_jobs, metrics=metrics)
    answered = pairs[pairs["error"].isna()]  # failed pairs: no metric, only n_failed
    directed = answered[gives_directions(answered)]  # rotation-only methods: no field, no AHC
    goals, rr_starts = goal_tables(directed, metrics)
    by = (["style"] if pairs["style"].notna().any() else []) + GROUP
    swept = pairs["seed"].nunique(dropna=False) > 1
    by_seed = [*by[:-2], "seed", *GROUP]
    return RunTables(
        pairs,
        with_failures(summary_table(answered, goals, metrics, by), pairs, by),
        goals,
        ahc_table(directed, metrics, by),
        missing_jobs,
        with_failures(summary_table(answered, goals, metrics, by_seed), pairs, by_seed)
        if swept
        else pd.DataFrame(),
        rr_starts,
        metrics,
        band_table(answered, metrics, by),
    )


def with_failures(summary: pd.DataFrame, pairs: pd.DataFrame, by: list[str]) -> pd.DataFrame:
    """``summary`` with ``n_failed`` after ``pairs``: the pairs whose method raised (they are
    in no metric, not even as "no estimate"; a goal with one has no RR, its field has a hole)."""
    counts = pairs["error"].notna().groupby([pairs[c] for c in by], dropna=False).sum()
    failed = counts.rename("n_failed").reset_index()
    merged = failed.merge(summary, on=by, how="left") if len(summary) else failed.assign(pairs=0)
    merged["pairs"] = merged["pairs"].fillna(0).astype(int)
    columns = [c for c in merged.columns if c != "n_failed"]
    columns.insert(columns.index("pairs") + 1, "n_failed")
    return merged[columns]


def method_comparisons(tables: RunTables) -> pd.DataFrame:
    """Every two methods of the run compared per condition
    (:func:`~homebench.analysis.comparisons.comparison_table`, its columns); per style when
    the run sweeps styles (a ``style`` column first; Holm within each style)."""
    from homebench.analysis.comparisons import comparison_table  # that module imports this

    pairs, starts = tables.pairs, tables.rr_starts
    definition = tables.metrics.ahc.definition
    if pairs.empty or not pairs["style"].notna().any():
        return comparison_table(pairs, starts, definition=definition)
    frames = [
        comparison_table(group, starts[starts["style"] == style], definition=definition).assign(
            style=style
        )
        for style, group in pairs.groupby("style", sort=True)
    ]
    table = pd.concat(frames, ignore_index=True)
    return table[["style", *table.columns[:-1]]]
