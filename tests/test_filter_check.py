"""Coherence (`synth filter check`): P1-P4, GO and its cycles, 001's pair conditions,
global consistency, and the check of given equations (004's printed (30))."""

from __future__ import annotations

import json

from conftest import ROOT
from synth.filter.coherence import Property, Status, coherence
from synth.filter.language_check import load_filter, parse_filter

PLANTS = ROOT / "plants"
TRI = (PLANTS / "tri.filter").read_text()


def _found(report, prop, subject=""):
    return next(f for f in report.findings if f.property is prop and f.subject == subject)


def test_tri_without_assumptions_is_inconsistent():
    text = TRI.replace("assume !(C4 & C5)", "").replace("assume !(A2^-1 & A3^-1)", "")
    c = _found(coherence(parse_filter(text, "tri.filter")), Property.CONSISTENCY)
    assert c.status is Status.VIOLATED
    assert c.counterexample == {"C5": True, "C7^-1": False, "C8^-1": False, "A2^-1": True, "A3^-1": True}
    assert c.constraints == ("S9", "S10", "S13")


def test_tri_with_assumptions_leaves_one_cube(cli):
    report = coherence(load_filter(PLANTS / "tri.filter"))
    c = _found(report, Property.CONSISTENCY)
    assert c.status is Status.VIOLATED
    assert c.counterexample == {"C4": True, "C6^-1": True, "C6": True, "A2^-1": True}
    assert c.constraints == ("S7", "S12")
    assert c.text() == "consistency: violated: no output vector satisfies S7, S12 when C4 & C6^-1 & C6 & A2^-1"
    p1 = _found(report, Property.P1, "A2")
    assert p1.text() == "P1 on A2: violated: S12 forces 0, S7 forces 1 when C4 & C6^-1 & C6 & A2^-1"
    assert [f.subject for f in report.findings if f.property is Property.P3 and not f.holds] == ["A2", "A3"]
    assert _found(report, Property.P3, "A2").constraints == ("S13", "S7")
    assert _found(report, Property.P2).status is Status.HOLDS
    assert [e.text() for e in report.go] == ["S5 -(A1:=0)-> S2", "S13 -(A2:=0)-> S5"]
    assert _found(report, Property.PAIR, "S13").status is Status.ASSUMED
    code, out, _ = cli("filter", "check", PLANTS / "tri.filter", "--json")
    data = json.loads(out)
    assert code == 1 and data["holds"] is False
    cons = next(f for f in data["findings"] if f["property"] == "consistency")
    assert cons["counterexample"] == {"C4": 1, "C6^-1": 1, "C6": 1, "A2^-1": 1}
    assert cons["constraints"] == ["S7", "S12"] and cons["holds"] is False


def test_printed_eq30_violations(cli):
    report = coherence(load_filter(PLANTS / "tri_printed30.filter"))
    eq = {f.subject: f for f in report.findings if f.property is Property.EQUATION}
    assert sorted((i for i, f in eq.items() if not f.holds), key=lambda i: int(i[1:])) == ["S9", "S10", "S13"]
    assert eq["S9"].counterexample == {"R_A2": False, "C5": True, "C8^-1": False, "A2^-1": True}
    assert eq["S10"].counterexample == {"R_A3": False, "C5": True, "C7^-1": False, "A3^-1": True}
    assert eq["S13"].counterexample == {"R_A2": False, "R_A3": True, "C5": True, "C8^-1": True, "C8": False,
                                        "A2^-1": True}
    assert eq["S6"].status is Status.ASSUMED and eq["S7"].status is Status.ASSUMED
    code, out, _ = cli("filter", "check", PLANTS / "tri_printed30.filter")
    assert code == 1
    assert "equation on S9: violated: the equations violate S9 when !R_A2 & C5 & !C8^-1 & A2^-1" in out
    differs = [line for line in out.splitlines() if line.startswith("differs: ")]
    assert [d.split(":")[1].strip() for d in differs] == ["A2", "A2", "A3", "A3", "A3", "A4", "A4", "A4"]
    assert ("differs: A2: the printed term A2^-1 & (C4 & !C6 | C5 & ↓C8) gives 1 where the synthesis gives 0, "
            "e.g. when !R_A2 & C5 & C8^-1 & !C8 & A2^-1") in differs


def test_printed30_file_is_tri_plus_equations():
    body = [l for l in (PLANTS / "tri_printed30.filter").read_text().splitlines()[3:] if l.strip()]
    assert [l for l in TRI.splitlines()[4:] if l.strip()] == body[: len(body) - 8]


def test_example_c_has_a_go_cycle(cli):
    code, out, _ = cli("filter", "check", PLANTS / "loop_c.filter")
    assert code == 1
    assert "P2: violated: GO cycle K1 -(o2:=0)-> K2 -(o2:=1)-> K1" in out.splitlines()


def test_not_a_cycle(cli):
    code, out, _ = cli("filter", "check", PLANTS / "loop_no_cycle.filter")
    assert code == 0
    assert "P2: holds: GO is acyclic" in out and "GO edge: K1 -(o2:=0)-> K2" in out


def test_examples_a_b_hold(cli):
    for name in ("loop_a.filter", "loop_b.filter", "seed004_eq13.filter", "seed004_eq22.filter"):
        code, out, _ = cli("filter", "check", PLANTS / name)
        assert code == 0, out
        assert "violated" not in out


def test_four_cylinders_edge_rule():
    report = coherence(load_filter(PLANTS / "four_cylinders.filter"))
    assert [_found(report, Property.P1, q).status for q in ("Q1", "Q2", "Q3", "Q4")] == [Status.EDGE_RULE] * 4
    assert _found(report, Property.P2).status is Status.HOLDS
    # docs/filter.md, "The domain of P1–P4": read literally, P3 fails (i1 while both cylinders are extending)
    p3 = _found(report, Property.P3, "Q2")
    assert p3.status is Status.VIOLATED and p3.constraints == ("CSc1", "CSs2_6")


def test_p1_and_p4_violations_and_assumptions(tmp_path):
    f = parse_filter("inputs a, b\noutputs o, p\nsafety S0: a & o\nsafety S1: b & !o\n"
                     "safety K: o & p keep o\n", "x.filter")
    report = coherence(f)
    p1 = _found(report, Property.P1, "o")
    assert (p1.status, p1.counterexample, p1.constraints) == (Status.VIOLATED, {"a": True, "b": True}, ("S0", "S1"))
    f = parse_filter("inputs a, b\noutputs o, p\nassume !(a & b)\nsafety S0: a & o\nsafety S1: b & !o\n"
                     "safety K: o & p keep p\n", "x.filter")
    report = coherence(f)
    p1 = _found(report, Property.P1, "o")
    assert p1.status is Status.ASSUMED
    assert p1.detail == "fails only outside the assumptions, e.g. when a & b"
    p4 = _found(report, Property.P3, "o")  # K forces o to 0 where S1 forces 1
    assert (p4.status, p4.constraints) == (Status.VIOLATED, ("K", "S1"))
    assert p4.counterexample == {"b": True, "p": True}


def test_pair_condition_of_001():
    f = parse_filter("inputs a, b\noutputs k, l\nsafety S0: a & !k\nsafety S1: b & !l\n"
                     "safety K: k & l force l=0\n", "x.filter")
    pair = _found(coherence(f), Property.PAIR, "K")
    assert pair.status is Status.VIOLATED
    assert pair.constraints == ("K", "S0", "S1") and pair.counterexample == {"a": True, "b": True}
