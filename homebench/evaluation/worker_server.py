"""The worker server: one fresh interpreter that imports what the workers need, once, then forks
each isolated worker (:mod:`homebench.evaluation.worker`) on request and says how each one ended.

Started by :mod:`homebench.evaluation.isolation` as ``python -m
homebench.evaluation.worker_server FD PARENT_PID``, with one thread per numeric library in its
environment, which its workers inherit. Forking a worker costs milliseconds where a fresh
interpreter would import everything again (about a second). The server ends with its parent, and
its workers end with it. Messages on the control connection FD:

- parent to server: ``(sys.path, preload)`` once; then ``("start", memory_mb)`` followed by the
  new worker's end of a socket pair (a file descriptor), or ``("kill", pid)``;
- server to parent: ``("ready", pid)`` once the preload modules are imported; ``("started",
  pid)`` for each start; ``("ended", pid, code)`` when a worker has ended (``code`` as
  :attr:`subprocess.Popen.returncode` gives it: negative for the signal that killed it).

Only the server waits for its workers, and it kills only workers it has not yet waited for, so a
kill can never reach another process that got a finished worker's pid.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import signal
import socket
import sys
import traceback
from multiprocessing.connection import Connection, wait
from multiprocessing.reduction import recv_handle

from homebench.evaluation.worker import die_with_parent, keep_freed_memory, serve


class _Server:
    """The server's loop: start and kill workers as the parent asks, report their ends."""

    def __init__(self, control: Connection):
        self.control = control
        self.workers: set[int] = set()  # started and not yet waited for
        self.wakeup, wakeup_write = socket.socketpair()
        wakeup_write.setblocking(False)
        self._wakeup_write = wakeup_write
        signal.set_wakeup_fd(wakeup_write.fileno())
        signal.signal(signal.SIGCHLD, lambda *_: None)  # only to write to the wakeup socket

    def run(self) -> None:
        """Serve until the parent closes the connection; then kill the workers left and wait
        for them (so that their CPU time counts in the server's children's, and the parent's)."""
        self.control.send(("ready", os.getpid()))
        while True:
            ready = wait([self.control, self.wakeup])
            if self.wakeup in ready:
                self.wakeup.recv(4096)
                self._reap()
            if self.control in ready:
                try:
                    kind, value = self.control.recv()
                except (EOFError, OSError):  # closed, or reset (it left messages unread)
                    break
                if kind == "start":
                    self._start(value)
                elif kind == "kill" and value in self.workers:
                    os.kill(value, signal.SIGKILL)
        for pid in self.workers:
            os.kill(pid, signal.SIGKILL)
        for pid in self.workers:
            os.waitpid(pid, 0)

    def _start(self, memory_mb: int) -> None:
        """Fork a worker serving the socket that follows on the control connection."""
        fd = recv_handle(self.control)
        pid = os.fork()
        if pid == 0:
            self._become_worker(fd, memory_mb)
        os.close(fd)
        self.workers.add(pid)
        self.control.send(("started", pid))

    def _become_worker(self, fd: int, memory_mb: int) -> None:
        """In the forked child: drop the server's connections and signal handling, serve calls
        on ``fd``, and end there (never return into the server's loop)."""
        code = 0
        try:
            signal.set_wakeup_fd(-1)
            signal.signal(signal.SIGCHLD, signal.SIG_DFL)
            for end in (self.control, self.wakeup, self._wakeup_write):
                end.close()
            serve(Connection(fd), memory_mb, os.getppid())
        except BaseException:  # noqa: BLE001  (said on stderr; the parent sees the exit code)
            traceback.print_exc()
            code = 1
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os._exit(code)

    def _reap(self) -> None:
        """Wait for every worker that has ended and tell the parent how."""
        while self.workers:
            try:
                pid, status = os.waitpid(-1, os.WNOHANG)
            except ChildProcessError:
                return
            if pid == 0:
                return
            self.workers.discard(pid)
            with contextlib.suppress(OSError):  # the parent has closed: it no longer asks
                self.control.send(("ended", pid, os.waitstatus_to_exitcode(status)))


def main(control: Connection, parent: int) -> None:
    """Set up as a worker needs (Ctrl-C is the parent's, freed memory kept for reuse), take the
    parent's ``sys.path``, import the modules it names, and serve. Once its workers are gone
    the server ends at once: the interpreter's clean-up (tearing down numpy, OpenCV, numba)
    would keep the parent waiting about a quarter of a second, and nothing of it is needed."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    die_with_parent(parent)
    keep_freed_memory()
    sys.path[:], preload = control.recv()
    for module in preload:
        importlib.import_module(module)
    _Server(control).run()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)


if __name__ == "__main__":
    fd, parent_pid = (int(arg) for arg in sys.argv[1:3])
    main(Connection(fd), parent_pid)
