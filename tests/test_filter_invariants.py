"""``synth filter check --plant``: the valuations the filter can read on the plant under any
control, as ``assume`` lines, and the coherence judged on them (issue 23, item 6)."""

from __future__ import annotations

import json

from conftest import ROOT
from synth.cli.main import main
from synth.filter.invariants import assumed, invariants
from synth.filter.language_check import load_filter
from synth.logic.expr import evaluate
from synth.plant.composition import plant
from synth.plant.rules_check import load_rules

CYLINDER = str(ROOT / "tests/data/filter/cylinder_ends.filter")
TRI = str(ROOT / "plants/tri.rules")


def test_a_contradiction_outside_the_reachable_valuations_holds_with_the_invariants(capsys):
    assert main(["filter", "check", CYLINDER]) == 1
    assert "consistency: violated: no output vector satisfies OUT, IN when v10 & v11" in capsys.readouterr().out
    assert main(["filter", "check", CYLINDER, "--plant", TRI]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[:2] == [f"invariants of {TRI} under any control: 62208 reachable plant states, 6 of the 8 valuations "
                       "of v10, v11, AVANCER1^-1:", "assume !(v10 & v11)"]
    assert "P1 on AVANCER1: holds under assumptions: fails only outside the assumptions, e.g. when v10 & v11" in out
    assert out[-1] == "consistency: holds under assumptions: fails only outside the assumptions, e.g. when v10 & v11"


def test_json_lists_the_invariants(capsys):
    assert main(["filter", "check", str(ROOT / "tests/data/codegen/tri_box.filter"), "--plant", TRI, "--json"]) == 0
    inv = json.loads(capsys.readouterr().out)["invariants"]
    assert inv["assume"] == ["assume !(v10 & v11)", "assume !(v20 & v21)", "assume !(v30 & v31)",
                             "assume !(v40 & v41)", "assume !(cp11 & cp12)"]
    assert (inv["states"], inv["valuations"], len(inv["variables"])) == (62208, 31104, 17)


def test_the_invariants_hold_on_every_reachable_state_and_exclude_only_unreached_valuations():
    """Against an independent search: a breadth-first search over Plant.successors."""
    f = load_filter(ROOT / "tests/data/codegen/tri_box.filter")
    inv = invariants(f, TRI)
    p = plant(load_rules(TRI))
    start = p.local(p.initial_index)
    seen, frontier = {start}, [start]
    while frontier:
        nxt = []
        for s in frontier:
            for _, t in p.successors(s):
                if t not in seen:
                    seen.add(t)
                    nxt.append(t)
        frontier = nxt
    assert len(seen) == inv.states
    read = set()
    for s in seen:
        values = p.valuation(s)
        point = {n: values[n.removesuffix("^-1")] for n in inv.variables}
        read.add(tuple(point.values()))
        assert all(evaluate(a.expr, point.__getitem__) for a in assumed(f, inv).assumptions[len(f.assumptions):])
    assert len(read) == inv.valuations


def test_a_filter_name_the_plant_lacks_is_located(tmp_path, capsys):
    bad = tmp_path / "bad.filter"
    bad.write_text("inputs v10, v1l\noutputs AVANCER1\nsafety A: v1l & AVANCER1\n")
    assert main(["filter", "check", str(bad), "--plant", TRI]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"{bad}:1:13: error: the filter's input v1l is not a variable of the plant {TRI}\n")
    assert err.splitlines()[-1].startswith("  = expected ")
