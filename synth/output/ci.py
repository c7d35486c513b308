"""Results for CI servers: JUnit XML (Jenkins, GitLab) and SARIF 2.1.0 (GitHub code
scanning, most static-analysis dashboards) of a synth command's findings.

A command turns its result into a :class:`CiReport` (one :class:`CiFinding` per
blocking situation, prohibited order, failed property or mismatch, each located at
``file:line:col`` with its trace); the two writers render it, text only (the command
writes the file atomically, as every output).

Example
-------
>>> r = CiReport("validate", "g.g7", Verdict.FAIL, (CiFinding("missing_order", Level.ERROR,
...     "missing order AVANCER2 in step 103", "g.g7", 12, 5, ("↑dcy", "↑cp12")),))
>>> print(junit_xml([r]).splitlines()[1])
<testsuites name="synth" tests="1" failures="1" errors="0">
>>> sarif_json([r])["runs"][0]["results"][0]["locations"][0]["physicalLocation"]["region"]
{'startLine': 12, 'startColumn': 5}
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import TYPE_CHECKING, Any, Sequence
from xml.sax.saxutils import escape, quoteattr

from synth.version import version

if TYPE_CHECKING:  # pragma: no cover
    from synth.errors import Location
    from synth.filter.coherence import Check
    from synth.filter.language import Filter
    from synth.filter.loop.verification import Verification
    from synth.codegen.check import DifferentialReport
    from synth.grafcet.language import Grafcet
    from synth.validation.result import Validation

__all__ = ["Level", "Verdict", "CiFinding", "CiReport", "junit_xml", "sarif_json", "SARIF_SCHEMA",
           "filter_check_report", "filter_verify_report", "validation_report", "st_check_report", "located",
           "write_ci"]

SARIF_SCHEMA = "https://docs.oasis-open.org/sarif/sarif/v2.1.0/errata01/os/schemas/sarif-schema-2.1.0.json"


class Level(StrEnum):
    """How a finding fails the run (SARIF's levels): an error fails it, a warning or a note does not."""

    ERROR = "error"
    WARNING = "warning"
    NOTE = "note"


class Verdict(StrEnum):
    """The command's verdict: its exit code 0 (pass) or 1 (fail)."""

    PASS = "pass"
    FAIL = "fail"


@dataclass(frozen=True)
class CiFinding:
    """One finding: a rule id (the diagnosis or property), its level, a sentence, where it
    is in the user's file (1-based line and column), and the events that lead to it."""

    rule: str
    level: Level
    message: str
    file: str
    line: int = 1
    column: int = 1
    trace: tuple[str, ...] = ()


@dataclass(frozen=True)
class CiReport:
    """One command run on one file: ``synth validate g.g7`` and what it found."""

    command: str
    target: str
    verdict: Verdict
    findings: tuple[CiFinding, ...]


def _where(f: CiFinding) -> str:
    return f"{f.file}:{f.line}:{f.column}"


def junit_xml(reports: Sequence[CiReport]) -> str:
    """JUnit XML: one ``<testsuite>`` per report, one ``<testcase>`` per finding (a
    ``<failure>`` for an error, passed with the finding in ``<system-out>`` otherwise);
    a report without findings is one passing test case named after its verdict."""
    suites = []
    total = failures = 0
    for r in reports:
        cases = []
        suite_failures = 0
        for i, f in enumerate(r.findings, 1):
            name = f"{i}: {f.rule} at {_where(f)}"
            body = f"{_where(f)}: {f.level}: {f.message}"
            if f.trace:
                body += "\ntrace: " + " ".join(f.trace)
            attrs = f'classname={quoteattr("synth." + r.command.replace(" ", "."))} name={quoteattr(name)} file={quoteattr(f.file)} line="{f.line}"'
            if f.level == Level.ERROR:
                suite_failures += 1
                cases.append(f"    <testcase {attrs}>\n      <failure message={quoteattr(f.message)} "
                             f"type={quoteattr(f.rule)}>{escape(body)}</failure>\n    </testcase>")
            else:
                cases.append(f"    <testcase {attrs}>\n      <system-out>{escape(body)}</system-out>\n    </testcase>")
        if not r.findings:
            cases.append(f'    <testcase classname={quoteattr("synth." + r.command.replace(" ", "."))} '
                         f'name={quoteattr(f"{r.target}: {r.verdict}")} file={quoteattr(r.target)}/>')
        total += len(cases)
        failures += suite_failures
        suites.append(f'  <testsuite name={quoteattr(f"synth {r.command} {r.target}")} tests="{len(cases)}" '
                      f'failures="{suite_failures}" errors="0" skipped="0">\n' + "\n".join(cases) + "\n  </testsuite>")
    head = f'<testsuites name="synth" tests="{total}" failures="{failures}" errors="0">'
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + head + "\n" + "\n".join(suites) + "\n</testsuites>\n"


def sarif_json(reports: Sequence[CiReport]) -> dict[str, Any]:
    """A SARIF 2.1.0 log: one run of the ``synth`` tool, one result per finding with its
    physical location and, when it has one, its trace as a code flow (one step per event)."""
    rules: dict[str, dict[str, Any]] = {}
    results = []
    for r in reports:
        for f in r.findings:
            rules.setdefault(f.rule, {"id": f.rule, "shortDescription": {"text": f.rule.replace("_", " ")}})
            result: dict[str, Any] = {
                "ruleId": f.rule,
                "level": str(f.level),
                "message": {"text": f.message},
                "locations": [{"physicalLocation": {"artifactLocation": {"uri": f.file},
                                                    "region": {"startLine": f.line, "startColumn": f.column}}}],
                "properties": {"command": r.command, "verdict": str(r.verdict)},
            }
            if f.trace:
                steps = [{"location": {"message": {"text": e}}} for e in f.trace]
                result["codeFlows"] = [{"threadFlows": [{"locations": steps}]}]
            results.append(result)
    return {
        "$schema": SARIF_SCHEMA,
        "version": "2.1.0",
        "runs": [{
            "tool": {"driver": {"name": "synth", "version": version(), "rules": list(rules.values())}},
            "invocations": [{"executionSuccessful": True,
                             "properties": {"verdicts": {f"{r.command} {r.target}": str(r.verdict) for r in reports}}}],
            "results": results,
        }],
    }


def located(rule: str, level: Level, message: str, loc: Location | None, file: str,
            trace: Sequence[str] = ()) -> CiFinding:
    """A finding at ``loc`` (the start of ``file`` when the model kept no location)."""
    if loc is None:
        return CiFinding(rule, level, message, file, 1, 1, tuple(trace))
    return CiFinding(rule, level, message, loc.file, loc.line, loc.column, tuple(trace))


def _constraint_location(f: Filter, ids: Sequence[str]) -> Location | None:
    """Where the first of the constraints ``ids`` is written in the filter."""
    by_id = {s.id: s.loc for s in f.safeties}
    return next((by_id[i] for i in ids if by_id.get(i) is not None), None)


def filter_check_report(f: Filter, c: Check) -> CiReport:
    """``synth filter check``: one finding per violated property (at the first constraint it
    names), one per stated equation that differs from the synthesis."""
    findings = [located(x.property.value, Level.ERROR, x.text(), _constraint_location(f, x.constraints), f.file)
                for x in c.coherence.findings if not x.holds]
    eq_loc = next((e.loc for e in f.equations if e.loc is not None), None)
    findings += [located("equation_differs", Level.ERROR, d, eq_loc, f.file) for d in c.differences]
    return CiReport("filter check", f.file, Verdict.PASS if c.holds else Verdict.FAIL, tuple(findings))


def filter_verify_report(f: Filter, v: Verification) -> CiReport:
    """``synth filter verify``: one finding per kind found (its shortest trace, at the first
    constraint involved); the kinds that do not fail the loop are warnings."""
    from synth.filter.loop.verification import INCOHERENT, UNSAFE, FindingKind
    from synth.output.filter_text import FINDINGS

    failing = set(UNSAFE) | set(INCOHERENT) | ({FindingKind.TRANSIENT} if v.strict else set())
    findings = []
    for kind, x in v.findings.items():
        text = FINDINGS[kind] + (f" ({', '.join(x.constraints)})" if x.constraints else "") + f"; {x.count} plant state(s)"
        findings.append(located(str(kind), Level.ERROR if kind in failing else Level.WARNING, text,
                                _constraint_location(f, x.constraints), f.file, [r.event for r in x.trace]))
    verdict = Verdict.PASS if v.safe and v.coherent else Verdict.FAIL
    return CiReport("filter verify", f.file, verdict, tuple(findings))


def validation_report(v: Validation) -> CiReport:
    """``synth validate``: one error per blocking situation (its diagnosis, at the awaited
    transition it names), per prohibited order (at the step that emits it) and for a
    Grafcet that never starts; a warning per OR conflict. Read from the validation's JSON,
    so both engines give the same file."""
    from synth.grafcet.language import step_variable
    from synth.output.result import validation_json

    data = validation_json(v)
    g, file = v.grafcet, str(data["grafcet"])
    transitions = {(t.grafcet, f"{','.join(t.sources)}->{','.join(t.targets)}"): t.loc for t in g.transitions}
    steps = {step_variable(s.name): s for s in g.steps}

    def awaited_location(diagnosis: dict[str, Any]) -> Location | None:
        awaited = diagnosis.get("awaited") or []
        named = [a for a in awaited if f"transition {a['transition']} of {a['grafcet']}" in diagnosis.get("summary", "")]
        for a in named + awaited:
            loc = transitions.get((a["grafcet"], a["transition"]))
            if loc is not None:
                return loc
        return None

    def emitting_step(state: dict[str, Any], order: str) -> Location | None:
        for x in state["situation"]:
            step = steps.get(x)
            if step is not None and any(a.order == order for a in step.actions):
                return step.loc
        return None

    findings = []
    if data["never_starts"] is not None:
        d = data["never_starts"]
        findings.append(located(str(d["verdict"]), Level.ERROR, d["summary"], awaited_location(d), file))
    for b in data["blocking"]:
        d = b["diagnosis"]
        findings.append(located(str(d["verdict"]), Level.ERROR, d["summary"], awaited_location(d), file, b["trace"]))
    for pr in data["prohibited"]:
        findings.append(located("prohibited_order", Level.ERROR, pr["diagnosis"], emitting_step(pr, pr["order"]),
                                file, pr["trace"]))
    for c in data["conflicts"]:
        loc = steps[step_variable(c["step"])].loc if step_variable(c["step"]) in steps else None
        findings.append(located("or_conflict", Level.WARNING,
                                f"OR divergence of step {c['step']}: {', '.join(c['transitions'])} fire together on {c['event']}",
                                loc, file, c["trace"]))
    if data["sup_empty"]:
        findings.append(located("sup_empty", Level.ERROR, "SUP is empty: the initial plant state is illegal or defended",
                                None, str(data["plant"])))
    return CiReport("validate", file, Verdict.PASS if v.passed else Verdict.FAIL, tuple(findings))


def st_check_report(g: Grafcet, report: DifferentialReport) -> CiReport:
    """``synth st --check``: one error per mismatch between the generated program and
    ``synth run`` (at the Grafcet's first step, with the events that lead to it)."""
    loc = next((s.loc for s in g.steps if s.loc is not None), None)
    findings = tuple(located(m.aspect.name.lower(), Level.ERROR, m.text(), loc, report.grafcet, m.events)
                     for m in report.mismatches)
    return CiReport("st --check", report.grafcet, Verdict.PASS if report.ok else Verdict.FAIL, findings)


def write_ci(reports: Sequence[CiReport], junit: str | None = None, sarif: str | None = None) -> None:
    """``--junit FILE`` and ``--sarif FILE``: the files, written whole or not at all."""
    from synth.output.files import write_atomic
    from synth.output.summary import json_text

    if junit:
        write_atomic(junit, junit_xml(reports))
    if sarif:
        write_atomic(sarif, json_text(sarif_json(reports)))
