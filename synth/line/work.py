"""Running one job, in whatever process it lands: the local pool's workers, a Dask worker,
or the command itself. Each process compiles a plant once (keyed by the hash of its files)
and validates every Grafcet and mutant of its jobs against it; :data:`COMPILED` counts the
compilations, so the pool and the benchmark can show "once per worker".

A result is JSON-ready data (the same whether computed or read from the cache): the job,
its verdict (``pass``, ``fail``, or ``error`` for bad input, a limit reached or a dead
worker), a one-line summary, the command's text, the findings as a
:class:`~synth.output.ci.CiReport`, and for a mutant its status.
"""

from __future__ import annotations

import dataclasses
import json
import os
from typing import TYPE_CHECKING, Any

from synth.errors import InputError, InputErrors, LimitExceeded, SynthError
from synth.line.jobs import Job, JobKind

if TYPE_CHECKING:  # pragma: no cover
    from synth.grafcet.language import Grafcet
    from synth.output.ci import CiReport
    from synth.plant.composition import Plant
    from synth.plant.rules import RuleSet

__all__ = ["COMPILED", "fresh_worker", "compiled_plant", "run_job", "run_counted", "error_result", "ci_report_of"]

COMPILED: list[str] = []
"""The plants this process compiled (path and digest), in order: one entry per compilation."""

_PLANTS: dict[tuple[str, str], tuple[RuleSet, Plant]] = {}
_ASS: dict[tuple[str, str, str, str], Any] = {}


def fresh_worker() -> None:
    """A worker process's start: nothing compiled yet (a forked worker forgets its parent's plants)."""
    COMPILED.clear()
    _PLANTS.clear()
    _ASS.clear()


def compiled_plant(path: str, digest: str) -> tuple[RuleSet, Plant]:
    """The rules and plant of ``path``, compiled once per process and digest."""
    key = (path, digest)
    if key not in _PLANTS:
        from synth.plant.composition import plant
        from synth.plant.rules_check import load_rules

        rs = load_rules(path)
        _PLANTS[key] = (rs, plant(rs))
        COMPILED.append(f"{path}@{digest[:12]}")
    return _PLANTS[key]


def _grafcet(job: Job) -> tuple[RuleSet, Plant, Grafcet]:
    from synth.grafcet.language_check import load_grafcet

    assert job.plant is not None and job.grafcet is not None
    rs, p = compiled_plant(job.plant, job.plant_digest)
    return rs, p, load_grafcet(job.grafcet, inputs=p.inputs, outputs=p.outputs, semantics=job.option("semantics", "grafcet"))


def _validate(job: Job, rs: RuleSet, p: Plant, g: Grafcet) -> Any:
    from synth.line.engine import validate_model

    homes = tuple(h for h in job.option("homes").split("\n") if h)
    budget = int(job.option("max_states")) if job.option("max_states") else None
    return validate_model(rs, p, g, engine=job.option("engine", "auto"), expert=job.option("expert") == "true", homes=homes,
                          max_states=budget, needs_listing=job.option("report") == "true")


def _result(job: Job, verdict: str, summary: str, text: str, report: CiReport | None,
            mutant: dict[str, Any] | None = None, html: str | None = None) -> dict[str, Any]:
    data = {"id": job.id, "station": job.station, "kind": str(job.kind), "name": job.name,
            "expect": None if job.expect is None else str(job.expect), "verdict": verdict, "summary": summary,
            "text": text, "report": None if report is None else dataclasses.asdict(report), "mutant": mutant,
            "html": html}
    return json.loads(json.dumps(data))  # plain JSON types: a computed result equals a cached one


def error_result(job: Job, message: str) -> dict[str, Any]:
    """The result of a job that could not run (bad input, a limit, a dead worker)."""
    mutant = {"id": job.mutant, "operator": "", "description": "", "status": "error", "why": message,
              "file": None, "line": 1, "column": 1}
    return _result(job, "error", message.splitlines()[0] if message else "error", message, None,
                   mutant if job.mutant else None)


def ci_report_of(data: dict[str, Any]) -> CiReport:
    """A result's findings back as a :class:`CiReport`."""
    from synth.output.ci import CiFinding, CiReport, Level, Verdict

    findings = tuple(CiFinding(f["rule"], Level(f["level"]), f["message"], f["file"], f["line"], f["column"],
                               tuple(f["trace"])) for f in data["findings"])
    return CiReport(data["command"], data["target"], Verdict(data["verdict"]), findings)


def _first(text: str) -> str:
    return text.strip().splitlines()[0] if text.strip() else ""


