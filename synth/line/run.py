"""``synth check``: every station's jobs, from the cache or run (serial, local pool or Dask),
then with ``--mutate`` the mutants of every station's Grafcets that pass (and of its
filter's equations); each station judged against its expectation.

A station meets its expectation when its checks reach the station's ``expect`` (``pass``:
every check passes; ``fail``: at least one fails), every variant reaches its own, no job
ended in an error, and with ``--mutate`` no mutant survives that its ``allow_survivors``
does not list.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

from synth.errors import SynthError
from synth.line.cache import Cache, with_digests
from synth.line.jobs import Job, JobKind, line_jobs, station_options
from synth.line.project import Expect, Line, Station
from synth.line.runners import LocalPool, RunStats, run_dask, run_local, run_serial

__all__ = ["LineRun", "StationVerdict", "check_line", "mutant_jobs", "grafcet_mutant_jobs", "filter_mutant_jobs", "run_jobs"]


@dataclass(frozen=True)
class StationVerdict:
    """One station's outcome: whether it met its expectation, and why not."""

    name: str
    expect: Expect
    met: bool
    jobs: int
    failed: int
    errors: int
    caught: int = 0
    changing: int = 0
    equivalent: int = 0
    survivors: tuple[str, ...] = ()
    unexpected_survivors: tuple[str, ...] = ()
    reasons: tuple[str, ...] = ()

    @property
    def score(self) -> float | None:
        """Mutants caught / mutants that change behaviour (None without mutants)."""
        return self.caught / self.changing if self.changing else None


@dataclass
class LineRun:
    """A run of the line: results in job order, what was computed and what came from the cache."""

    line: Line
    results: list[dict[str, Any]]
    computed: int
    cached: int
    stats: RunStats = field(default_factory=RunStats)
    mutated: bool = False

    def station(self, s: Station) -> StationVerdict:
        mine = [r for r in self.results if r["station"] == s.name]
        checks = [r for r in mine if r["kind"] != str(JobKind.MUTANT) and not r["name"].startswith("variant ")]
        variants = [r for r in mine if r["name"].startswith("variant ")]
        mutants = [r for r in mine if r["kind"] == str(JobKind.MUTANT)]
        errors = [r for r in mine if r["verdict"] == "error"]
        reasons = [f"{r['name']}: {r['summary']}" for r in errors]
        failed = any(r["verdict"] == "fail" for r in checks)
        if checks and failed != (s.expect is Expect.FAIL):
            reasons.append(f"expected {s.expect}, the checks {'fail' if failed else 'pass'}")
        reasons += [f"{r['name']}: expected {r['expect']}, got {r['verdict']}" for r in variants
                    if r["verdict"] != "error" and r["verdict"] != r["expect"]]
        status = {r["name"].removeprefix("mutant "): r["mutant"]["status"] for r in mutants}
        survivors = tuple(i for i, st in status.items() if st == "survived")
        unexpected = tuple(i for i in survivors if i not in s.allow_survivors and i.split(" ", 1)[-1] not in s.allow_survivors)
        if unexpected:
            reasons.append(f"{len(unexpected)} mutant(s) survive that allow_survivors does not list")
        caught = sum(st == "caught" for st in status.values())
        return StationVerdict(s.name, s.expect, not reasons, len(mine), sum(r["verdict"] == "fail" for r in checks + variants),
                              len(errors), caught, caught + len(survivors),
                              sum(st == "equivalent" for st in status.values()), survivors, unexpected, tuple(reasons))

    def verdicts(self) -> list[StationVerdict]:
        return [self.station(s) for s in self.line.stations]

    @property
    def exit_code(self) -> int:
        """0 every station meets its expectation, 2 a job could not run (bad input, a limit), 1 otherwise."""
        verdicts = self.verdicts()
        if any(v.errors for v in verdicts):
            return 2
        return 0 if all(v.met for v in verdicts) else 1


