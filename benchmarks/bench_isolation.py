"""Per-job overhead of isolated workers against joblib (loky) and plain Dask tasks.

Every call runs a job that does (almost) nothing with a payload the size of a home job's, so the
time per call is the cost of handing a job over and its outcome back. Workers are warm (started
and importing before the clock runs); start-up and shut-down are measured apart, and so is a
new worker's first call of a numba kernel (CPU), with the kernels alone in the server's
preload and with numba set up there too (:mod:`homebench.methods.jit_setup`, as
:func:`~homebench.evaluation.executors.preload_for` adds it). Prints the load average, since
the numbers mean little on a busy machine.

    python benchmarks/bench_isolation.py [--workers 2] [--calls 400] [--dask]
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable

from joblib import Parallel, delayed

from homebench.config import MethodEntry
from homebench.evaluation.executors import PRELOAD, preload_for
from homebench.evaluation.isolation import Limits, WorkerPool, run_isolated

KERNELS = "homebench.methods.klt_sector.sector_law_kernels"

PAYLOAD = bytes(20_000)  # a pickled home job of a 10 x 17 grid is about this size


def job(item: int, payload: bytes) -> int:
    """The job: nothing but taking its payload and returning a small outcome."""
    return item + len(payload)


def first_kernel_call(_: int) -> float:
    """CPU seconds of a worker's first call of a numba kernel (the sector law's)."""
    import numpy as np

    from homebench.methods.klt_sector.sector_law_kernels import first_longest_rotation

    start = time.process_time()
    first_longest_rotation(np.arange(4, dtype=np.int64))
    return time.process_time() - start


def _per_call(run: Callable[[int], None], calls: int) -> float:
    """Best of 3 of wall seconds per call for ``calls`` calls, after a warm-up round."""
    run(calls)
    times = []
    for _ in range(3):
        start = time.perf_counter()
        run(calls)
        times.append((time.perf_counter() - start) / calls)
    return min(times)


def _local(workers: int, calls: int) -> dict[str, float]:
    results = {}
    results["in-process loop (today's --jobs 1)"] = _per_call(
        lambda n: [job(k, PAYLOAD) for k in range(n)], calls
    )
    parallel = Parallel(n_jobs=workers, return_as="generator_unordered")
    results[f"joblib/loky, {workers} workers (today)"] = _per_call(
        lambda n: list(parallel(delayed(job)(k, PAYLOAD) for k in range(n))), calls
    )
    for size in sorted({1, workers}):
        with WorkerPool(size, Limits(timeout_s=3600.0, memory_mb=4096), PRELOAD) as pool:
            start = time.perf_counter()
            list(pool.map_unordered(job, [0], (PAYLOAD,)))
            results[f"isolated pool start-up, {size} worker(s) [s, once]"] = (
                time.perf_counter() - start
            )
            results[f"isolated pool, {size} worker(s)"] = _per_call(
                lambda n, p=pool: list(p.map_unordered(job, range(n), (PAYLOAD,))), calls
            )
            closing = time.perf_counter()
        results[f"isolated pool shut-down, {size} worker(s) [s, once]"] = (
            time.perf_counter() - closing
        )
    for how, preload in (
        ("kernels only", (*PRELOAD, KERNELS)),
        ("numba set up", preload_for([MethodEntry(method="klt-sector")])),
    ):
        with WorkerPool(workers, Limits(), preload) as pool:
            cpu = [seconds for _, seconds in pool.map_unordered(first_kernel_call, range(workers))]
        results[f"first numba call per worker, {how} [s, once]"] = max(cpu)
    return results


def _dask(workers: int, calls: int) -> dict[str, float]:
    from dask.distributed import Client, LocalCluster, wait

    limits = Limits(timeout_s=3600.0, memory_mb=4096)
    with (
        LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
            dashboard_address=None,
        ) as cluster,
        Client(cluster) as client,
    ):  # fmt: skip

        def plain(n: int) -> None:
            wait([client.submit(job, k, PAYLOAD, pure=False) for k in range(n)])

        def isolated(n: int) -> None:
            futures = [
                client.submit(run_isolated, job, (k, PAYLOAD), limits, PRELOAD, pure=False)
                for k in range(n)
            ]
            wait(futures)

        return {
            f"dask task, {workers} workers": _per_call(plain, calls),
            f"dask task + isolated worker, {workers} workers": _per_call(isolated, calls),
        }


def measure(workers: int, calls: int, dask: bool) -> dict[str, float]:
    """Seconds per call of each way to run a job (start-ups in seconds, once)."""
    results = _local(workers, calls)
    return results | _dask(workers, calls) if dask else results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--calls", type=int, default=400)
    parser.add_argument("--dask", action="store_true", help="also measure Dask tasks")
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()}, {os.cpu_count()} CPUs")
    # workers import a job by its module's name: run the measurement from the module imported
    # by name, not from this script's "__main__"
    import bench_isolation

    results = bench_isolation.measure(args.workers, args.calls, args.dask)
    for name, seconds in results.items():
        unit = f"{seconds:8.2f} s" if "[s, once]" in name else f"{1e3 * seconds:8.3f} ms/job"
        print(f"{name:<52} {unit}")
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
