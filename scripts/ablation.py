"""The camera ablation: a base grid config run once per camera level, then every method's AHC
and seed 001's findings compared across the levels, paired by pair position.

    python scripts/ablation.py run --out DIR [--jobs N] [--only LEVEL]... [KEY=VALUE ...]
    python scripts/ablation.py analyse --out DIR --report reports/ablation

``run`` writes each level's config to ``DIR/configs/LEVEL.yaml`` (the base config,
``--config``, default ``configs/ablation.yaml``, with the level's camera from ``--levels``,
default ``configs/ablation/levels.yaml``, in every generated database, and output
``DIR/LEVEL``) and runs it as ``homebench run --no-report`` does (an interrupted run resumes;
``KEY=VALUE`` overrides apply to every level, e.g. ``'styles=[posters]' 'goals=[[1, 4]]'``).
It records the levels run in ``DIR`` so far (this run's, with ``--only`` those named, and
earlier runs') in ``DIR/levels.json`` and each level's wall and CPU time and load in
``DIR/timing.json``. ``analyse`` checks that the levels' runs differ in the camera alone and
hold the same pairs, then writes to ``--report`` (CSV and Markdown, the statistics of
:mod:`homebench.analysis.ablation`): ``ahc.md`` (each level's AHC and AHC90 per place),
``changes.md`` (each level against the reference), ``findings.md`` (seed 001's findings per
level) and ``finding_changes.md`` (their effects against the reference).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import resource
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import pandas as pd
import yaml
from pydantic import BaseModel, ConfigDict, model_validator

from homebench import api
from homebench.analysis.ablation import (
    contrast_changes,
    default_places,
    findings_by_level,
    level_changes,
    level_summary,
    sift_contrasts,
    stack_levels,
)
from homebench.analysis.findings import SiftRoles
from homebench.config import load_config
from homebench.data.synth.camera import CameraSpec
from homebench.yamlio import read_yaml

ROOT = Path(__file__).resolve().parents[1]
#: The roles of seed 001's methods in configs/ablation.yaml.
ROLES = SiftRoles(p="sift", pn="sift-pn", w="warping")
ALPHA = 0.05


class Levels(BaseModel):
    """The levels file: the ``reference`` level and each level's camera fields."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    reference: str
    levels: dict[str, dict[str, Any]]

    @model_validator(mode="after")
    def _known(self) -> Levels:
        if self.reference not in self.levels:
            raise ValueError(f"reference {self.reference!r} is not a level")
        for camera in self.levels.values():
            CameraSpec(**camera)
        return self


def level_config(base: dict[str, Any], camera: dict[str, Any], name: str, out: Path) -> dict:
    """``base`` (a grid config mapping) with ``camera`` merged into every database's
    generated world, named ``ablation-NAME`` and written to ``out/NAME``."""
    config = json.loads(json.dumps(base))
    for alias, database in config["databases"].items():
        if not isinstance(database, dict) or "world" not in database:
            raise SystemExit(f"databases.{alias}: the ablation needs generated worlds")
        world = database["world"]
        world["camera"] = {**world.get("camera", {}), **camera}
    return config | {"name": f"ablation-{name}", "output": str(out / name)}


def run(args: argparse.Namespace) -> None:
    levels = Levels(**read_yaml(args.levels, what="levels").data)
    base = read_yaml(args.config, what="config", overrides=args.overrides).data
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "configs").mkdir(exist_ok=True)
    unknown = sorted(set(args.only) - set(levels.levels))
    if unknown:
        raise SystemExit(f"--only {unknown}: not levels of {args.levels}")
    # the levels run in this folder: those of earlier runs (--only) and this one's
    record_path = args.out / "levels.json"
    earlier = json.loads(record_path.read_text())["levels"] if record_path.exists() else {}
    chosen = {
        name: camera
        for name, camera in levels.levels.items()
        if not args.only or name in args.only or name in earlier
    }
    record = {
        "reference": levels.reference,
        "levels": chosen,
        "config": str(args.config),
        "overrides": args.overrides,
        "roles": dataclasses.asdict(ROLES),
    }
    record_path.write_text(json.dumps(record, indent=1) + "\n")
    timing_path = args.out / "timing.json"
    timing = json.loads(timing_path.read_text()) if timing_path.exists() else {}
    for name, camera in levels.levels.items():
        if args.only and name not in args.only:
            continue
        path = args.out / "configs" / f"{name}.yaml"
        path.write_text(yaml.safe_dump(level_config(base, camera, name, args.out), sort_keys=False))
        load_config(path)  # a level the run would refuse stops here, naming its file and key
        print(f"level {name}: {camera or 'the default camera'} -> {args.out / name}", flush=True)
        timing[name] = _timed(lambda p=path: api.run(p, jobs=args.jobs, progress=False))
        timing_path.write_text(json.dumps(timing, indent=1) + "\n")
        print(f"level {name}: {timing[name]}", flush=True)


