"""synth check (issue 39, build 2): every station's checks, one JUnit, one SARIF and an
HTML index, exit codes by the stations' expectations, and the cache: an unchanged run
recomputes nothing, a changed file recomputes exactly the stations that read it, and a
changed input never gets an old result."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from synth.cli.main import main
from synth.line.cache import Cache
from synth.line.project import load_line
from synth.line.run import check_line

from conftest import ROOT
EXAMPLE = ROOT / "lines" / "example"

TOML = """[line]
name = "small"

[[station]]
name = "cyl"
plant = "m/cylinder.rules"
grafcets = ["m/production_loop.g7"]
checks = ["validate"]
homes = ["X1"]

[[station.variant]]
name = "no home"
homes = []
expect = "fail"

[[station]]
name = "press"
plant = "m/clamp.rules"
grafcets = ["m/clamp.g7"]
checks = ["validate"]

"""
GATE = """
[[station]]
name = "gate"
plant = "m/gate.rules"
grafcets = ["m/gate.g7"]
checks = ["validate"]
expect = "fail"
"""
TOML += GATE


@pytest.fixture
def line_dir(tmp_path: Path) -> Path:
    m = tmp_path / "m"
    (m / "lib").mkdir(parents=True)
    for src in (ROOT / "tests/data/home/cylinder.rules", ROOT / "tests/data/home/production_loop.g7",
                EXAMPLE / "plants/clamp.rules", EXAMPLE / "grafcets/clamp.g7", EXAMPLE / "plants/gate.rules",
                EXAMPLE / "grafcets/gate.g7"):
        shutil.copy(src, m / src.name)
    shutil.copy(ROOT / "plants/lib/single_acting.rules", m / "lib" / "single_acting.rules")  # gate.rules uses it
    (tmp_path / "synth.toml").write_text(TOML, encoding="utf-8")
    return tmp_path


def run(folder: Path):  # type: ignore[no-untyped-def]
    ran: list[str] = []
    result = check_line(load_line(folder / "synth.toml"), Cache(folder / "cache"), workers=1,
                        progress=lambda job, r, cached: None if cached else ran.append(job.id))
    return result, sorted(ran)


def test_an_unchanged_second_run_recomputes_nothing(line_dir: Path) -> None:
    first, ran = run(line_dir)
    assert ran == ["cyl/validate production_loop.g7", "cyl/variant no home", "gate/validate gate.g7",
                   "press/validate clamp.g7"]
    assert (first.computed, first.cached, first.exit_code) == (4, 0, 0)
    second, ran = run(line_dir)
    assert (ran, second.computed, second.cached) == ([], 0, 4)
    assert second.results == first.results


def test_a_changed_file_recomputes_exactly_the_stations_that_read_it(line_dir: Path) -> None:
    run(line_dir)
    with open(line_dir / "m" / "clamp.g7", "a", encoding="utf-8") as fh:
        fh.write("# a comment changes the hash\n")
    assert run(line_dir)[1] == ["press/validate clamp.g7"]
    with open(line_dir / "m" / "lib" / "single_acting.rules", "a", encoding="utf-8") as fh:
        fh.write("# read through the use lines of gate.rules and clamp.rules, not cylinder.rules\n")
    assert run(line_dir)[1] == ["gate/validate gate.g7", "press/validate clamp.g7"]
    assert run(line_dir)[1] == []


def test_the_cache_never_returns_a_result_for_changed_inputs(line_dir: Path) -> None:
    first, _ = run(line_dir)
    assert [r["verdict"] for r in first.results if r["station"] == "press"] == ["pass"]
    g = line_dir / "m" / "clamp.g7"
    g.write_text(g.read_text(encoding="utf-8").replace("step 2: CLAMP, PRESS", "step 2: CLAMP"), encoding="utf-8")
    second, ran = run(line_dir)
    assert ran == ["press/validate clamp.g7"]
    (press,) = [r for r in second.results if r["station"] == "press"]
    assert press["verdict"] == "fail" and press["summary"].startswith("FAIL: 1 blocking situation(s)")
    assert second.exit_code == 1
    assert [v.reasons for v in second.verdicts() if v.name == "press"] == [("expected pass, the checks fail",)]


def test_synth_check_writes_one_junit_one_sarif_and_an_index(line_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from junitparser import JUnitXml

    from tests.test_ci_output import assert_sarif

    report = line_dir / "out"
    code = main(["check", str(line_dir / "synth.toml"), "--cache", str(line_dir / "cache"), "--report", str(report),
                 "--workers", "1", "--quiet"])
    out = capsys.readouterr().out.splitlines()
    assert code == 0
    assert out[:5] == ["station  jobs  failed  errors  expect  verdict",
                       "cyl         2       1       0  pass    ok",
                       "press       1       0       0  pass    ok",
                       "gate        1       1       0  fail    ok",
                       "3 station(s), 3 meet their expectation; 4 job(s): 4 run, 0 from the cache"]
    assert sorted(p.name for p in report.iterdir()) == ["index.html", "junit.xml", "line.sarif", "station-cyl.html",
                                                        "station-gate.html", "station-press.html"]
    xml = JUnitXml.fromfile(str(report / "junit.xml"))
    assert (xml.tests, xml.failures) == (4, 0)  # expected failures are notes: the line passes
    sarif = json.loads((report / "line.sarif").read_text(encoding="utf-8"))
    assert_sarif(sarif)
    assert [(r["ruleId"], r["level"]) for r in sarif["runs"][0]["results"]] == [
        ("livelock", "note"), ("prohibited_order", "note")]
    index = (report / "index.html").read_text(encoding="utf-8")
    assert index.count('<a href="station-') == 3 and "NOT MET" not in index
    before = {p.name: p.read_bytes() for p in report.iterdir()}
    assert main(["check", str(line_dir / "synth.toml"), "--cache", str(line_dir / "cache"), "--report", str(report),
                 "--quiet"]) == 0
    assert {p.name: p.read_bytes() for p in report.iterdir()} == before  # from the cache, byte for byte


def test_an_unmet_expectation_exits_1_and_bad_input_exits_2(line_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    toml = line_dir / "synth.toml"
    toml.write_text(TOML.replace('expect = "fail"\n', 'expect = "pass"\n'), encoding="utf-8")  # the variant and gate
    args = ["check", str(toml), "--no-cache", "--report", str(line_dir / "out"), "--workers", "1", "--quiet"]
    assert main(args) == 1
    out = capsys.readouterr().out
    assert "gate        1       1       0  pass    NOT MET: expected pass, the checks fail" in out
    assert "cyl         2       1       0  pass    NOT MET: variant no home: expected pass, got fail" in out
    toml.write_text(TOML.replace("homes = []", "homes = [1]"), encoding="utf-8")
    assert main(args) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[0] == f"{toml}:13:9: error: homes must be a list of strings: homes = [\"...\"]"
    (line_dir / "m" / "clamp.g7").write_text("grafcet G {\n  initial step 0: NOPE\n}\n", encoding="utf-8")
    toml.write_text(TOML, encoding="utf-8")
    assert main(args) == 2  # a station's own file is wrong: that job is an error, the others run
    out = capsys.readouterr().out
    assert "press       1       0       1  pass    NOT MET: validate clamp.g7: " in out
    assert "gate        1       1       0  fail    ok" in out


def test_a_job_over_its_budget_is_reported_with_its_station_and_the_rest_goes_on(line_dir: Path) -> None:
    toml = line_dir / "synth.toml"
    toml.write_text(TOML.replace('grafcets = ["m/clamp.g7"]\n', 'grafcets = ["m/clamp.g7"]\nmax_states = 3\n'),
                    encoding="utf-8")
    result, ran = run(line_dir)
    assert len(ran) == 4 and result.exit_code == 2
    (press,) = [r for r in result.results if r["station"] == "press"]
    assert (press["id"], press["verdict"]) == ("press/validate clamp.g7", "error")
    assert press["summary"].startswith("stopped: ") and "3" in press["summary"]
    assert [v.met for v in result.verdicts()] == [True, False, True]
    assert run(line_dir)[1] == ["press/validate clamp.g7"]  # an error is not cached: it runs again


def test_a_worker_that_sees_other_files_refuses_the_job(line_dir: Path) -> None:
    from synth.line.cache import with_digests
    from synth.line.jobs import line_jobs
    from synth.line.work import run_job

    job = with_digests(line_jobs(load_line(line_dir / "synth.toml"))[2])
    assert run_job(job)["verdict"] == "pass"
    (line_dir / "m" / "clamp.g7").write_text("# another version\n", encoding="utf-8")
    result = run_job(job)
    assert (result["verdict"], result["summary"]) == (
        "error", f"press/validate clamp.g7: {line_dir / 'm' / 'clamp.g7'} differs where the job runs from where it was planned")


def test_a_filter_verify_result_holds_no_wall_clock_time(tmp_path: Path) -> None:
    from synth.line.jobs import Job, JobKind
    from synth.line.work import run_job

    data = ROOT / "tests" / "data" / "filter"
    job = Job("s", JobKind.FILTER_VERIFY, "filter verify", str(data / "two.rules"), None, str(data / "two_assume.filter"))
    first = run_job(job)
    explored = [x for x in first["text"].splitlines() if x.startswith("explored ")]
    assert len(explored) == 1 and explored[0].endswith(" cycles")  # "... cycles in 0.01 s" on the terminal
    assert run_job(job) == first


def test_bad_options_exit_2_without_a_traceback(line_dir: Path, capsys: pytest.CaptureFixture[str]) -> None:
    toml = str(line_dir / "synth.toml")
    with pytest.raises(SystemExit) as info:
        main(["check", toml, "--workers", "0"])
    assert info.value.code == 2
    assert capsys.readouterr().err.endswith("error: argument --workers: '0' is not a number of workers (1 or more)\n")
    pytest.importorskip("distributed")
    assert main(["check", toml, "--no-cache", "--quiet", "--cluster", "nonsense", "--report", str(line_dir / "o")]) == 2
    assert capsys.readouterr().err == ("error: --cluster nonsense: cannot reach the scheduler: missing port number in "
                                       "address 'nonsense'\n")
    assert not (line_dir / "o").exists()  # nothing written


def test_validation_reports_are_written_and_linked_from_their_station(line_dir: Path) -> None:
    toml = line_dir / "synth.toml"
    toml.write_text(TOML.split("\n[[station]]\nname = \"press\"")[0], encoding="utf-8")  # the cylinder alone
    report = line_dir / "out"
    assert main(["check", str(toml), "--no-cache", "--quiet", "--workers", "1", "--report", str(report),
                 "--validation-reports"]) == 0
    assert sorted(p.name for p in report.iterdir()) == ["index.html", "junit.xml", "line.sarif", "station-cyl-1.html",
                                                        "station-cyl-2.html", "station-cyl.html"]
    page = (report / "station-cyl.html").read_text(encoding="utf-8")
    assert page.count('<a href="station-cyl-') == 2
    variant, home = ((report / f"station-cyl-{k}.html").read_text(encoding="utf-8") for k in (2, 1))
    assert "<h2>Blocking 1: situation {X1}" in variant and "<h2>Blocking" not in home  # synth validate --report's
