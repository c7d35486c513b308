"""``--home`` conditions with ``&``, ``|`` and ``!`` mean the same to both engines (issue 24):
one expression walker (:func:`synth.logic.expr.evaluate`) reads them on explicit states and,
on the symbolic side, on BDDs. Random models, random home conditions, identical reports."""

from __future__ import annotations

import json
import random

import pytest

from synth.grafcet.language_check import load_grafcet
from synth.output.result import validation_json, validation_text
from synth.plant.composition import plant
from synth.plant.rules_check import load_rules

from synth.validation.validate import validate
from test_symbolic import _outcome, _random_case, validate_symbolic

def random_home(rng: random.Random, names: list[str], depth: int = 3) -> str:
    """A random condition over ``names`` with ``&``, ``|``, ``!`` and parentheses."""
    if depth == 0 or rng.random() < 0.3:
        atom = rng.choice(names)
        return ("!" if rng.random() < 0.4 else "") + atom
    op = rng.choice((" & ", " | "))
    parts = [random_home(rng, names, depth - 1) for _ in range(rng.randint(2, 3))]
    text = op.join(parts)
    return ("!" if rng.random() < 0.3 else "") + f"({text})"

SEEDS = range(40)

@pytest.mark.parametrize("seed", SEEDS)
def test_random_home_conditions_identical(seed, tmp_path):
    _random_case(seed, tmp_path)
    g = load_grafcet(tmp_path / "g.g7")
    p = plant(load_rules(tmp_path / "r.rules"))
    rng = random.Random(1000 + seed)
    names = [s.variable for s in g.steps] + list(p.inputs) + list(p.outputs)
    homes = (random_home(rng, names), random_home(rng, names, 1))[: 1 + seed % 2]
    a, err_a = _outcome(validate, tmp_path / "g.g7", tmp_path / "r.rules", homes=homes)
    b, err_b = _outcome(validate_symbolic, tmp_path / "g.g7", tmp_path / "r.rules", homes=homes)
    assert err_a == err_b, homes
    if a is None:
        return
    assert validation_text(b) == validation_text(a), homes
    assert json.dumps(validation_json(b), ensure_ascii=False) == json.dumps(validation_json(a), ensure_ascii=False)

@pytest.mark.parametrize("home", ["X0 & dcy", "X0 & !dcy", "X0 | X1", "!X1", "!(X1 | X2) & v0"])
def test_issue_cases_on_the_home_example(home):
    """The three conditions of the report: ``&`` was PASS where the explicit engine says
    FAIL, ``|`` the reverse, ``!`` a TypeError."""
    from conftest import ROOT

    g7, rules = ROOT / "tests/data/home/production_loop.g7", ROOT / "tests/data/home/cylinder.rules"
    a, err_a = _outcome(validate, g7, rules, homes=(home,))
    b, err_b = _outcome(validate_symbolic, g7, rules, homes=(home,))
    assert err_a == err_b
    assert a is not None and b is not None
    assert validation_text(b) == validation_text(a)
