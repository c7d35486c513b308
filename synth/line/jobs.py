"""The jobs of a line: one per check of a station (``validate`` of each Grafcet and
variant, ``filter check``, ``filter verify``, ``st --check``) and one per mutant with
``--mutate``. A job is plain frozen data (it travels to worker processes and Dask workers);
it names every file it reads, and its cache key is their contents' hash with synth's
version and the job's options (:mod:`synth.line.cache`).

Example
-------
>>> j = Job("press", JobKind.VALIDATE, "validate g.g7", plant="p.rules", grafcet="g.g7")
>>> j.id, j.files
('press/validate g.g7', ('p.rules', 'g.g7'))
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path

from synth.line.project import Check, Expect, Line, Station

__all__ = ["JobKind", "Job", "station_jobs", "line_jobs", "station_options", "files_read", "MUTANT_STATUSES"]


class JobKind(StrEnum):
    """What a job runs."""

    VALIDATE = "validate"
    FILTER_CHECK = "filter check"
    FILTER_VERIFY = "filter verify"
    ST_CHECK = "st --check"
    MUTANT = "mutant"


MUTANT_STATUSES = ("caught", "survived", "equivalent")
"""What a mutant job finds: the plant catches it, lets it pass, or it behaves as the original (equal ASS)."""


@dataclass(frozen=True)
class Job:
    """One independent unit of work. ``options`` are (name, value) pairs of the check's options;
    ``mutant`` the mutant's id for a mutant job (of ``grafcet``, or of ``filter`` when the id
    starts with ``drop-term``); ``digests`` pairs each of :attr:`files` with the hash of its
    contents and of the files it uses (set by :func:`synth.line.cache.with_digests`)."""

    station: str
    kind: JobKind
    name: str
    plant: str | None = None
    grafcet: str | None = None
    filter: str | None = None
    options: tuple[tuple[str, str], ...] = ()
    expect: Expect | None = Expect.PASS
    mutant: str | None = None
    digests: tuple[tuple[str, str], ...] = ()

    @property
    def id(self) -> str:
        return f"{self.station}/{self.name}"

    @property
    def files(self) -> tuple[str, ...]:
        """The files the job names (plant, Grafcet, filter); :func:`files_read` adds what they use."""
        return tuple(f for f in (self.plant, self.grafcet, self.filter) if f is not None)

    def option(self, name: str, default: str = "") -> str:
        return dict(self.options).get(name, default)

    @property
    def plant_digest(self) -> str:
        """The hash of the plant and the files it uses: a worker's compiled plant is keyed by it."""
        return dict(self.digests).get(self.plant or "", "")


def station_options(s: Station) -> tuple[tuple[str, str], ...]:
    """The validation options of a station's jobs."""
    return (("semantics", s.semantics), ("engine", s.engine), ("homes", "\n".join(s.homes)),
            ("expert", str(s.expert).lower())) + ((("max_states", str(s.max_states)),) if s.max_states else ())


def station_jobs(s: Station, reports: bool = False) -> list[Job]:
    """The jobs of one station, in a fixed order: its checks as listed, each on its Grafcets in
    file order, then its variants; with ``reports`` each validation also renders its full
    HTML report (explicit engine)."""
    plant, options = str(s.plant), station_options(s) + ((("report", "true"),) if reports else ())
    jobs: list[Job] = []
    for check in s.checks:
        if check is Check.VALIDATE:
            jobs += [Job(s.name, JobKind.VALIDATE, f"validate {g.name}", plant, str(g), None, options, s.expect)
                     for g in s.grafcets]
        elif check is Check.FILTER_CHECK:
            jobs.append(Job(s.name, JobKind.FILTER_CHECK, f"filter check {s.filter.name if s.filter else ''}",
                            None, None, str(s.filter), (), s.expect))
        elif check is Check.FILTER_VERIFY:
            jobs.append(Job(s.name, JobKind.FILTER_VERIFY, f"filter verify {s.filter.name if s.filter else ''}",
                            plant, None, str(s.filter), (("control", "any"),), s.expect))
        elif check is Check.ST_CHECK:
            jobs += [Job(s.name, JobKind.ST_CHECK, f"st --check {g.name}", plant, str(g), None,
                         (("semantics", s.semantics), ("depth", str(s.depth))), s.expect) for g in s.grafcets]
    for v in s.variants:
        homes = s.homes if v.homes is None else v.homes
        jobs.append(Job(s.name, JobKind.VALIDATE, f"variant {v.name}", str(v.plant), str(v.grafcet), None,
                        tuple((k, "\n".join(homes) if k == "homes" else x) for k, x in options), v.expect))
    return jobs


def line_jobs(line: Line, reports: bool = False) -> list[Job]:
    """Every station's jobs, stations in file order."""
    return [j for s in line.stations for j in station_jobs(s, reports)]


_USE = re.compile(r'^\s*use\s+"([^"]+)"', re.M)


def files_read(path: str) -> list[str]:
    """``path`` and every file its ``use`` lines name, transitively (as the readers resolve them:
    beside the file, else the element library), in a fixed order; unreadable ones are skipped
    (the job itself reports them)."""
    from synth.plant.library import library_file

    out: list[str] = []
    todo = [Path(path)]
    while todo:
        p = todo.pop(0)
        if str(p) in out:
            continue
        out.append(str(p))
        try:
            text = p.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            continue
        todo += [library_file(u, p.parent) for u in _USE.findall(text)]
    return out
