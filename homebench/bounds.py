"""What one run can hold: the bounds every count of a config is checked against before any work.

The counts a config sets multiply: seeds x styles x conditions x method points x goals make a
grid run's jobs, routes x lengths x repeats x methods a route run's trials, styles x goals x
starts x labels a closed-loop run's; a robot trial's frames are its route's length over the
step (and its turns over the turn limit). Each job or trial is a file of the run folder and a few
hundred bytes of the main process's memory from planning to the tables, each grid pair a row of
``pairs.csv`` (about 1 KB in memory), so the products are bounded, and a config beyond them is
refused before anything is generated or run, naming the key that sets the most.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

#: Most jobs (grid home jobs) or trials (route, closed loop) of one run: a million files.
MAX_JOBS = 1_000_000
#: Most grid pairs of one run (rows of ``pairs.csv``; about 10 GB of tables in memory).
MAX_PAIRS = 10_000_000
#: Most frames (steps, views) of one robot trial: a route's outbound drive, a closed loop's
#: steps, a goal's training views; each is a render in the worker and poses in the trial's file.
MAX_TRIAL_FRAMES = 100_000
#: Most frames of all of one run's trials (their poses are read back for the tables, as pairs).
MAX_FRAMES = MAX_PAIRS
#: Most AHC distance bins (each a mask over every pair; seed 001 has 13).
MAX_AHC_BINS = 1000
#: Most distance bands of the band table (each a mask over every pair; the default has 3).
MAX_BANDS = 20


def workers_problem(jobs: int) -> str:
    """Why ``jobs`` is no number of parallel workers (``--jobs``, a config's ``jobs``): they
    are a positive number, or -1 for one per core; "" when it is one."""
    if jobs >= 1 or jobs == -1:
        return ""
    return f"jobs must be a positive number, or -1 for all cores (got {jobs})"


def count_problem(
    counts: Mapping[str, int], what: str, limit: int = MAX_JOBS, total: int | None = None
) -> str:
    """Why the run's ``total`` ``what`` (default: the product of ``counts``, config key -> the
    count it sets) are more than ``limit``, in one line starting with the key of the largest
    count: "routes[0].repeats: 1,000,000,000 x 5 (routes[0].lengths): 5,000,000,000 trials in
    all, more than the 1,000,000 one run can hold"; "" when they are not."""
    total = math.prod(counts.values()) if total is None else total
    if total <= limit:
        return ""
    key = max(counts, key=lambda k: counts[k])
    others = "".join(f" x {n:,} ({k})" for k, n in counts.items() if k != key and n != 1)
    return (
        f"{key}: {counts[key]:,}{others}: {total:,} {what} in all, more than the {limit:,} one "
        "run can hold"
    )
