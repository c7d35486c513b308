"""What ``synth commission`` prints and writes: the text, the JSON (its schema in
``synth/output/schemas/commission.json``), and the CI report (JUnit, SARIF) — renders only.
"""

from __future__ import annotations

from typing import Any

from synth.commission.loop import Outcome, Walk
from synth.commission.run import CommissionResult, FaultRun
from synth.output.ci import CiReport, Level, Verdict, located

__all__ = ["result_json", "result_text", "ci_report"]


def _walk_json(w: Walk) -> dict[str, Any]:
    return {"walk": w.index, "seed": w.seed, "outcome": w.outcome.value, "message": w.message,
            "details": list(w.details), "trace": list(w.trace), "steps": [s.as_dict() for s in w.steps]}


def _run_json(r: FaultRun) -> dict[str, Any]:
    return {"fault": r.fault.text if r.fault else None, "fault_kind": r.fault.kind.value if r.fault else None,
            "survived": not r.failed, "walks": [_walk_json(w) for w in r.walks]}


def result_json(res: CommissionResult) -> dict[str, Any]:
    """The run as JSON: verdict, protocol and timing, one entry per fault run, coverage."""
    return {
        "target": res.target,
        "verdict": "pass" if res.ok else "fail",
        "protocol": res.protocol,
        "timing": res.timing,
        "steps": res.steps,
        "seconds": round(res.seconds, 3),
        "runs": [_run_json(r) for r in res.runs],
        "coverage": res.coverage.as_dict() if res.coverage else None,
    }


def _walk_lines(w: Walk) -> list[str]:
    lines = [f"  walk {w.index}{'' if w.seed is None else f' (seed {w.seed})'}: {w.outcome}"
             + (f": {w.message}" if w.message else f", {len(w.steps) - 1} steps")]
    if w.outcome is not Outcome.PASS:
        lines.append(f"    trace: {' '.join(w.trace) or '(initial)'}")
        last = w.steps[-1]
        lines.append(f"    last: steps {{{', '.join('X' + s for s in last.steps)}}}, PLC orders "
                     f"{{{', '.join(last.orders)}}}, plant {last.plant}, {last.scans} scans")
        lines += [f"    {d}" for d in w.details]
    return lines


def result_text(res: CommissionResult) -> str:
    """The terminal summary: the verdict, each run and walk, the coverage."""
    n_walks = sum(len(r.walks) for r in res.runs)
    rate = res.steps / res.seconds if res.seconds > 0 else 0.0
    lines = [f"{'PASS' if res.ok else 'FAIL'}: {res.target} over {res.protocol} ({res.timing}): {n_walks} walk(s), "
             f"{res.steps} closed-loop steps in {res.seconds:.2f} s ({rate:.0f} steps/s)"]
    for r in res.runs:
        if r.fault is not None:
            lines.append(f"fault {r.fault.text} ({r.fault.kind}): {'survived' if not r.failed else 'NOT survived'}")
        else:
            lines.append("the machine as modelled:")
        for w in r.walks:
            lines += _walk_lines(w)
    if res.coverage is not None:
        c = res.coverage
        lines.append(f"coverage: plant transitions {len(c.transitions_seen)}/{len(c.transitions)}, "
                     f"Grafcet steps {len(c.steps_seen)}/{len(c.steps)} (reachable under the Grafcet)")
        lines += [f"  not seen: {t}" for t in c.transitions if t not in c.transitions_seen]
        lines += [f"  step never active: X{s}" for s in c.steps if s not in c.steps_seen]
    return "\n".join(lines) + "\n"


def ci_report(res: CommissionResult) -> CiReport:
    """One finding per walk that did not pass (an error where it fails the run, a warning for a
    walk a fault blocked), with its closed-loop trace."""
    findings = []
    for r in res.runs:
        failing = set(id(w) for w in r.failed)
        for w in r.walks:
            if w.outcome is Outcome.PASS:
                continue
            where = f" under fault {r.fault.text}" if r.fault else ""
            findings.append(located(w.outcome.value, Level.ERROR if id(w) in failing else Level.WARNING,
                                    f"walk {w.index}{where}: {w.message}", None, res.target, w.trace))
    return CiReport("commission", res.target, Verdict.PASS if res.ok else Verdict.FAIL, tuple(findings))