def _run(job: Job) -> dict[str, Any]:
    if job.kind is JobKind.VALIDATE:
        from synth.output.ci import validation_report
        from synth.output.result import validation_text

        v = _validate(job, *_grafcet(job))
        text = validation_text(v)
        html = None
        if job.option("report") == "true":
            from synth.output.html import report_html

            html = report_html(v)
        return _result(job, "pass" if v.passed else "fail", _first(text), text, validation_report(v), html=html)
    if job.kind is JobKind.ST_CHECK:
        from synth.codegen.check import differential_check
        from synth.output.ci import st_check_report

        rs, _, g = _grafcet(job)
        initial = {v.name: v.initial for v in rs.variables if v.is_input}
        report = differential_check(g, {n: initial.get(n, False) for n in g.inputs}, depth=int(job.option("depth", "2")))
        return _result(job, "pass" if report.ok else "fail", _first(report.text()), report.text(), st_check_report(g, report))
    from synth.filter.language_check import load_filter

    assert job.filter is not None
    f = load_filter(job.filter)
    if job.kind is JobKind.FILTER_CHECK:
        from synth.filter.coherence import check
        from synth.output.ci import filter_check_report
        from synth.output.filter_text import check_text

        c = check(f)
        text = check_text(c)
        summary = f"{'holds' if c.holds else 'fails'}: {sum(not x.holds for x in c.coherence.findings)} property(ies) violated"
        return _result(job, "pass" if c.holds else "fail", summary, text, filter_check_report(f, c))
    if job.kind is JobKind.FILTER_VERIFY:
        from synth.filter.loop.verify import verify
        from synth.output.ci import filter_verify_report
        from synth.output.filter_text import verification_text

        assert job.plant is not None
        v = verify(f, job.plant, any_control=True)
        text = verification_text(v).replace(f" in {v.seconds:.2f} s", "", 1)  # the same result wherever it ran
        if not v.complete:
            return error_result(job, "stopped: the closed loop has more states than the exploration's limit\n" + text)
        return _result(job, "pass" if v.safe and v.coherent else "fail", _first(text), text, filter_verify_report(f, v))
    return _mutant(job, f)


def _ass_key(rs: RuleSet, p: Plant, g: Grafcet) -> Any:
    """The ASS of ``g`` on the plant's admissible inputs from its initial ones, as comparable data."""
    from synth.grafcet.ass import stable_situation_automaton
    from synth.grafcet.machine import GrafcetMachine

    initial = {v.name: v.initial for v in rs.variables if v.is_input}
    ass = stable_situation_automaton(GrafcetMachine(g), initial_inputs={n: initial.get(n, False) for n in g.inputs},
                                     admissible=p.admissible_inputs())
    return (tuple((s.situation.text(), s.orders, s.conditional) for s in ass.states),
            tuple((t.source, str(t.event), t.condition, t.target) for t in ass.transitions))


def mutant_status(job: Job, rs: RuleSet, p: Plant, g: Grafcet, mutated: Grafcet) -> tuple[str, str]:
    """``equivalent`` (the mutant's ASS equals the original's), ``caught`` (its validation
    fails, or synth refuses it) or ``survived``, with a sentence."""
    key = (job.grafcet or "", dict(job.digests).get(job.grafcet or "", ""), job.option("semantics"), job.plant_digest)
    try:
        if key not in _ASS:
            _ASS[key] = _ass_key(rs, p, g)
        if _ass_key(rs, p, mutated) == _ASS[key]:
            return "equivalent", "the same stable situations and transitions as the original (equal ASS)"
    except SynthError:  # no ASS to compare (a limit, a Grafcet that never stabilises): validation judges
        pass
    try:
        v = _validate(job, rs, p, mutated)
    except LimitExceeded:
        raise
    except SynthError as err:  # the original passes: synth refuses the mutant (it never stabilises, ...)
        return "caught", "refused: " + _first(err.render() if isinstance(err, (InputError, InputErrors)) else str(err))
    if v.passed:
        return "survived", "the mutant passes validation: the plant model and its constraints do not tell it apart"
    from synth.output.result import validation_text

    return "caught", _first(validation_text(v))


def _mutant(job: Job, f: Any) -> dict[str, Any]:
    from synth.line.mutate import filter_mutants

    assert job.mutant is not None
    if f is not None:
        from synth.filter.coherence import check

        found = dict((m.id, (m, model)) for m, model in filter_mutants(f))
        if job.mutant not in found:
            return error_result(job, f"no mutant {job.mutant!r} of {job.filter}")
        m, model = found[job.mutant]
        before, after = check(f), check(model)
        caught = (after.holds, after.differences) != (before.holds, before.differences)
        status, why = ("caught", "filter check finds it") if caught else ("survived", "filter check sees no difference")
    else:
        from synth.line.mutate import grafcet_mutants

        rs, p, g = _grafcet(job)
        found_g = dict((m.id, (m, model)) for m, model in grafcet_mutants(g))
        if job.mutant not in found_g:
            return error_result(job, f"no mutant {job.mutant!r} of {job.grafcet}")
        m, mutated = found_g[job.mutant]
        status, why = mutant_status(job, rs, p, g, mutated)
    loc = m.loc
    data = {"id": m.id, "operator": str(m.operator), "description": m.description, "status": status, "why": why,
            "file": loc.file if loc else (job.grafcet or job.filter), "line": loc.line if loc else 1,
            "column": loc.column if loc else 1}
    return _result(job, "fail" if status == "caught" else "pass", f"{status}: {m.description}", why, None, data)


def run_job(job: Job) -> dict[str, Any]:
    """Run ``job``; bad input, a limit, or files that are not those the job was planned on
    (a worker on another machine) are an ``error`` result, never an exception."""
    from synth.line.cache import digest

    changed = [f for f, d in job.digests if digest(f) != d]
    if changed:  # a cluster's worker that sees other files than the command did
        return error_result(job, f"{job.id}: {', '.join(changed)} differs where the job runs from where it was planned")
    try:
        if job.kind is JobKind.MUTANT and job.filter is None:
            return _mutant(job, None)
        return _run(job)
    except (InputError, InputErrors) as err:
        return error_result(job, err.render())
    except LimitExceeded as err:
        return error_result(job, f"stopped: {err}")
    except SynthError as err:
        return error_result(job, f"error: {err}")
    except MemoryError:
        return error_result(job, "stopped: out of memory")


def run_counted(job: Job) -> tuple[dict[str, Any], tuple[int, int]]:
    """:func:`run_job`, with this process's id and its number of plant compilations so far."""
    result = run_job(job)
    return result, (os.getpid(), len(COMPILED))