def _timed(work: Callable[[], object]) -> dict[str, float]:
    """Wall time, CPU time of this process and its children (s) and the load before and
    after ``work``."""
    load, wall = os.getloadavg()[0], time.monotonic()
    before = [resource.getrusage(who) for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)]
    work()
    after = [resource.getrusage(who) for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)]
    cpu = sum(
        a.ru_utime + a.ru_stime - b.ru_utime - b.ru_stime
        for a, b in zip(after, before, strict=True)
    )
    return {
        "wall_s": round(time.monotonic() - wall, 1),
        "cpu_s": round(cpu, 1),
        "load_before": load,
        "load_after": os.getloadavg()[0],
    }


# ---------------------------------------------------------------- analysis


def load_levels(out: Path) -> tuple[dict[str, Any], pd.DataFrame, pd.DataFrame]:
    """The levels record of ``out`` and its levels' pairs and return-ratio starts, stacked;
    SystemExit when the runs differ in more than the camera or in their pairs."""
    record = json.loads((out / "levels.json").read_text())
    names = list(record["levels"])
    _same_but_camera({name: out / name / "config.resolved.json" for name in names})
    found = {name: api.tables(out / name) for name in names}
    keys = ["style", "seed", "condition", "method", "goal_i", "goal_j", "current_i", "current_j"]
    counts = {name: len(t.pairs[keys].drop_duplicates()) for name, t in found.items()}
    if len(set(counts.values())) != 1 or any(t.missing_jobs for t in found.values()):
        raise SystemExit(
            f"the levels' runs hold different pairs (pairs per level: {counts}); "
            "finish every level's run first"
        )
    pairs = stack_levels({name: t.pairs for name, t in found.items()})
    starts = stack_levels({name: t.rr_starts for name, t in found.items()})
    return record, pairs, starts


def _same_but_camera(configs: dict[str, Path]) -> None:
    """SystemExit unless the resolved configs agree in everything but the worlds' cameras,
    the run's name and output."""
    seen = {}
    for name, path in configs.items():
        config = json.loads(path.read_text())
        for database in config["databases"].values():
            database["world"].pop("camera")
        seen[name] = {k: v for k, v in config.items() if k not in ("name", "output", "jobs")}
    first = next(iter(seen.values()))
    differ = [name for name, config in seen.items() if config != first]
    if differ:
        raise SystemExit(f"levels {differ} differ from the first in more than the camera")


def analyse(args: argparse.Namespace) -> None:
    record, pairs, starts = load_levels(args.out)
    reference = record["reference"]
    if reference not in record["levels"] or len(record["levels"]) < 2:
        raise SystemExit(f"{args.out}: run the reference level {reference!r} and another first")
    roles = SiftRoles(**record["roles"])
    places = default_places(
        [s for s in ("posters", "lab", "corridor", "outdoor", "arena") if s in set(pairs["style"])]
    )
    tables = {
        "ahc": level_summary(pairs, places),
        "changes": level_changes(pairs, places, reference),
        "finding_changes": contrast_changes(pairs, sift_contrasts(roles), places, reference),
        "findings": findings_by_level(pairs, starts, places, roles),
    }
    args.report.mkdir(parents=True, exist_ok=True)
    for name, table in tables.items():
        table.to_csv(args.report / f"{name}.csv", index=False, float_format="%.6g")
    markdown = {
        "ahc": _ahc_markdown(tables["ahc"]),
        "changes": _changes_markdown(tables["changes"], reference),
        "findings": _findings_markdown(tables["findings"]),
        "finding_changes": _finding_changes_markdown(tables["finding_changes"], reference),
    }
    for name, text in markdown.items():
        (args.report / f"{name}.md").write_text(text)
    print(f"tables in {args.report}: {', '.join(sorted(markdown))} (.md, .csv)")


def _cell(estimate: float, lo: float, hi: float, digits: int, sign: str = "") -> str:
    return f"{estimate:{sign}.{digits}f} [{lo:.{digits}f}, {hi:.{digits}f}]"


def _grid(table: pd.DataFrame, rows: str, cell: Callable[[pd.Series], str]) -> str:
    """A Markdown table: a row per ``rows`` value, a column per level (in the table's order),
    ``cell`` of each row."""
    text = table.assign(cell=table.apply(cell, axis=1), level=table["level"].astype(str))
    wide = text.pivot(index=rows, columns="level", values="cell")
    return wide[list(dict.fromkeys(text["level"]))].fillna("").to_markdown() + "\n"


