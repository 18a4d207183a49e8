"""Run a sweep: chains of cases on joblib workers, chunks into the Parquet dataset.

Each chain (cases that differ only in the chain axis) is solved in order, each
case warm-started from the previous solution of its chain; a chain's first case
(and a case after a change of dimension, method or roller count) starts cold.
Results do not depend on the number of workers or on how chains are packed
into tasks: a chain never crosses a task, and nothing else carries over
between cases.

Workers are the backend's processes (loky by default; dask.distributed or Ray
through joblib). A worker keeps its compiled kernels for all the tasks it runs,
so kernels are loaded (from Numba's on-disk cache) once per worker process, not
once per case. On a cold cache (:func:`pipelay_fast.kernels._jit.kernels_cached`)
with more than one worker, the sweep starts with one round of a task per
dimension (:func:`compile_first`), which all finish before the other tasks
start: each of those workers compiles one dimension's kernels while the
other compiles the other's, and every later task loads them from the cache,
instead of every worker compiling both. The parent process is the only
writer of the dataset.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
import time
from dataclasses import dataclass, field

import numpy as np
from tqdm import tqdm

from ..api.notice import announce_compile, notice_given
from ..api.solve import solve
from ..api.target import solve_for
from ..input.errors import SolveError
from ..kernels._jit import kernels_cached
from ..output.results import SUMMARY_UNITS
from .dataset import Dataset, encode_chunk, repeated_text
from .sensitivity import sensitivity_columns, sensitivity_values
from .sweep import INPUT_UNITS, Sweep, SweepCase, chains, target_bounds

__all__ = ["BACKENDS", "SweepReport", "run_sweep", "solve_case", "solve_chain"]

BACKENDS = ("loky", "dask", "ray")
# errors of one case that make it a failed row; anything else stops the sweep
CASE_ERRORS = (SolveError, NotImplementedError, ValueError)


@dataclass
class SweepReport:
    """What a run did: ``total`` cases, of which ``skipped`` (already
    written), ``solved`` (rows written, ``failed`` among them) in ``chunks``
    chunks by ``workers`` workers (``worker_pids``). Times in seconds:
    ``seconds`` wall time of the run (case expansion included),
    ``solve_seconds`` the time spent in ``pf.solve`` summed over the workers,
    ``write_seconds`` the time the parent spent writing the chunks the
    workers encoded to Parquet; ``cpu_seconds`` the processor time of the
    workers' tasks and of the parent, ``solve_cpu_seconds`` the part of it in
    ``pf.solve``."""

    total: int = 0
    skipped: int = 0
    solved: int = 0
    failed: int = 0
    chunks: int = 0
    seconds: float = 0.0
    solve_seconds: float = 0.0
    write_seconds: float = 0.0
    cpu_seconds: float = 0.0
    solve_cpu_seconds: float = 0.0
    workers: int = 1
    worker_pids: set = field(default_factory=set)

    @property
    def overhead_share(self) -> float:
        """Share of the worker time not spent solving: 1 - solve time / (workers x wall)."""
        if self.seconds <= 0 or self.solved == 0:
            return math.nan
        return 1.0 - self.solve_seconds / (self.workers * self.seconds)

    @property
    def cpu_overhead_share(self) -> float:
        """Share of the processor time not spent solving (idle workers not counted;
        not affected by other programs sharing the cores)."""
        if self.cpu_seconds <= 0 or self.solved == 0:
            return math.nan
        return 1.0 - self.solve_cpu_seconds / self.cpu_seconds

    def __str__(self):
        rate = self.solved / self.seconds if self.seconds > 0 else math.nan
        return (f"{self.total} cases: {self.solved} solved ({self.failed} failed), "
                f"{self.skipped} already written; {self.chunks} chunks in {self.seconds:.1f} s "
                f"({rate:.1f} cases/s on {self.workers} workers)")


def run_sweep(sweep: Sweep, out, *, workers: int = 2, backend: str = "loky",
              scheduler: str | None = None, chunk_size: int | None = None,
              profiles: bool = True, progress: bool = True,
              warm_start: bool = True) -> SweepReport:
    """Solve every case of ``sweep`` not yet in the results directory ``out``.

    Parameters
    ----------
    sweep : Sweep
    out : path-like
        The results directory (:class:`pipelay_fast.study.dataset.Dataset`),
        created if missing; cases whose id it already holds are skipped.
    workers : int
        Worker processes (1: in this process).
    backend : str
        "loky" (default), "dask" (a running ``distributed.Client`` is used, else
        the ``scheduler`` address, else a LocalCluster of ``workers`` processes)
        or "ray".
    scheduler : str, optional
        The dask scheduler or Ray cluster address to join (default: start
        one of ``workers`` processes).
    chunk_size : int, optional
        Cases per task and per Parquet chunk, rounded up to whole chains;
        default an eighth of each worker's share, at most 256.
    profiles : bool
        Write the profiles table (one row per node per case).
    progress : bool
        Show cases done, failures, the rate and an ETA on stderr (:func:`progress_bar`).
    warm_start : bool
        Start each case from the previous solution of its chain (default); False
        solves every case cold (for comparison).

    Returns
    -------
    SweepReport
        The counts and times of the run.

    Raises
    ------
    ValueError
        For a bad ``backend``, ``workers`` or ``chunk_size``, or a results
        directory holding another case under a scene's name.
    RuntimeError
        When another live process holds the directory's lock.
    ImportError
        When the dask or ray backend is asked for and not installed.
    """
    if backend not in BACKENDS:
        raise ValueError(f"backend = {backend!r} must be one of {', '.join(BACKENDS)}")
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers = {workers!r} must be a positive integer")
    if chunk_size is not None and (not isinstance(chunk_size, int) or chunk_size < 1):
        raise ValueError(f"chunk_size = {chunk_size!r} must be a positive integer")
    start, start_cpu = time.perf_counter(), time.process_time()
    cases = sweep.cases()
    report = SweepReport(total=len(cases), workers=workers)
    with Dataset(out, sweep) as dataset:
        done = dataset.case_ids()
        # building a case (to know its id) is left to the workers unless some
        # cases are already written
        todo = [c for c in cases if c.case_id not in done] if done else cases
        report.skipped = len(cases) - len(todo)
        tasks = pack(chains(todo), chunk_size or _default_chunk(len(todo), workers))
        first = 0
        if tasks and workers > 1 and not kernels_cached():
            tasks, first = compile_first(tasks)
        if tasks:
            announce_compile()  # here, once, rather than in each worker
        with (progress_bar(len(todo), enabled=progress) as bar,
              _backend(backend, workers, scheduler)):
            for chunk, times, pid in _parallel(tasks, (sweep.name, profiles, warm_start,
                                                       sweep.sensitivities), workers, first):
                t0 = time.perf_counter()
                dataset.write_chunk(chunk)
                report.write_seconds += time.perf_counter() - t0
                report.chunks += 1
                report.solved += chunk.rows
                report.failed += chunk.failed
                report.solve_seconds += times["solve"]
                report.solve_cpu_seconds += times["solve_cpu"]
                report.cpu_seconds += times["task_cpu"]
                report.worker_pids.add(pid)
                bar.set_postfix(failed=report.failed, refresh=False)
                bar.update(chunk.rows)
    report.seconds = time.perf_counter() - start
    parent_cpu = time.process_time() - start_cpu
    if os.getpid() in report.worker_pids:  # tasks ran here: their time is in parent_cpu
        report.cpu_seconds = 0.0
    report.cpu_seconds += parent_cpu
    return report


def pack(chain_list: list[list[SweepCase]], size: int) -> list[list[list[SweepCase]]]:
    """Chains packed in order into tasks of about ``size`` cases, one scene per task."""
    tasks, current, count = [], [], 0
    for chain in chain_list:
        if current and (count + len(chain) > size or current[0][0].scene != chain[0].scene):
            tasks.append(current)
            current, count = [], 0
        current.append(chain)
        count += len(chain)
    if current:
        tasks.append(current)
    return tasks


def compile_first(tasks: list[list[list[SweepCase]]]) -> tuple[list, int]:
    """``tasks`` reordered for a cold kernel cache, and how many of them form
    the first round: the first task of each dimension ("2d", "3d": the Newton
    kernel's two compilations, :mod:`pipelay_fast.kernels.newton`), so that
    each of the first round's workers compiles a dimension of its own and the
    later tasks load it from numba's cache instead of compiling it again.
    First round 0 (no round) when the tasks have a single dimension."""
    picked, seen = [], set()
    for i, task in enumerate(tasks):
        dims = {chain[0].case.resolved_dimension for chain in task if chain[0].case is not None}
        if dims - seen:
            picked.append(i)
            seen |= dims
    if len(picked) < 2:
        return tasks, 0
    return [tasks[i] for i in picked] + [t for i, t in enumerate(tasks) if i not in picked], \
        len(picked)


def _default_chunk(n: int, workers: int) -> int:
    """Eight tasks per worker: small enough that the last ones even out the
    workers' loads, large enough that a task's fixed costs do not count."""
    return int(min(256, max(1, math.ceil(n / (8 * workers)))))


# --------------------------------------------------------------------------- workers


def solve_task(task: list[list[SweepCase]], sweep: str, profiles: bool,
               warm_start: bool = True, sensitivities: tuple = ()):
    """Solve the chains of one task and encode them as a chunk (runs in a
    worker), the summary with the columns of the sweep's ``sensitivities``
    (:func:`pipelay_fast.study.sensitivity.sensitivity_columns`).

    Returns (the :class:`~pipelay_fast.study.dataset.Chunk`, times in seconds: "solve"
    and "solve_cpu" in ``pf.solve``, "task_cpu" of the whole task; the pid).
    """
    start_cpu = time.process_time()
    notice_given()  # by the process that runs the sweep
    rows, parts, roller_parts, span_parts = [], [], [], []
    times = {"solve": 0.0, "solve_cpu": 0.0}
    for chain in task:
        for sc, row, result, dt, cpu in solve_chain(chain, warm_start, sensitivities):
            rows.append(row)
            times["solve"] += dt
            times["solve_cpu"] += cpu
            if profiles and result is not None:
                parts.append((sc.case_id, {"node": np.arange(len(result.columns["s"])),
                                           **result.columns}))
            if result is not None and result.roller_columns is not None:
                roller_parts.append((sc.case_id, result.roller_columns))
            if result is not None and result.span_columns and len(result.span_columns["span"]):
                span_parts.append((sc.case_id, result.span_columns))
    chunk = encode_chunk(sweep, task[0][0].scene, rows, _joined(parts), _joined(roller_parts),
                         sensitivity_columns(sensitivities), _joined(span_parts))
    times["task_cpu"] = time.process_time() - start_cpu
    return chunk, times, os.getpid()


def _joined(parts: list[tuple[str, dict]]) -> dict | None:
    """The columns of ``parts`` ((case id, dict of arrays of one length)) end
    to end, with each row's ``case_id`` first; None when empty."""
    if not parts:
        return None
    first = parts[0][1]
    counts = [len(next(iter(columns.values()))) for _cid, columns in parts]
    return {"case_id": repeated_text([cid for cid, _columns in parts], counts),
            **{k: np.concatenate([columns[k] for _cid, columns in parts]) for k in first}}


def solve_chain(chain: list[SweepCase], warm_start: bool = True, sensitivities: tuple = ()):
    """Yield (case, summary row, Result or None, wall and processor seconds in
    ``pf.solve``) along one chain.

    Each case is warm-started from the last successful solution of the chain
    when it has the same lay method, dimension and roller count
    (``warm_started`` in its row); a case that fails (invalid inputs,
    SolveError, a gated case, a target out of reach) becomes a row with
    status "failed" and the reason in ``message``. A scene with a target solves each case for it
    (:func:`pipelay_fast.solve_for`, its first trial warm from the chain). A
    row has the columns of the sweep's ``sensitivities`` that its scene's
    case gives, and the reasons for the others' NaN
    (:func:`pipelay_fast.study.sensitivity.sensitivity_values`).
    """
    previous = None
    for sc in chain:
        base = {"case_id": sc.case_id, "chain": sc.chain, "chain_position": sc.position,
                "target": sc.source.target_text}
        if sc.case is None:
            yield sc, _failed_row(sc, base, f"invalid case: {sc.error}"), None, 0.0, 0.0
            continue
        warm = previous if warm_start and _compatible(previous, sc) else None
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            result = solve_case(sc.case, warm, sc.source.target, sc.source.sensitivities)
        except CASE_ERRORS as err:
            dt, cpu = time.perf_counter() - t0, time.process_time() - c0
            yield sc, _failed_row(sc, base, f"{type(err).__name__}: {err}"), None, dt, cpu
            continue
        dt, cpu = time.perf_counter() - t0, time.process_time() - c0
        previous = result
        row = {**result.summary, **_given(sc), **base, "warm_started": warm is not None}
        if result.target is not None:
            row["target_value"] = result.target["value"]
        if sensitivities:
            row.update(sensitivity_values(result.sensitivities, sc.source.sensitivities,
                                          sensitivities))
        yield sc, row, result, dt, cpu


def solve_case(case, warm=None, target=None, sensitivities=()):
    """``pf.solve`` of ``case`` started from the Result ``warm`` (None: cold),
    with the derivatives by the keys ``sensitivities``; with ``target`` (a
    scene's, see :class:`pipelay_fast.study.sweep.Scene`) the target solve
    :func:`pipelay_fast.solve_for` (no sensitivities).

    The solver itself falls back to its own first guess when the warm start
    fails, so the answer does not depend on the start beyond its tolerance.
    """
    if target is None:
        return solve(case, warm=warm, sensitivities=list(sensitivities) or None)
    return solve_for(case, {target["column"]: target["goal"]}, target["vary"],
                     target_bounds(target, case), warm=warm)


def _compatible(previous, sc: SweepCase) -> bool:
    """Whether the Result ``previous`` can warm-start ``sc``: same lay
    method, dimension and roller count."""
    return (previous is not None and previous.case.lay.method == sc.case.lay.method
            and previous.summary["dimension"] == sc.case.resolved_dimension
            and previous.case.lay.roller_count == sc.case.lay.roller_count)


def _given(sc: SweepCase) -> dict:
    return {k: v for k, v in sc.inputs.items() if k in INPUT_UNITS}


def _failed_row(sc: SweepCase, base: dict, message: str) -> dict:
    """The summary row of a case that failed: its inputs, NaN answers,
    status "failed" and ``message``."""
    row = {name: math.nan for name, unit in SUMMARY_UNITS.items() if unit}
    row.update(sc.inputs)
    row.update(base)
    row.update({"status": "failed", "message": message, "warm_started": False,
                "n_elements": None, "n_iterations": None, "n_current_steps": None,
                "max_current_step_iterations": None, "n_meshes": None})
    return row


# --------------------------------------------------------------------------- scheduling


def _parallel(tasks, args: tuple, workers: int, first: int = 0):
    """Results of ``solve_task`` over ``tasks`` (each with the further
    arguments ``args``) as they finish; the ``first`` tasks all finish before
    the others start (:func:`compile_first`)."""
    if workers == 1 or len(tasks) <= 1:
        for task in tasks:
            yield solve_task(task, *args)
        return
    if first:
        yield from _parallel(tasks[:first], args, workers)
        tasks = tasks[first:]
    from joblib import Parallel, delayed

    calls = (delayed(solve_task)(task, *args) for task in tasks)
    try:
        runner = Parallel(n_jobs=workers, return_as="generator_unordered", batch_size=1,
                          pre_dispatch="2*n_jobs")
    except ValueError:  # a backend without result streaming: run in rounds
        runner = None
    if runner is not None:
        yield from runner(calls)
        return
    size = 2 * workers
    for i in range(0, len(tasks), size):
        yield from Parallel(n_jobs=workers, batch_size=1)(
            delayed(solve_task)(task, *args) for task in tasks[i:i + size])


@contextlib.contextmanager
def _backend(backend: str, workers: int, scheduler: str | None):
    """joblib's backend for the run; dask and ray are imported only when asked for.

    A dask cluster or Ray instance started here is closed at the end; one the
    caller started (a current ``distributed.Client``, ``ray.init``) is left running.
    """
    from joblib import parallel_config

    if backend == "loky":
        with parallel_config(backend="loky", n_jobs=workers):
            yield
        return
    if backend == "dask":
        try:
            from distributed import Client, LocalCluster
        except ImportError:
            raise ImportError("backend 'dask' needs dask.distributed: "
                              "pip install 'pipelay-fast[dask]'") from None
        with contextlib.ExitStack() as stack:
            try:
                Client.current()  # a client the caller started
            except ValueError:
                if scheduler:
                    stack.enter_context(Client(scheduler))
                else:
                    cluster = stack.enter_context(LocalCluster(
                        n_workers=workers, threads_per_worker=1, processes=True,
                        dashboard_address=None))
                    stack.enter_context(Client(cluster))
            with parallel_config(backend="dask", n_jobs=workers):
                yield
        return
    try:
        import ray
        from ray.util.joblib import register_ray
    except ImportError:
        raise ImportError("backend 'ray' needs Ray: pip install 'pipelay-fast[ray]'") from None
    register_ray()
    started = not ray.is_initialized()  # else: the caller's Ray, left running
    if started:
        ray.init(address=scheduler, num_cpus=None if scheduler else workers)
    try:
        with parallel_config(backend="ray", n_jobs=workers):
            yield
    finally:
        if started:
            ray.shutdown()


# --------------------------------------------------------------------------- progress


# seconds between redraws in a log (a file or a pipe): tqdm's longest
# interval between redraws (its maxinterval), so that a log line comes as
# often as a bar that stalls would redraw; on a terminal tqdm's own default
REDRAW_LOG = 10.0
# a log's bar: plain characters, a fixed width and height (a pseudo-terminal of
# 0 x 0, as some CI runners give, would make tqdm hide it)
LOG_STYLE = {"ascii": True, "ncols": 80, "nrows": 20}


def progress_bar(total: int, *, enabled: bool = True, stream=None) -> tqdm:
    """A tqdm bar of cases on ``stream`` (default stderr): done, rate, ETA and
    ``failed=N`` (set with ``set_postfix(failed=N, refresh=False)`` before
    ``update``).

    On a terminal it is redrawn in place, at tqdm's default interval. Elsewhere
    (a log file, a pipe) each redraw is a line of its own, one every
    REDRAW_LOG seconds at most besides the first and the last.
    """
    stream = stream or sys.stderr
    tty = _terminal(stream)
    return (tqdm if tty else _LogBar)(
        total=total, unit=" cases", file=stream, disable=not enabled or total == 0,
        postfix={"failed": 0}, dynamic_ncols=tty,
        **({} if tty else {"mininterval": REDRAW_LOG, **LOG_STYLE}))


def _terminal(stream) -> bool:
    """A terminal with a width (not a pseudo-terminal of 0 columns)."""
    try:
        return stream.isatty() and os.get_terminal_size(stream.fileno()).columns > 0
    except (AttributeError, OSError, ValueError):  # not a file, or not a terminal
        return False


class _LogBar(tqdm):
    """tqdm writing each redraw on a line of its own (tqdm ends the last one)."""

    @staticmethod
    def status_printer(file):
        started = False

        def print_status(text):
            nonlocal started
            file.write(("\n" if started else "") + text)
            file.flush()
            started = True

        return print_status
