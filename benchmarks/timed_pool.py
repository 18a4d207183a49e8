"""Worker processes with a deadline per job, for benchmarks whose solves may hang.

    pool = Pool(2, warm_up)          # spawned workers, each runs warm_up() first
    results = pool.map([(fn, args, n_solves), ...], timeout=60.0)
    pool.close()

A job is a picklable module-level function and its arguments. Each worker runs
one job at a time and keeps its state (compiled kernels) between jobs; a job
that runs over ``timeout`` x ``n_solves`` seconds has its worker killed and
replaced, and becomes ``{"status": "timeout", ...}``; a worker that dies makes
its job ``{"status": "failed", "message": "worker died"}``. A job that raises
becomes ``{"status": "error", "message": ...}``. joblib's ``timeout`` would
abort the whole batch instead.
"""

from __future__ import annotations

import multiprocessing as mp
import sys
import time
from collections import deque
from multiprocessing.connection import wait


def _serve(conn, warm_up):
    """A worker: warm up, report how long it took, then run jobs until None."""
    t0 = time.perf_counter()
    warm_up()
    conn.send(time.perf_counter() - t0)
    while (job := conn.recv()) is not None:
        index, fn, args = job
        try:
            out = fn(*args)
        except Exception as err:  # noqa: BLE001  (a bug in one job must not stop the others)
            out = {"status": "error", "message": f"{type(err).__name__}: {err}"}
        conn.send((index, out))


class Pool:
    """``workers`` spawned processes, one job each at a time, a deadline per job.

    ``startup``: each worker's warm-up time [s]; ``restarts``: workers replaced.
    """

    def __init__(self, workers: int, warm_up):
        self._ctx = mp.get_context("spawn")
        self._warm_up = warm_up
        self._workers = [self._start() for _ in range(workers)]
        self.startup = [conn.recv() for _, conn in self._workers]
        self.restarts = 0

    def _start(self):
        parent, child = self._ctx.Pipe()
        proc = self._ctx.Process(target=_serve, args=(child, self._warm_up), daemon=True)
        proc.start()
        return proc, parent

    def _replace(self, i: int):
        proc, _ = self._workers[i]
        proc.kill()
        proc.join()
        self._workers[i] = self._start()
        self._workers[i][1].recv()
        self.restarts += 1

    def map(self, jobs, timeout: float, progress: str = "") -> list[dict]:
        """Results of ``jobs`` ((fn, args, n_solves) each) in order; progress on
        stderr every 100 jobs when ``progress`` names the batch."""
        results: list = [None] * len(jobs)
        todo, busy = deque(range(len(jobs))), {}  # worker index -> (job index, deadline)
        t0, done, shown = time.perf_counter(), 0, 0
        while todo or busy:
            for i in range(len(self._workers)):
                if i not in busy and todo:
                    j = todo.popleft()
                    fn, args, solves = jobs[j]
                    self._workers[i][1].send((j, fn, args))
                    busy[i] = (j, time.perf_counter() + timeout * solves)
            conns = {self._workers[i][1]: i for i in busy}
            left = min(deadline for _, deadline in busy.values()) - time.perf_counter()
            for conn in wait(list(conns), timeout=max(left, 0.0)):
                i = conns[conn]
                try:
                    j, out = conn.recv()
                except EOFError:
                    j, out = busy[i][0], {"status": "failed", "message": "worker died"}
                    self._replace(i)
                results[j] = out
                del busy[i]
                done += 1
            for i, (j, deadline) in list(busy.items()):
                if time.perf_counter() > deadline:
                    self._replace(i)
                    limit = timeout * jobs[j][2]
                    results[j] = {"status": "timeout", "seconds": limit,
                                  "message": f"timeout: killed after {limit:g} s"}
                    del busy[i]
                    done += 1
            if progress and (done - shown >= 100 or done == len(jobs)):
                shown = done
                print(f"  {progress}: {done}/{len(jobs)} in {time.perf_counter() - t0:.0f} s",
                      file=sys.stderr, flush=True)
        return results

    def close(self):
        """Stop the workers (again: nothing)."""
        for proc, conn in self._workers:
            if proc.is_alive():
                conn.send(None)
                proc.join(5)
            if proc.is_alive():
                proc.kill()
                proc.join()
        self._workers = []
