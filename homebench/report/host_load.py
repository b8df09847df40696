"""What a report says beside its timing columns and figure: the host's load while the run timed
its jobs (``environment.json``'s ``load``, :func:`homebench.evaluation.provenance.record_load_end`).

A time per call measured while other processes wanted the cores includes waiting for one; the
1-min load average (processes running or waiting) at the start and end of the run call says
whether that was likely. Jobs reused from earlier calls were timed under a load not recorded;
run folders written before homebench recorded the load say nothing of it.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

NOT_RECORDED = (
    "The host's load while this run timed its jobs was not recorded (a run folder of an older "
    "homebench): times measured on a busy host include waiting for a core."
)


def _cpus(environment: Mapping[str, Any]) -> Any:
    """The CPU count the record gives (``cpu.count``, else ``cpu_count``), or None."""
    cpu = environment.get("cpu")
    count = cpu.get("count") if isinstance(cpu, Mapping) else None
    return count if count is not None else environment.get("cpu_count")


def _jobs(load: Mapping[str, Any]) -> str:
    """Which jobs the recorded call timed, in words ("" when not recorded)."""
    timed, reused = load.get("jobs_timed"), load.get("jobs_reused")
    if timed is None:
        return ""
    if not reused:
        return f" that timed all {timed} jobs"
    return (
        f" that timed {timed} of {timed + reused} jobs ({reused} in earlier calls, under a load "
        "not recorded)"
    )


def load_note(environment: Mapping[str, Any]) -> str:
    """The note on a report's timing columns and figure from a run's ``environment`` record:
    the 1-min load average at the start and end of the run call, the jobs it timed, the CPUs;
    :data:`NOT_RECORDED` when the record has no load."""
    load = environment.get("load")
    if not isinstance(load, Mapping) or load.get("start_1min") is None:
        return NOT_RECORDED
    end = load.get("end_1min")
    ends = (
        f" and {end:.2f} at the end" if end is not None else " (end not recorded: the call stopped)"
    )
    cpus = _cpus(environment)
    on = f", on {cpus} CPUs" if cpus else ""
    return (
        f"Times depend on the host's load: its 1-min load average was {load['start_1min']:.2f} "
        f"at the start{ends} of the run call{_jobs(load)}{on}; a load above the CPU count means "
        "calls waited for a core."
    )