def _sections(table: pd.DataFrame, by: Sequence[str]) -> list[tuple[str, pd.DataFrame]]:
    """The table's groups by ``by`` with a title each (none for an empty table)."""
    if table.empty:
        return []
    return [(", ".join(map(str, key)), group) for key, group in table.groupby(list(by), sort=False)]


def _ahc_markdown(summary: pd.DataFrame) -> str:
    parts = [
        "# AHC per level: estimate [95 % goal-bootstrap interval]\n",
        "AHC: a pair without an estimate left out (seed 001); AHC90: counted as 90 deg.\n",
    ]
    for metric in ("ahc", "ahc90"):
        for title, group in _sections(summary, ["place", "condition"]):
            parts.append(f"\n## {metric.upper()}, {title} ({group['n_goals'].max()} goals)\n\n")
            parts.append(
                _grid(
                    group, "method", lambda r, m=metric: _cell(r[m], r[f"{m}_lo"], r[f"{m}_hi"], 3)
                )
            )
    return "".join(parts)


def _marked(row: pd.Series, value: str, digits: int) -> str:
    """``value`` with its interval, Holm p, bold when significant."""
    text = _cell(row[value], row["lo"], row["hi"], digits, "+") + f" p={row['p_holm']:.2g}"
    return f"**{text}**" if row["p_holm"] < ALPHA else text


def _changes_markdown(changes: pd.DataFrame, reference: str) -> str:
    parts = [
        f"# Each level against `{reference}`: AHC change [95 % interval], Holm p\n",
        "Paired by pair position (the same place, goal and current; only the camera "
        "differs); goal bootstrap and sign-flip test over goals, Holm within each place. "
        f"**Bold**: p < {ALPHA}.\n",
    ]
    for title, group in _sections(changes, ["missing", "place", "condition"]):
        goals = group["n_goals"].max()
        parts.append(f"\n## missing {title} ({goals} goals)\n\n")
        parts.append(_grid(group, "method", lambda r: _marked(r, "change", 3)))
    return "".join(parts)


def _findings_markdown(found: pd.DataFrame) -> str:
    parts = [
        "# Seed 001's findings per level: verdict, effect [95 % interval]\n",
        f"Holm within each level and place, alpha = {ALPHA}.\n",
    ]
    for title, group in _sections(found, ["place"]):
        parts.append(f"\n## {title} ({group['clusters'].max()} goals)\n\n")
        parts.append(
            _grid(
                group,
                "finding",
                lambda r: f"{r['verdict']} " + _cell(r["effect"], r["lo"], r["hi"], 2, "+"),
            )
        )
    return "".join(parts)


def _finding_changes_markdown(changes: pd.DataFrame, reference: str) -> str:
    parts = [
        f"# Seed 001's AE findings: effect at each level and its change against "
        f"`{reference}` (deg of AE, positive: the finding holds more)\n"
    ]
    for title, group in _sections(changes, ["missing", "place"]):
        parts.append(f"\n## missing {title}\n\n")
        parts.append(
            _grid(
                group,
                "finding",
                lambda r: (
                    _cell(r["effect"], r["effect_lo"], r["effect_hi"], 1, "+")
                    if pd.isna(r.get("p"))
                    else _marked(r, "change", 1)
                ),
            )
        )
    return "".join(parts)


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)
    runs = commands.add_parser("run", help="run the base config at every level")
    runs.add_argument("--out", type=Path, required=True, help="folder of the levels' runs")
    runs.add_argument("--config", type=Path, default=ROOT / "configs" / "ablation.yaml")
    runs.add_argument("--levels", type=Path, default=ROOT / "configs" / "ablation" / "levels.yaml")
    runs.add_argument("--jobs", type=int, default=None, help="workers (default: the config's)")
    runs.add_argument(
        "--only", action="append", default=[], metavar="LEVEL", help="run only this level (repeat)"
    )
    runs.add_argument("overrides", nargs="*", help="KEY=VALUE settings for every level")
    analysis = commands.add_parser("analyse", help="compare the levels' runs")
    analysis.add_argument("--out", type=Path, required=True, help="folder of the levels' runs")
    analysis.add_argument("--report", type=Path, required=True, help="folder for the tables")
    args = parser.parse_args(argv)
    if args.command == "run":
        run(args)
    else:
        analyse(args)


if __name__ == "__main__":
    main()
