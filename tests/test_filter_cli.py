"""`synth filter check|solve`: exit codes, text and JSON (validated against the shipped
schemas) for every bundled filter."""

from __future__ import annotations

import json

import jsonschema
import pytest

from conftest import ROOT
from schemas import assert_valid

FILTERS = sorted(p.name for p in (ROOT / "plants").glob("*.filter"))
CHECK_HOLDS = {"loop_a.filter", "loop_b.filter", "loop_no_cycle.filter", "seed004_eq13.filter",
               "seed004_eq22.filter"}
SOLVE_OK = CHECK_HOLDS | {"loop_c.filter"}


@pytest.mark.parametrize("name", FILTERS)
def test_check_json(cli, name):
    code, out, err = cli("filter", "check", ROOT / "plants" / name, "--json")
    data = json.loads(out)
    assert_valid("filter_check", data)
    assert code == (0 if name in CHECK_HOLDS else 1)
    assert data["holds"] == (code == 0)


@pytest.mark.parametrize("name", FILTERS)
def test_solve_json(cli, name):
    code, out, err = cli("filter", "solve", ROOT / "plants" / name, "--json")
    data = json.loads(out)
    assert_valid("filter_solve", data)
    assert code == (0 if name in SOLVE_OK else 1)
    assert code == (0 if data["functional"] and data["consistent"] else 1)


def test_schema_rejects_drift(cli):
    _, out, _ = cli("filter", "solve", ROOT / "plants" / "seed004_eq13.filter", "--json")
    data = json.loads(out)
    data["equations"]["O1"] = 1
    with pytest.raises(jsonschema.ValidationError):
        assert_valid("filter_solve", data)


def test_text_outputs(cli):
    code, out, err = cli("filter", "solve", ROOT / "plants" / "seed004_eq13.filter")
    assert (code, out) == (0, "equation O1 = i1\nequation O2 = !i1\n")
    assert "warning: criterion 2 has no effect" in err
    code, out, _ = cli("filter", "check", ROOT / "plants" / "loop_a.filter")
    assert out.splitlines()[:3] == ["P1 on o1: holds", "P1 on o2: holds", "P2: holds: GO is acyclic"]


def test_bad_input(cli, tmp_path):
    code, _, err = cli("filter", "check", tmp_path / "missing.filter")
    assert code == 2 and "cannot read" in err
    with pytest.raises(SystemExit) as info:  # argparse's own error, exit 2 as for bad input
        cli("filter", "nope")
    assert info.value.code == 2
