"""The texts and JSON of the ``synth filter`` commands: ``check``, ``solve``, ``run``,
``from-rules`` and ``verify`` (the filter computes, this module prints).

Example
-------
>>> from synth.filter.language_check import parse_filter
>>> from synth.filter.solve import synthesis
>>> f = parse_filter('''inputs i1
... outputs O1, O2
... safety K: O1 & O2''', "x.filter")
>>> print(synthesis_text(synthesis(f)), end="")
equation O1 = R_O1
equation O2 = R_O2 & !O1
>>> print(trace_text([TraceRow("initial", "A", "", (), ()), TraceRow("↑s", "A s", "", ("A",), ())]), end="")
0  initial  A
1  ↑s       A s  requests: A  orders: -
"""

from __future__ import annotations

from typing import Any, Sequence

from synth.filter.clusters import clusters
from synth.filter.coherence import Check
from synth.filter.cycle import Algorithm
from synth.filter.from_rules import Classification, Skeleton
from synth.filter.run import Run
from synth.filter.solve import Synthesis
from synth.filter.loop.verification import ANY_CONTROL, INCOHERENT, UNSAFE, FindingKind, TraceRow, Verification
from synth.logic.bdd import cube_text

__all__ = ["FINDINGS", "check_text", "check_json", "synthesis_text", "synthesis_json", "run_text", "run_json",
           "skeleton_text", "trace_text", "verification_text", "verification_json"]

FINDINGS = {
    FindingKind.VIOLATION: "a plant state violates a constraint once the outputs are written",
    FindingKind.EDGE: "an output event breaks an edge constraint",
    FindingKind.REFUSED: "the plant has no controllable event for an output change",
    FindingKind.FALLBACK: "the loop falls back",
    FindingKind.OUTSIDE_CARE: "Y is outside the care set of the algebraic filter",
    FindingKind.TRANSIENT: "a plant state violates a constraint before the PLC writes its outputs",
    FindingKind.OUTSIDE_SUP: "uncontrollable events alone can lead from a state to a violation (it is not in SUP)",
}
"""What each kind of finding of ``verify`` means, as printed."""


# ---------------------------------------------------------------------------- check / solve


def check_text(c: Check) -> str:
    """One line per finding, then GO's edges, then how the equations differ."""
    lines = [f.text() for f in c.coherence.findings]
    lines += [f"GO edge: {e.text()}" for e in c.coherence.go]
    lines += [f"differs: {d}" for d in c.differences]
    return "\n".join(lines) + "\n"


def check_json(file: str, c: Check) -> dict[str, Any]:
    return {"file": file, **c.coherence.as_dict(), "differences": list(c.differences)}


def synthesis_text(s: Synthesis, flat: bool = False) -> str:
    """The chained equations (``flat``: the Y-only ones, in output order), then why the
    synthesis may have failed."""
    lines = [f"equation {o} = {t}" for o, t in (s.equations if flat else s.chained).items()]
    if s.plan is not None:  # too large for equations: the chain the block runs on truth tables
        lines = [f"criterion {i}: {a.text()}" for i, a in enumerate(s.applied, 1)]
    for o, cube in s.free.items():
        lines.append(f"not functional: {o} is free when {cube_text(cube)}")
    if s.inconsistent is not None:
        where = cube_text(s.inconsistent)
        lines.append(f"inconsistent: no safe output vector when {where}"
                     + (f" (wherever {s.inconsistent_text})" if s.inconsistent_text != where else ""))
    return "\n".join(lines) + "\n"


