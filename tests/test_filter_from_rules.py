"""`synth filter from-rules`: the skeleton of plants/tri.rules (the rules' constraints as simple and combined ones),
edge and `= 1` constraints, constraints without an order, atomic writing, round trip."""

from __future__ import annotations

from conftest import ROOT
from synth.filter.from_rules import skeleton
from synth.filter.language_check import load_filter
from synth.filter.model import functions
from synth.filter.solve import synthesis
from synth.plant.rules_check import load_rules

TRI = ROOT / "plants" / "tri.rules"


def test_tri_classification(cli, tmp_path):
    out = tmp_path / "F.filter"
    code, text, err = cli("filter", "from-rules", TRI, "-o", out)
    assert code == 0
    assert text.splitlines() == [
        "C2_1: CSc (no priority) on AVANCER1, RECULER1",
        "C2_2: CSc (no priority) on AVANCER2, RECULER2",
        "C2_3: CSs on AVANCER3",
        "C2_4: CSs on AVANCER3",
        "C2_5: CSs on AVANCER2",
        "C2_6: CSc (no priority) on AVANCER3, AVANCER1",
        "C2_7: CSc (no priority) on AVANCER3, AVANCER4",
        "C2_8: CSs on AVANCER4",
        f"wrote {out}",
    ]
    f = load_filter(out)
    assert [s.id for s in f.simple] == ["C2_3", "C2_4", "C2_5", "C2_8"]
    assert [s.id for s in f.combined] == ["C2_1", "C2_2", "C2_6", "C2_7"]
    assert not any(s.has_priority for s in f.safeties)
    rs = load_rules(TRI)
    assert f.outputs == rs.outputs and f.inputs == rs.inputs and f.plant is not None
    assert 'use "' in out.read_text() and "# combined: add `keep L`" in out.read_text()


def test_tri_solve_implies_the_constraints(tmp_path):
    """One equation per output (7); substituted for the outputs, every constraint is 0."""
    out = tmp_path / "F.filter"
    skeleton(TRI, out)  # not written: the text is parsed in memory
    assert not out.exists()
    sk = skeleton(TRI, out)
    s = synthesis(sk.filter)
    assert (s.functional, s.consistent, len(s.equations)) == (True, True, 7)
    assert s.equations["AVANCER3"] == "!R_AVANCER1 & R_AVANCER3 & !v11 & !v21"
    m = s.functions
    e = m.engine
    outputs = {o: s.output(o) for o in m.outputs}
    for cid, u in m.constraint.items():
        assert e.let(outputs, u) & s.care == e.false, cid
    assert s.care == e.true  # every Y admits a safe vector


def test_round_trip_and_special_constraints(tmp_path):
    rules = tmp_path / "p.rules"
    rules.write_text(
        'use "{lib}"\n'
        "element V1 = double_acting(AVANCER=AVANCER1, RECULER=RECULER1, v0=v10, v1=v11)\n"
        "free b = 0\n"
        'constraint E1 "do not drop AVANCER1 before v11": ↓AVANCER1 & !v11 = 0\n'
        "constraint L1: RECULER1 | !b = 1\n"
        "constraint N1: v10 & b = 0\n".format(lib=(ROOT / "plants" / "lib" / "double_acting.rules").as_posix()))
    sub = tmp_path / "out"
    sub.mkdir()
    sk = skeleton(rules, sub / "p.filter")
    lines = sk.text.splitlines()
    assert lines[1] == 'use "../p.rules"'
    assert 'safety E1 "do not drop AVANCER1 before v11": ↓AVANCER1 & !v11' in lines
    assert "safety L1: !(RECULER1 | !b)" in lines
    assert "# N1: v10 & b  -- involves no order: not a filter constraint" in lines
    assert [(c.id, c.kind) for c in sk.constraints] == [("E1", "simple"), ("L1", "simple"), ("N1", "skipped")]
    (sub / "p.filter").write_text(sk.text)
    f = load_filter(sub / "p.filter")
    m = functions(f)
    e = m.engine
    rs = load_rules(rules)
    for c in rs.constraints[:2]:  # the same Boolean functions as the rules' forbidden expressions
        assert m.constraint[c.id] == e.expr(c.forbidden)
    assert m.engine.text(m.fs1["AVANCER1"]) == "!v11 & AVANCER1^-1"
