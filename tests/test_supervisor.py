"""SUP by Tajer's algorithm, checked against libFAUDES SupConClosed."""

from __future__ import annotations

import json

import numpy as np
import pytest

from synth.plant.composition import plant
from synth.output.faudes import _grid_generator, plant_generator, supervisor_generator
from synth.plant.rules_check import load_rules, parse_rules
from synth.sup.constraints import CompiledConstraints
from synth.sup.explain import explain
from synth.sup.supervisor import supremal_controllable

from conftest import ROOT
from randrules import random_rules

faudes = pytest.importorskip("faudes")


def _faudes_sup(p, sup, tmp_path):
    """libFAUDES SupConClosed(plant, plant restricted to legal states, edge-forbidden events cut)."""
    legal = ~sup.illegal

    def allowed(t):
        s, d = p.slices(t)
        ok = legal[s] & legal[d]
        if t.controllable and t.event in sup.forbid:
            ok = ok & ~sup.forbid[t.event][s]
        return ok

    (tmp_path / "plant.gen").write_text(plant_generator(p))
    (tmp_path / "spec.gen").write_text(_grid_generator(p, "spec", legal, allowed))
    (tmp_path / "ours.gen").write_text(supervisor_generator(sup))
    g = faudes.System(str(tmp_path / "plant.gen"))
    k = faudes.Generator(str(tmp_path / "spec.gen"))
    theirs = faudes.System()
    faudes.SupConClosed(g, k, theirs)
    ours = faudes.System(str(tmp_path / "ours.gen"))
    return theirs, ours


def _check_against_faudes(rs, tmp_path):
    p = plant(rs)
    sup = supremal_controllable(p, rs.constraints)
    theirs, ours = _faudes_sup(p, sup, tmp_path)
    assert ours.Size() == sup.size
    assert ours.TransRelSize() == sup.count_transitions()
    if sup.size == 0:
        assert theirs.Size() == 0
        return sup
    assert (theirs.Size(), theirs.TransRelSize()) == (sup.size, sup.count_transitions())
    assert faudes.LanguageEquality(theirs, ours)
    return sup


def test_tri_annex_sup_equals_libfaudes(tmp_path):
    sup = _check_against_faudes(load_rules(ROOT / "plants" / "tri_annex.rules"), tmp_path)
    assert (sup.size, sup.count_transitions()) == (1626, 10738)


def test_tri_sup_equals_libfaudes(tmp_path):
    sup = _check_against_faudes(load_rules(ROOT / "plants" / "tri.rules"), tmp_path)
    assert sup.size == 9180


@pytest.mark.parametrize("seed", range(24))
def test_random_rule_sets_equal_libfaudes(seed, tmp_path):
    rs = parse_rules(random_rules(seed), f"random{seed}.rules")
    _check_against_faudes(rs, tmp_path)


def test_edge_constraint_forbids_only_that_event(tmp_path):
    lib = (ROOT / "plants" / "lib" / "double_acting.rules").read_text()
    rs = parse_rules(
        lib + "element V1 = double_acting(AVANCER=A, RECULER=R, v0=v10, v1=v11)\n"
        'constraint K "do not drop A before v11": ↓A & !v11 = 0\n',
        "e.rules",
    )
    sup = _check_against_faudes(rs, tmp_path)
    p = sup.plant
    ex = explain(sup, p.parse_state("A"))
    assert ex.status == "kept"
    assert ex.forbidden == (("↓A", ("K",)),)


def _annex_with(ids):
    text = (ROOT / "plants" / "tri_annex.rules").read_text()
    kept = [l for l in text.splitlines() if not l.startswith("constraint") or l.split()[1] in ids]
    return parse_rules("\n".join(kept), str(ROOT / "plants" / "annex_part.rules"), ROOT / "plants")


def test_annex_walkthrough_constraints_1_to_5():
    """Annex lines 13000-13020: p13 (Z13 = TAPIS, AVANCER1, AVANCER3) is weakly defended:
    ↓v10 leads to p51, defended because ↑v11 there violates constraint (3)."""
    rs = _annex_with({"A1", "A2", "A3", "A4", "A5"})
    p = plant(rs)
    sup = supremal_controllable(p, rs.constraints)
    p13 = p.parse_state("v10,v20,v30,v40,TAPIS,AVANCER1,AVANCER3")
    ex = explain(sup, p13)
    assert ex.status == "weakly_defended"
    assert ex.path == ("↓v10", "↑v11")
    assert ex.constraints == ("A3",)
    p51 = p.parse_state("v20,v30,v40,TAPIS,AVANCER1,AVANCER3")
    ex51 = explain(sup, p51)
    assert (ex51.status, ex51.path, ex51.constraints) == ("defended", ("↑v11",), ("A3",))
    # the controllable transition into p13 is forbidden from the initial state's successor
    p1 = p.parse_state("v10,v20,v30,v40,TAPIS,AVANCER1")
    assert ("↑AVANCER3", ("A3",)) in explain(sup, p1).forbidden
    # (q1, ↑RECULER1, q9) is forbidden by constraint (1)
    assert ("↑RECULER1", ("A1",)) in explain(sup, p1).forbidden