def synthesis_json(file: str, s: Synthesis) -> dict[str, Any]:
    form = {} if s.plan is None else {"form": {"kind": "tables", "bags": len(s.plan.bags), "width": s.plan.width,
                                               "entries": s.plan.entries}}
    return {
        "file": file,
        "functional": s.functional,
        "consistent": s.consistent,
        "equations": dict(s.equations),
        "chained": {"order": list(s.chained), "equations": dict(s.chained)},
        "flat_omitted": list(s.flat_omitted),
        "variable_order": list(s.variable_order),
        "clusters": [list(g) for g in clusters(s.functions.filter)],
        "warnings": s.warnings,
        "notes": list(s.notes),
        "criteria": [{"sense": a.criterion.sense.value, "expression": a.criterion.expr.text(),
                      "origin": a.criterion.origin, "narrows": a.narrows, "effect": a.effect} for a in s.applied],
        "free": {o: {n: int(v) for n, v in c.items()} for o, c in s.free.items()},
        "inconsistent": None if s.inconsistent is None else {
            "counterexample": {n: int(v) for n, v in s.inconsistent.items()},
            "expression": s.inconsistent_text},
        **form,
    }


# ---------------------------------------------------------------------------- run / from-rules


def _bits(v: Sequence[bool]) -> str:
    return "".join("1" if b else "0" for b in v)


def run_text(r: Run) -> str:
    """One line per cycle: the true read-only values, R -> O as bit strings in output
    order, then what happened; the loop's iterations on a second line."""
    cycle, results = r.cycle, r.results
    ys = [n for n in cycle.reads if n not in cycle.requests]
    lines = [f"outputs: {', '.join(cycle.filter.outputs)}   ({cycle.algorithm.value}, {cycle.mode.value})"]
    width = len(str(len(r.rows)))
    for k, (row, res) in enumerate(zip(r.rows, results), 1):
        vals = dict(row.values)
        y = ", ".join(n for n in ys if vals[n])
        line = f"{k:>{width}}  Y: {{{y}}}  R: {_bits(res.requests)} -> O: {_bits(res.outputs)}"
        if res.violated:
            line += "  violated: " + ", ".join(res.violated)
        if res.corrections:
            line += "  corrected: " + ", ".join(res.corrections)
        for flag, word in ((res.fallback, "FALLBACK"), (res.outside_care, "OUTSIDE CARE SET"),
                           (res.blocked, "blocked")):
            if flag:
                line += f"  {word}"
        if res.unsafe:
            line += "  UNSAFE: " + ", ".join(res.unsafe)
        lines.append(line)
        if cycle.algorithm is Algorithm.LOOP:
            lines.append(" " * width + "  iterations: " + " ".join(_bits(si) for si in res.iterations))
    lines.append(f"{len(results)} cycles, {sum(1 for x in results if x.corrections)} corrected, "
                 f"{sum(1 for x in results if x.fallback)} fallback, "
                 f"{sum(1 for x in results if x.outside_care)} outside the care set"
                 + (": coherent" if r.coherent else ""))
    return "\n".join(lines) + "\n"


def run_json(file: str, r: Run) -> dict[str, Any]:
    outs = r.cycle.outputs

    def named(v: Sequence[bool]) -> dict[str, int]:
        return {o: int(b) for o, b in zip(outs, v)}

    return {
        "file": file,
        "trace": r.trace,
        "algorithm": r.cycle.algorithm.value,
        "mode": r.cycle.mode.value,
        "outputs": list(outs),
        "cycles": [{
            "cycle": k, "line": row.line,
            "read": {n: int(v) for n, v in row.values},
            "requests": named(res.requests), "outputs": named(res.outputs),
            "iterations": [named(si) for si in res.iterations],
            "fallback": res.fallback, "violated": list(res.violated), "corrections": list(res.corrections),
            "outside_care": res.outside_care, "unsafe": list(res.unsafe), "blocked": res.blocked,
        } for k, (row, res) in enumerate(zip(r.rows, r.results), 1)],
        "fallbacks": sum(1 for x in r.results if x.fallback),
        "outside_care": sum(1 for x in r.results if x.outside_care),
        "coherent": r.coherent,
    }


_CLASSIFICATION = {Classification.SIMPLE: "CSs", Classification.COMBINED: "CSc (no priority)",
                   Classification.SKIPPED: "skipped: no order"}


def skeleton_text(sk: Skeleton) -> str:
    """One line per rules constraint: how the skeleton takes it, on which outputs."""
    return "".join(f"{c.id}: {_CLASSIFICATION[c.kind]}" + (f" on {', '.join(c.outputs)}" if c.outputs else "") + "\n"
                   for c in sk.constraints)


