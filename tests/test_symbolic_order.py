"""The symbolic engine's variable order (constraint graph), its report in ``validate
--json``, and the bench families steep and branches × sequence (``--engine auto``: tests/test_probe.py)."""

from __future__ import annotations

import json
import sys

import pytest

from synth.output.result import validation_json, validation_text
from synth.plant.composition import plant
from synth.plant.rules_check import load_rules
from synth.symbolic import encoding
from synth.symbolic.encoding import element_order
from synth.symbolic.validate import validate_symbolic
from synth.validation.validate import validate

from conftest import ROOT
from schemas import assert_valid

sys.path.insert(0, str(ROOT / "bench"))
from gen_branches import write_branches  # noqa: E402
from gen_par import write_par  # noqa: E402
from gen_steep import write_steep  # noqa: E402

G = ROOT / "grafcets"
P = ROOT / "plants"


def _names(rules, order) -> list[str]:
    return [rules.elements[a].name for a in order]


def test_interlock_partners_are_neighbours(tmp_path):
    r, _, _ = write_branches(3, 3, tmp_path)
    rs = load_rules(r)
    assert [e.name for e in rs.elements][:4] == ["start", "C1_1", "C1_2", "C1_3"]  # declared branch by branch
    assert _names(rs, element_order(plant(rs), rs.constraints)) == [
        "start", "C1_1", "C2_1", "C3_1", "C1_2", "C2_2", "C3_2", "C1_3", "C2_3", "C3_3"]


def test_no_constraint_between_elements_keeps_declaration_order(tmp_path):
    r, _, _ = write_par(3, tmp_path)
    rs = load_rules(r)
    assert element_order(plant(rs), rs.constraints) == tuple(range(len(rs.elements)))


def test_variable_order_in_validate_json(tmp_path, capsys):
    from synth.cli.main import main

    r, g, _ = write_branches(2, 2, tmp_path)
    assert main(["validate", str(g), "--plant", str(r), "--engine", "symbolic", "--json", "--quiet"]) == 1
    data = json.loads(capsys.readouterr().out)
    assert data["symbolic"]["variable_order"] == ["start", "C1_1", "C2_1", "C1_2", "C2_2"]
    assert_valid("validate", data)


def _reversed(p, constraints=()):
    return tuple(reversed(range(len(p.elements))))


@pytest.mark.parametrize("case", ["tri_missing_order", "steep_2_missing", "par_3_missing"])
def test_reports_do_not_depend_on_the_variable_order(case, tmp_path, monkeypatch):
    """Reversed element order: the same text and JSON as the explicit engine (the states
    a report shows are the smallest in declaration order, whatever the BDD order)."""
    if case == "tri_missing_order":
        g, r = G / "tri_missing_order.g7", P / "tri.rules"
    elif case == "steep_2_missing":
        r, _, g = write_steep(2, tmp_path)
    else:
        r, _, g = write_par(3, tmp_path)
    a = validate(g, r)
    monkeypatch.setattr(encoding, "element_order", _reversed)
    b = validate_symbolic(g, r)
    assert b.engine_stats is not None
    assert b.engine_stats["variable_order"] == [e.name for e in reversed(b.plant.elements)]
    assert validation_text(b) == validation_text(a)
    ja, jb = validation_json(a), validation_json(b)
    assert json.dumps(jb, ensure_ascii=False) == json.dumps(ja, ensure_ascii=False)


@pytest.mark.parametrize("n", [2, 3])
def test_steep_family_identical(n, tmp_path):
    r, g, missing = write_steep(n, tmp_path)
    for grafcet in (g, missing):
        a, b = validate(grafcet, r), validate_symbolic(grafcet, r)
        assert validation_text(b) == validation_text(a)
    assert validate(g, r).passed and not validate(missing, r).passed


def test_smallest_state_is_in_declaration_order_whatever_the_bdd_order(tmp_path, monkeypatch):
    r, _, _ = write_par(2, tmp_path)
    p = plant(load_rules(r))
    monkeypatch.setattr(encoding, "element_order", _reversed)
    enc = encoding.PlantEncoding(p)
    first, last = list(p.initial), list(p.initial)
    first[1] = (p.initial[1] + 1) % p.elements[1].size  # C1 moved
    last[-1] = (p.initial[-1] + 1) % p.elements[-1].size  # C2 moved
    a, b = tuple(first), tuple(last)
    u = enc.state(a) | enc.state(b)
    key = {s: tuple(enc.pick(enc.state(s)).values()) for s in (a, b)}
    expected = min((a, b), key=key.__getitem__)
    assert enc.one(u) == expected
    assert sorted(enc.states(u, 10)) == sorted({a, b}) and list(enc.states(u, 10))[0] == expected
    assert enc.local(enc.pick(u)) != expected  # the path walk follows the BDD order
