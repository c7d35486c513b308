"""Where the jobs run: in this process (``serial``), on a local pool of worker processes
(one per core, the default), or on a Dask distributed cluster (``--cluster
tcp://HOST:8786``: dask.distributed schedules, synth brings no scheduler of its own).

Every runner returns the results in the jobs' order, so the files written from them are
the same byte for byte wherever the jobs ran. A worker that dies is survived: the local
pool runs the jobs it lost again in a fresh pool, Dask reschedules them on the other
workers; a job that still cannot finish is an ``error`` result naming its station and job.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

from synth.errors import SynthError
from synth.line.jobs import Job
from synth.line.work import error_result, fresh_worker, run_counted

__all__ = ["RunStats", "LocalPool", "run_serial", "run_local", "run_dask", "default_workers"]

Progress = Callable[[int, dict[str, Any]], None]


@dataclass
class RunStats:
    """How a run went: plant compilations per worker process (pid → count)."""

    compiled: dict[int, int] = field(default_factory=dict)

    def note(self, worker: tuple[int, int]) -> None:
        pid, count = worker
        self.compiled[pid] = max(self.compiled.get(pid, 0), count)

    @property
    def compilations(self) -> int:
        return sum(self.compiled.values())


def default_workers() -> int:
    """One worker per core this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def run_serial(jobs: Sequence[Job], progress: Progress | None = None,
               stats: RunStats | None = None) -> list[dict[str, Any]]:
    """Every job in this process, in order."""
    from synth.line import work

    out = []
    before = len(work.COMPILED)
    for i, job in enumerate(jobs):
        result, _ = run_counted(job)
        out.append(result)
        if progress is not None:
            progress(i, result)
    if stats is not None:
        stats.note((os.getpid(), len(work.COMPILED) - before))
    return out


class LocalPool:
    """Worker processes kept for a whole run (``synth check --mutate`` runs the checks, then the
    mutants, on the same workers: each compiles a plant once for both); a new set of processes
    after a worker died. Use as a context manager."""

    def __init__(self, workers: int | None = None) -> None:
        self.workers = workers or default_workers()
        self._pool: Any = None

    def __enter__(self) -> LocalPool:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None

    def round(self, jobs: Sequence[Job], todo: list[int], results: dict[int, dict[str, Any]],
              progress: Progress | None, stats: RunStats | None) -> list[int]:
        """Run ``todo``; the indices lost when a worker died (the pool breaks: every job not
        finished yet is lost with it, and the next round starts new processes)."""
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor, as_completed
        from concurrent.futures.process import BrokenProcessPool

        if self._pool is None:
            self._pool = ProcessPoolExecutor(max_workers=self.workers, mp_context=multiprocessing.get_context("fork"),
                                             initializer=fresh_worker)
        lost: list[int] = []
        futures = {self._pool.submit(run_counted, jobs[i]): i for i in todo}
        for fut in as_completed(futures):
            i = futures[fut]
            try:
                result, worker = fut.result()
            except BrokenProcessPool:
                lost.append(i)
                continue
            if stats is not None:
                stats.note(worker)
            results[i] = result
            if progress is not None:
                progress(i, result)
        if lost:
            self.close()
        return sorted(lost)


def run_local(jobs: Sequence[Job], workers: int | None = None, progress: Progress | None = None,
              stats: RunStats | None = None, pool: LocalPool | None = None) -> list[dict[str, Any]]:
    """The jobs on ``pool`` (else a pool of ``workers`` processes, default one per core, for
    these jobs only). A worker that dies breaks the pool: the jobs lost with it run again on
    new processes, as long as each round finishes some; then each remaining job alone on a
    process of its own, so a job that kills its worker is an ``error`` result and no other job
    is lost with it."""
    own = pool is None
    pool = pool or LocalPool(min(workers or default_workers(), max(1, len(jobs))))
    results: dict[int, dict[str, Any]] = {}
    todo = list(range(len(jobs)))
    try:
        while todo:
            lost = pool.round(jobs, todo, results, progress, stats)
            if len(lost) == len(todo):
                break
            todo = lost
    finally:
        if own:
            pool.close()
    for i in [i for i in todo if i not in results]:
        with LocalPool(1) as alone:
            if alone.round(jobs, [i], results, progress, stats):
                results[i] = error_result(jobs[i], f"{jobs[i].id}: its worker process died")
                if progress is not None:
                    progress(i, results[i])
    return [results[i] for i in range(len(jobs))]


def run_dask(jobs: Sequence[Job], address: str, progress: Progress | None = None,
             stats: RunStats | None = None) -> list[dict[str, Any]]:
    """The jobs on the Dask cluster at ``address`` (``tcp://HOST:8786``); synth must be
    installed on its workers. A job whose workers keep dying is an ``error`` result."""
    try:
        from distributed import Client, as_completed
        from distributed.scheduler import KilledWorker
    except ImportError:
        raise SynthError("--cluster needs dask.distributed: pip install 'synth[line]'") from None
    try:
        client = Client(address, timeout="20s")
    except (OSError, TimeoutError, ValueError) as err:
        raise SynthError(f"--cluster {address}: cannot reach the scheduler: {err}") from None
    results: dict[int, dict[str, Any]] = {}
    try:
        futures = {client.submit(run_counted, job, pure=False, key=f"synth-line-{i}-{os.getpid()}-{id(jobs)}"): i
                   for i, job in enumerate(jobs)}
        for fut in as_completed(list(futures)):
            i = futures[fut]
            try:
                result, worker = fut.result()
                if stats is not None:
                    stats.note(worker)
            except KilledWorker:
                result = error_result(jobs[i], f"{jobs[i].id}: the Dask workers running it died")
            results[i] = result
            if progress is not None:
                progress(i, result)
    finally:
        client.close()
    return [results[i] for i in range(len(jobs))]
