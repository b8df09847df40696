"""How much address space homebench's processes reserve, and the least a run needs.

Address space is what ``ulimit -v`` (``RLIMIT_AS``, as batch systems set it) limits, and a
reservation counts in full even where no page of it is ever touched. pyarrow, which pandas
uses for its string columns, allocates through mimalloc, which reserves 1 GiB of address space
at its first allocation: a process that builds one table of strings maps 2.2 GB where it
needs 1.2. :func:`reserve_less` has pyarrow allocate through the C library's ``malloc``
instead (its ``system`` pool), which reserves what it hands out.
"""

from __future__ import annotations

import os
import resource

from homebench.errors import ConfigError

#: The environment variable that chooses pyarrow's default memory pool, read when pyarrow
#: loads, and the pool that reserves no more than it hands out.
ARROW_POOL = {"ARROW_DEFAULT_MEMORY_POOL": "system"}
#: The least address space a run's main process works in (MB): the libraries of a run (numpy,
#: scipy, pandas, OpenCV, matplotlib, numba) map 1.2 GB; the tables and the report need more.
MIN_RUN_MB = 1536


def reserve_less() -> None:
    """Have pyarrow in this process and its children allocate through ``malloc``
    (:data:`ARROW_POOL`), unless the environment chooses a pool; called before pyarrow is
    imported (by the command line, first thing)."""
    for name, value in ARROW_POOL.items():
        os.environ.setdefault(name, value)


def inherited_mb() -> int | None:
    """The address-space limit this process inherited (``ulimit -v``), MB; None: none."""
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    return None if soft == resource.RLIM_INFINITY else soft >> 20


def check_run_space() -> None:
    """ConfigError, in one line, when this process may map less address space than a run
    needs (:data:`MIN_RUN_MB`): said before any work, not as a crash once the jobs are done."""
    limit = inherited_mb()
    if limit is not None and limit < MIN_RUN_MB:
        raise ConfigError(
            f"ulimit -v: this process may map {limit:,} MB of address space; a homebench run "
            f"needs at least {MIN_RUN_MB:,} MB (its libraries alone map 1.2 GB): raise the "
            "limit"
        )