def test_local_supervisor_agrees_with_grid():
    rs = load_rules(ROOT / "plants" / "tri.rules")
    p = plant(rs)
    sup = supremal_controllable(p, rs.constraints)
    oracle = CompiledConstraints(p, rs.constraints)
    rng = np.random.default_rng(7)
    for code in rng.integers(0, p.size, 3000).tolist():
        local = p.local(code)
        assert oracle.kept(local) == (not sup.removed[local])
        assert bool(oracle.violated(local)) == bool(sup.illegal[local])


def test_sup_cli_json_keys(cli):
    code, out, _ = cli("sup", ROOT / "plants" / "tri_annex.rules", "--json")
    data = json.loads(out)
    assert code == 0
    for key in ("states", "transitions", "controllable", "uncontrollable", "forbidden_transitions",
                "defended", "weakly_defended", "unreachable_removed"):
        assert isinstance(data[key], int)
    assert data["states"] == 1626 and data["transitions"] == 10738
    assert data["controllable"] + data["uncontrollable"] == data["transitions"]


def test_sup_cli_why(cli):
    code, out, _ = cli("sup", ROOT / "plants" / "tri_annex.rules", "--why", "TAPIS,v10,v20,v30,v40,AVANCER1,AVANCER3")
    assert code == 0
    assert out.strip() == '{v10,v20,v30,v40,TAPIS,AVANCER1,AVANCER3} is illegal: it violates A6 "V3 and V1 must not advance together"'


def test_sup_cli_why_bad_state(cli):
    code, _, err = cli("sup", ROOT / "plants" / "tri_annex.rules", "--why", "TAPIS,v10,v11")
    assert code == 2
    assert "not a state of element V1" in err


def test_sup_export_reads_in_faudes(cli, tmp_path):
    gen = tmp_path / "sup.gen"
    code, _, _ = cli("sup", ROOT / "plants" / "tri_annex.rules", "--export", gen)
    assert code == 0
    s = faudes.System(str(gen))
    assert (s.Size(), s.TransRelSize()) == (1626, 10738)
    assert "AVANCER1_up" in s.ControllableEvents().ToString()


def _plain_tajer(p, constraints):
    """Tajer's algorithm written the plain way, state by state: the reference the
    vectorised closed form must match."""
    from synth.logic.expr import evaluate

    states = [p.local(c) for c in range(p.size)]

    def violates(local):
        val = p.valuation(local)
        return any(evaluate(c.forbidden, val.__getitem__) for c in constraints)

    def forbidden_edge(local, event):
        val = p.valuation(local)
        for c in constraints:
            if evaluate(c.forbidden, val.__getitem__, lambda e: e.text() == event):
                return True
        return False

    bad = {s for s in states if violates(s)}
    changed = True
    while changed:  # defended, then weakly defended, until nothing changes
        changed = False
        for s in states:
            if s in bad:
                continue
            if any(not t.controllable and n in bad for t, n in p.successors(s)):
                bad.add(s)
                changed = True
    if p.initial in bad:
        return set(), 0
    seen = {p.initial}
    stack = [p.initial]
    transitions = 0
    while stack:
        s = stack.pop()
        for t, n in p.successors(s):
            if n in bad or (t.controllable and forbidden_edge(s, t.event)):
                continue
            transitions += 1
            if n not in seen:
                seen.add(n)
                stack.append(n)
    return seen, transitions


@pytest.mark.parametrize("seed", range(30, 42))
def test_sparse_sup_equals_plain_tajer(seed):
    rs = parse_rules(random_rules(seed), f"random{seed}.rules")
    p = plant(rs)
    sup = supremal_controllable(p, rs.constraints)
    states, transitions = _plain_tajer(p, rs.constraints)
    assert {p.local(int(c)) for c in sup.states} == states
    assert sup.count_transitions() == transitions


def test_why_weakly_defended_names_each_uncontrollable_event_and_the_constraint(cli, tmp_path):
    """``sup --why`` on a weakly defended state: the path, event by event, and the violated
    constraint with its label (issue 10, item 6)."""
    text = (ROOT / "plants" / "tri_annex.rules").read_text().replace('use "lib/', f'use "{ROOT}/plants/lib/')
    kept = [l for l in text.splitlines() if not l.startswith("constraint") or l.split()[1] in {"A1", "A2", "A3", "A4", "A5"}]
    rules = tmp_path / "annex_1_5.rules"
    rules.write_text("\n".join(kept) + "\n")
    code, out, _ = cli("sup", rules, "--why", "TAPIS,v10,v20,v30,v40,AVANCER1,AVANCER3")
    assert code == 0
    label = next(l for l in kept if l.startswith("constraint A3")).split('"')[1]
    assert out.strip() == (
        "{v10,v20,v30,v40,TAPIS,AVANCER1,AVANCER3} is weakly defended: the uncontrollable path ↓v10 ↑v11 "
        f'leads to a state violating A3 "{label}"'
    )