def run_jobs(jobs: list[Job], cache: Cache | None, *, workers: int | None = None, cluster: str | None = None,
             progress: Callable[[Job, dict[str, Any], bool], None] | None = None,
             stats: RunStats | None = None, pool: LocalPool | None = None) -> tuple[list[dict[str, Any]], int]:
    """The results of ``jobs`` (in order): cached ones read, the others run and stored (errors
    are not stored: a dead worker or a limit may not happen again); and how many were run."""
    jobs = [with_digests(j) for j in jobs]
    results: list[dict[str, Any] | None] = [cache.get(j) if cache is not None else None for j in jobs]
    if progress is not None:
        for j, r in zip(jobs, results):
            if r is not None:
                progress(j, r, True)
    todo = [i for i, r in enumerate(results) if r is None]
    pending = [jobs[i] for i in todo]

    def done(k: int, result: dict[str, Any]) -> None:
        if progress is not None:
            progress(pending[k], result, False)

    if not pending:
        fresh: list[dict[str, Any]] = []
    elif cluster:
        fresh = run_dask(pending, cluster, done, stats)
    elif workers == 1 or len(pending) == 1:
        fresh = run_serial(pending, done, stats)
    else:
        fresh = run_local(pending, workers, done, stats, pool)
    for i, r in zip(todo, fresh):
        results[i] = r
        if cache is not None and r["verdict"] != "error":
            cache.put(jobs[i], r)
    return [r for r in results if r is not None], len(todo)


def grafcet_mutant_jobs(station: str, plant: str, grafcet: str, options: tuple[tuple[str, str], ...]) -> list[Job]:
    """One job per mutant of ``grafcet`` (read against ``plant``'s names)."""
    from pathlib import Path

    from synth.grafcet.language_check import load_grafcet
    from synth.line.mutate import grafcet_mutants
    from synth.plant.rules_check import load_rules

    rs = load_rules(plant)
    g = load_grafcet(grafcet, inputs=rs.inputs, outputs=rs.outputs, semantics=dict(options).get("semantics", "grafcet"))
    return [Job(station, JobKind.MUTANT, f"mutant {Path(grafcet).name} {m.id}", plant, grafcet, None, options, None, m.id)
            for m, _ in grafcet_mutants(g)]


def filter_mutant_jobs(station: str, filter_path: str) -> list[Job]:
    """One job per mutant of the filter's equations."""
    from pathlib import Path

    from synth.filter.language_check import load_filter
    from synth.line.mutate import filter_mutants

    return [Job(station, JobKind.MUTANT, f"mutant {Path(filter_path).name} {m.id}", None, None, filter_path, (), None, m.id)
            for m, _ in filter_mutants(load_filter(filter_path))]


def mutant_jobs(line: Line, results: list[dict[str, Any]]) -> list[Job]:
    """One job per mutant of each station's Grafcets whose validation passed (a Grafcet that
    fails already says the plant catches something), and of its filter's equations."""
    passed = {(r["station"], r["name"]) for r in results if r["kind"] == str(JobKind.VALIDATE) and r["verdict"] == "pass"}
    out: list[Job] = []
    for s in line.stations:
        for g in s.grafcets:
            if (s.name, f"validate {g.name}") in passed:
                out += grafcet_mutant_jobs(s.name, str(s.plant), str(g), station_options(s))
        if s.filter is not None:
            try:
                out += filter_mutant_jobs(s.name, str(s.filter))
            except SynthError:  # the station's filter check reports it as its error
                pass
    return out


def check_line(line: Line, cache: Cache | None, *, mutate: bool = False, workers: int | None = None,
               cluster: str | None = None, progress: Callable[[Job, dict[str, Any], bool], None] | None = None,
               reports: bool = False) -> LineRun:
    """Run the line (see the module docstring); ``reports``: each validation also renders its
    full HTML report."""
    stats = RunStats()
    local = None if cluster or workers == 1 else LocalPool(workers)
    try:
        results, computed = run_jobs(line_jobs(line, reports), cache, workers=workers, cluster=cluster, progress=progress,
                                     stats=stats, pool=local)
        total = len(results)
        if mutate:
            more, ran = run_jobs(mutant_jobs(line, results), cache, workers=workers, cluster=cluster,
                                 progress=progress, stats=stats, pool=local)
            results += more
            computed += ran
            total += len(more)
    finally:
        if local is not None:
            local.close()
    return LineRun(line, results, computed, total - computed, stats, mutate)