# ---------------------------------------------------------------------------- verify


def _names(names: Sequence[str]) -> str:
    return ", ".join(names) if names else "-"


def trace_text(rows: Sequence[TraceRow]) -> str:
    """A trace in the layout of ``synth run``: number, event, plant state (and the
    situation), then the requests and the orders written."""
    w_event = max(len(r.event) for r in rows)
    w_state = max(len(r.state) for r in rows)
    w_sit = max(len(r.situation) for r in rows)
    out = []
    for i, r in enumerate(rows):
        line = f"{i:<3}{r.event:<{w_event}}  {r.state:<{w_state}}"
        if w_sit:
            line += f"  {r.situation:<{w_sit}}"
        if i and r.ran:
            line += f"  requests: {_names(r.requests)}  orders: {_names(r.orders)}"
        if r.note:
            line += f"   {r.note}"
        out.append(line.rstrip() + "\n")
    return "".join(out)


def verification_text(v: Verification) -> str:
    lines = [f"closed loop: {v.filter} on {v.plant}, requests from {v.source} "
             f"({v.algorithm.value}, {v.mode.value}, {'atomic outputs' if v.atomic else 'ordered outputs'})",
             f"explored {v.states} states ({v.plant_states} plant states), {v.cycles} cycles"
             f" in {v.seconds:.2f} s" + ("" if v.complete else " -- STOPPED at the state limit")]
    for kind in UNSAFE:
        if kind in v.findings:
            fd = v.findings[kind]
            lines.append(f"unsafe: {FINDINGS[kind]} ({fd.count} plant states)"
                         + (f": {', '.join(fd.constraints)}" if fd.constraints else ""))
    if v.safe:
        lines.append("safe: no constraint is violated once the outputs are written"
                     + ("" if v.complete else " (in the explored part)"))
    if FindingKind.TRANSIENT in v.findings:
        fd = v.findings[FindingKind.TRANSIENT]
        lines.append(f"{'unsafe' if v.strict else 'transient'}: {fd.count} plant states violate a constraint "
                     "between the plant's event and the end of the write"
                     + (f" ({', '.join(fd.constraints)})" if fd.constraints else ""))
    if FindingKind.OUTSIDE_SUP not in v.findings:
        lines.append(f"outside SUP: {v.outside_sup} explored plant states can reach a violation by "
                     "uncontrollable events alone")
    for kind in INCOHERENT:
        if kind in v.findings:
            lines.append(f"incoherent: {FINDINGS[kind]} ({v.findings[kind].count} plant states)")
    if v.coherent:
        lines.append("coherent: " + ("the loop never falls back" if v.algorithm is Algorithm.LOOP
                                     else "Y never leaves the care set"))
    if v.source != ANY_CONTROL:
        lines.append(f"transparency: {v.corrected} of {v.cycles} cycles correct the requests, "
                     f"largest Hamming distance {v.max_distance}")
    for kind in FindingKind:
        if kind in v.findings:
            lines.append(f"\nshortest trace ({FINDINGS[kind]}):")
            lines.append(trace_text(v.findings[kind].trace).rstrip("\n"))
    return "\n".join(lines) + "\n"


def verification_json(v: Verification) -> dict[str, Any]:
    return {
        "filter": v.filter, "plant": v.plant, "source": v.source, "algorithm": v.algorithm.value,
        "mode": v.mode.value, "atomic_outputs": v.atomic, "strict": v.strict,
        "safe": v.safe, "coherent": v.coherent, "complete": v.complete,
        "states": v.states, "plant_states": v.plant_states, "cycles": v.cycles, "outside_sup": v.outside_sup,
        "corrected": v.corrected, "max_distance": v.max_distance, "seconds": round(v.seconds, 3),
        "findings": {str(k): {"count": f.count, "constraints": list(f.constraints), "trace": [
            {"event": r.event, "state": r.state, "situation": r.situation, "requests": list(r.requests),
             "orders": list(r.orders), "note": r.note, "plc_ran": r.ran} for r in f.trace]}
                     for k, f in v.findings.items()},
    }
