"""Every ``--json`` output of the plant, SUP, ASS and validate commands validates against its shipped
schema, for every bundled plant and Grafcet; and a schema does reject drift."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest

from schemas import assert_valid
from synth.cli.main import main

from conftest import ROOT

PLANTS = sorted(p.name for p in (ROOT / "plants").glob("*.rules") if p.name != "tri_wrong_v1.rules")
GRAFCETS = sorted(p.name for p in (ROOT / "grafcets").glob("*.g7"))


def _json(capsys, *argv: str) -> object:
    code = main(list(argv))
    out = capsys.readouterr().out
    assert code == 0, out
    return json.loads(out)


@pytest.mark.parametrize("rules", PLANTS)
def test_plant_json(capsys, rules):
    assert_valid("plant", _json(capsys, "plant", str(ROOT / "plants" / rules), "--json"))


def test_element_json(capsys):
    assert_valid("element", _json(capsys, "plant", str(ROOT / "plants/tri.rules"), "--element", "V1", "--json"))


@pytest.mark.parametrize("rules", ["tri_annex.rules", "tri_overstrict.rules"])
def test_sup_json(capsys, rules):
    assert_valid("sup", _json(capsys, "sup", str(ROOT / "plants" / rules), "--json"))


@pytest.mark.parametrize("state", ["TAPIS,v10,v20,v30,v40,AVANCER1,AVANCER3", "TAPIS,v10,v20,v30,v40"])
def test_sup_why_json(capsys, state):
    assert_valid("sup_why", _json(capsys, "sup", str(ROOT / "plants/tri_annex.rules"), "--why", state, "--json"))


@pytest.mark.parametrize("g7", GRAFCETS)
def test_ass_json(capsys, g7):
    plant = ["--plant", str(ROOT / "plants/tri.rules")] if g7.startswith("tri") else []
    assert_valid("ass", _json(capsys, "ass", str(ROOT / "grafcets" / g7), *plant, "--json"))


VALIDATE_CASES = [
    ("grafcets/tri.g7", "plants/tri.rules"),
    ("grafcets/tri_missing_order.g7", "plants/tri.rules"),
    ("grafcets/tri.g7", "plants/tri_missing_rule.rules", "--expert"),
    ("grafcets/tri.g7", "plants/tri_overstrict.rules"),
    ("grafcets/tri.g7", "plants/tri_overstrict.rules", "--expert"),
    ("tests/data/or_conflict.g7", "plants/tri.rules"),
    ("grafcets/tri.g7", "plants/tri_boxes.rules"),
]


@pytest.mark.parametrize("case", VALIDATE_CASES, ids=lambda c: " ".join(Path(x).name for x in c))
def test_validate_json(capsys, tmp_path, case):
    g7, rules, *flags = case
    argv = ["validate", str(ROOT / g7), "--plant", str(ROOT / rules), *flags, "--json", "--report", str(tmp_path)]
    code = main(argv)
    data = json.loads(capsys.readouterr().out)
    assert code == (0 if data["verdict"] == "pass" else 1)
    assert data["report"].endswith("index.html")
    assert_valid("validate", data)


def test_validate_schema_rejects_unknown_verdicts(capsys):
    main(["validate", str(ROOT / "grafcets/tri_missing_order.g7"), "--plant", str(ROOT / "plants/tri.rules"), "--json"])
    data = json.loads(capsys.readouterr().out)
    data["blocking"][0]["diagnosis"]["verdict"] = "blocked"
    with pytest.raises(jsonschema.ValidationError):
        assert_valid("validate", data)
    data["blocking"][0]["diagnosis"]["verdict"] = "missing_order"
    data["blocking"][0]["trace_states"][0]["extra"] = []
    with pytest.raises(jsonschema.ValidationError):
        assert_valid("validate", data)


def test_lib_json(capsys):
    data = _json(capsys, "lib", "--json")
    assert_valid("lib", data)
    data[0]["initial"]["TAPIS"] = 2
    with pytest.raises(jsonschema.ValidationError):
        assert_valid("lib", data)


def test_schema_rejects_drift(capsys):
    data = _json(capsys, "plant", str(ROOT / "plants/tri_annex.rules"), "--json")
    data["elements"][0]["unexpected"] = 1
    with pytest.raises(jsonschema.ValidationError):
        assert_valid("plant", data)
    del data["elements"][0]["unexpected"]
    data["initial"]["E"] = "10x"
    with pytest.raises(jsonschema.ValidationError):
        assert_valid("plant", data)
