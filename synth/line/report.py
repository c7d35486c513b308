"""What ``synth check`` writes: the summary table for the terminal, one JUnit and one SARIF
for the whole line (over :mod:`synth.output.ci`), and an HTML index linking one page per
station (jinja2 templates shipped in ``synth/line/templates``). Pure functions of the run's
results, so the files are the same byte for byte wherever the jobs ran.

A check whose findings the station expects (``expect = "fail"``) keeps them as notes: the
line's JUnit fails only where a station does not meet its expectation.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path
from typing import Any

from synth.line.run import LineRun, StationVerdict
from synth.output.ci import CiFinding, CiReport, Level, Verdict

__all__ = ["summary_table", "line_reports", "index_html", "station_html", "station_page", "write_line_reports"]


def _score(v: StationVerdict) -> str:
    if v.score is None:
        return "-"
    return f"{v.caught}/{v.changing} {100 * v.score:.0f}%"


def summary_table(run: LineRun) -> str:
    """One row per station, then the line's totals."""
    verdicts = run.verdicts()
    width = max([len("station")] + [len(v.name) for v in verdicts])
    head = f"{'station':<{width}}  {'jobs':>4}  {'failed':>6}  {'errors':>6}  {'expect':<6}"
    head += f"  {'mutants':<12}" if run.mutated else ""
    rows = [head + "  verdict"]
    for v in verdicts:
        row = f"{v.name:<{width}}  {v.jobs:>4}  {v.failed:>6}  {v.errors:>6}  {v.expect!s:<6}"
        row += f"  {_score(v):<12}" if run.mutated else ""
        rows.append(row + "  " + ("ok" if v.met else "NOT MET: " + "; ".join(v.reasons)))
        rows += [f"{'':<{width}}  survivor: {s}" + ("" if s in v.unexpected_survivors else " (allowed)")
                 for s in v.survivors]
    met = sum(v.met for v in verdicts)
    rows.append(f"{len(verdicts)} station(s), {met} meet their expectation; {len(run.results)} job(s): "
                f"{run.computed} run, {run.cached} from the cache")
    return "\n".join(rows) + "\n"


def line_reports(run: LineRun) -> list[CiReport]:
    """The CI reports of the line: each check's (its findings as notes when its station or
    variant expects it to fail), one per station for its mutants, and one per station that
    does not meet its expectation (at the station in the project file)."""
    from synth.line.work import ci_report_of

    out: list[CiReport] = []
    verdicts = {v.name: v for v in run.verdicts()}
    stations = {s.name: s for s in run.line.stations}
    toml = str(run.line.path)
    for r in run.results:
        if r["report"] is None:
            continue
        report = ci_report_of(r["report"])
        if r["expect"] == "fail" and r["verdict"] == "fail":
            report = dataclasses.replace(report, findings=tuple(dataclasses.replace(f, level=Level.NOTE)
                                                                for f in report.findings))
        out.append(dataclasses.replace(report, command=f"{report.command} [{r['station']}]"))
    for name, v in verdicts.items():
        s = stations[name]
        mutants = [r for r in run.results if r["station"] == name and r["mutant"] is not None]
        if mutants:
            findings = tuple(CiFinding("surviving_mutant", Level.ERROR if m["name"].removeprefix("mutant ") in
                                       v.unexpected_survivors else Level.NOTE,
                                       f"mutant {m['mutant']['id']} survives: {m['mutant'].get('description', '')}",
                                       m["mutant"].get("file") or toml, m["mutant"].get("line", 1), m["mutant"].get("column", 1))
                             for m in mutants if m["mutant"]["status"] == "survived")
            out.append(CiReport("mutate", name, Verdict.FAIL if v.unexpected_survivors else Verdict.PASS, findings))
        if not v.met:
            out.append(CiReport("check", name, Verdict.FAIL, tuple(
                CiFinding("expectation_not_met", Level.ERROR, f"station {name}: {reason}", toml, s.loc.line, s.loc.column)
                for reason in v.reasons)))
    return out


def _template(name: str) -> Any:
    import jinja2

    env = jinja2.Environment(loader=jinja2.PackageLoader("synth.line", "templates"), autoescape=True,
                             keep_trailing_newline=True, undefined=jinja2.StrictUndefined)
    return env.get_template(name)


def station_page(name: str) -> str:
    """The file name of a station's page: its name with anything but letters, digits, ``-``, ``_`` as ``_``."""
    return "station-" + re.sub(r"[^A-Za-z0-9_-]", "_", name) + ".html"


def index_html(run: LineRun) -> str:
    from synth.version import version

    return _template("index.html.j2").render(line=run.line, verdicts=run.verdicts(), page=station_page, score=_score,
                                             mutated=run.mutated, version=version(), run=run)


def validation_pages(run: LineRun) -> dict[str, str]:
    """The file name of each full validation report (``--validation-reports``), by job id:
    its station's page name and the job's rank in the run."""
    return {r["id"]: station_page(r["station"]).removesuffix(".html") + f"-{i}.html"
            for i, r in enumerate(run.results, 1) if r.get("html")}


def station_html(run: LineRun, v: StationVerdict) -> str:
    results = [r for r in run.results if r["station"] == v.name]
    return _template("station.html.j2").render(line=run.line, v=v, results=results, score=_score,
                                               pages=validation_pages(run))


def write_line_reports(run: LineRun, folder: str | Path, junit: str | Path | None = None,
                       sarif: str | Path | None = None) -> dict[str, Path]:
    """The index, the station pages, the JUnit and the SARIF (default: in ``folder``), every
    text rendered before the first is written; each written atomically."""
    from synth.output.ci import junit_xml, sarif_json
    from synth.output.files import write_atomic
    from synth.output.summary import json_text

    folder = Path(folder)
    reports = line_reports(run)
    files = [(folder / "index.html", index_html(run))]
    files += [(folder / station_page(v.name), station_html(run, v)) for v in run.verdicts()]
    by_id = {r["id"]: r for r in run.results}
    files += [(folder / name, by_id[ident]["html"]) for ident, name in validation_pages(run).items()]
    junit_path, sarif_path = Path(junit or folder / "junit.xml"), Path(sarif or folder / "line.sarif")
    files += [(junit_path, junit_xml(reports)), (sarif_path, json_text(sarif_json(reports)))]
    for path, text in files:
        write_atomic(path, text)
    return {"index": folder / "index.html", "junit": junit_path, "sarif": sarif_path}
