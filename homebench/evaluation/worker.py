"""One isolated worker process: receive a call, run it, send back its result; repeat.

Forked by the worker server (:mod:`homebench.evaluation.worker_server`), which has imported
what the calls need and set one thread per numeric library (parallelism comes from the job
level; one thread keeps results equal for any number of workers). A worker only limits its own
address space, ends with its server, and runs calls.
"""

from __future__ import annotations

import ctypes
import os
import pickle
import signal
import threading
import time
import traceback
from multiprocessing.connection import Connection

PR_SET_PDEATHSIG = 1  # linux/prctl.h
M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3  # malloc.h (glibc)
#: Blocks up to this size come from the heap in a worker (glibc's largest on 64 bits), and
#: the heap keeps up to TRIM_BYTES free at its top (see :func:`keep_freed_memory`): enough for
#: a pair's arrays (min-warping frees about 25 MB at once) and for SIFT's pyramids of a
#: 752 x 564 image (well over 100 MB; with 64 MB kept, 33,000 faults and 141 instead of 68 ms
#: per image), an eighth of a worker's smallest default memory limit.
MMAP_THRESHOLD_BYTES = 32 << 20
TRIM_BYTES = 256 << 20


def _poll_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(0.2)
    os._exit(0)


def die_with_parent(parent: int) -> None:
    """End with the parent (a killed run must not leave workers computing): on Linux the kernel
    kills the worker when the parent dies, elsewhere a thread watches the parent."""
    try:
        linux = ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL) == 0
    except AttributeError:  # no prctl: not Linux
        linux = False
    if not linux:
        threading.Thread(target=_poll_parent, args=(parent,), daemon=True).start()
    if os.getppid() != parent:  # the parent died before the kernel was told
        os._exit(0)


def keep_freed_memory() -> bool:
    """Ask glibc's allocator to keep freed memory for reuse (blocks up to MMAP_THRESHOLD_BYTES
    come from the heap, which is trimmed only past TRIM_BYTES free at its top) instead of
    handing it back to the kernel at once; False where there is no glibc.

    By default glibc maps a large block afresh and trims the heap's top as soon as a few
    blocks are free, so a method that allocates and frees the same large arrays for every pair
    pays the kernel's page faults every time: min-warping's search tables (9 MB each) took
    about 4,300 faults per pair in a fresh process, 22.7 ms per pair against 9.0 ms with this.
    Results do not change: only where freed memory goes.
    """
    try:
        libc = ctypes.CDLL(None)
        mallopt = libc.mallopt
    except (AttributeError, OSError):
        return False
    settings = ((M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES), (M_TRIM_THRESHOLD, TRIM_BYTES))
    return all(mallopt(option, value) == 1 for option, value in settings)


class AddressSpaceError(MemoryError):
    """A worker's memory limit is below what it already maps."""


def limit_address_space(memory_mb: int) -> None:
    """Limit this process's address space to ``memory_mb`` (``RLIMIT_AS``), so that a runaway
    allocation raises MemoryError; AddressSpaceError if the process already maps more (then
    every allocation would fail: the limit is too small to run anything) or may map less."""
    import resource

    limit = memory_mb * 1024 * 1024
    _, hard = resource.getrlimit(resource.RLIMIT_AS)
    if hard != resource.RLIM_INFINITY and limit > hard:  # a Dask worker's own `ulimit -v`
        raise AddressSpaceError(
            f"the worker memory limit of {memory_mb} MB is above the {hard >> 20} MB this "
            f"process inherited (ulimit -v); set worker_memory_mb to at most {hard >> 20}"
        )
    mapped = _mapped_bytes()
    if mapped is not None and mapped >= limit:
        raise AddressSpaceError(
            f"the worker memory limit of {memory_mb} MB is below the {mapped >> 20} MB a "
            "worker maps before its first call; raise worker_memory_mb"
        )
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))


def _mapped_bytes() -> int | None:
    """The size of this process's address space (None where /proc cannot say)."""
    try:
        with open("/proc/self/statm", "rb") as statm:
            return int(statm.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return None


def serve(conn: Connection, memory_mb: int, parent: int) -> None:
    """Limit the address space to ``memory_mb`` (0: none), end with ``parent``, say ready; then
    run ``(function, args)`` calls until the connection closes, replying ``("ok", result)``, or
    ``("raised", text)`` for anything the call raised that it did not handle itself (SystemExit
    included)."""
    if memory_mb > 0:
        limit_address_space(memory_mb)
    die_with_parent(parent)
    conn.send(("ready", os.getpid()))
    while True:
        try:
            message = conn.recv_bytes()
        except EOFError:
            return
        try:
            function, args = pickle.loads(message)
            reply = ("ok", function(*args))
        except BaseException as error:  # noqa: BLE001  (the job failed, the worker goes on)
            reply = ("raised", "".join(traceback.format_exception_only(error)).strip())
        conn.send(reply)
