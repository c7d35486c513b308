"""Every ``--json`` output of the plant, SUP and ASS commands validates against its shipped
schema, for every bundled plant and Grafcet; and a schema does reject drift."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest

from schemas import assert_valid
from synth.cli.main import main

ROOT = Path(__file__).resolve().parent.parent
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


def test_schema_rejects_drift(capsys):
    data = _json(capsys, "plant", str(ROOT / "plants/tri_annex.rules"), "--json")
    data["elements"][0]["unexpected"] = 1
    with pytest.raises(jsonschema.ValidationError):
        assert_valid("plant", data)
    del data["elements"][0]["unexpected"]
    data["initial"]["E"] = "10x"
    with pytest.raises(jsonschema.ValidationError):
        assert_valid("plant", data)
