"""Algebraic synthesis (`synth filter solve`): the published examples of seed 004, the
corrected single-output theorem against brute force, the box-sorting benchmark."""

from __future__ import annotations

import json
from itertools import product

import pytest

from conftest import ROOT
from synth.filter.language_check import load_filter, parse_filter
from synth.filter.model import functions
from synth.filter.solve import criteria, priority_criteria, synthesis
from synth.syntax import parse_tree

PLANTS = ROOT / "plants"
TRI = (PLANTS / "tri.filter").read_text()


def _tri(text: str = TRI, order=None):
    return synthesis(parse_filter(text, "tri.filter"), order)


def test_seed004_eq13():
    s = synthesis(load_filter(PLANTS / "seed004_eq13.filter"))
    assert (s.functional, s.consistent) == (True, True)
    assert s.equations == {"O1": "i1", "O2": "!i1"}


def test_seed004_eq22_to_26(cli):
    s = synthesis(load_filter(PLANTS / "seed004_eq22.filter"))
    assert s.equations == {"O1": "R_O1", "O2": "!R_O1 & R_O2"}
    assert [c.expr.text() for c in criteria(s.functions.filter)] == [
        "R_O1 & R_O2 & !O1", "R_O1 & O1 | !R_O1 & !O1", "R_O2 & O2 | !R_O2 & !O2"]
    assert s.warnings == ["criterion 1 has no effect (the criteria after it give the same filter without it): "
                          "minimize R_O1 & R_O2 & !O1  (priority of Cc1)"]
    code, out, err = cli("filter", "solve", PLANTS / "seed004_eq22.filter", "--json")
    data = json.loads(out)
    assert code == 0
    assert {k: data[k] for k in ("functional", "consistent", "equations")} == {
        "functional": True, "consistent": True, "equations": {"O1": "R_O1", "O2": "!R_O1 & R_O2"}}
    assert len(data["warnings"]) == 1


def test_sim_order_is_a_priority(cli, tmp_path):
    """docs/filter.md, "The algebraic synthesis": without a priority, Sim_O2 first gives O2 = R_O2, O1 = R_O1 & !R_O2;
    with the priority of (24) first, O1 keeps it whatever the Sim order."""
    f = tmp_path / "k.filter"
    f.write_text("outputs O1, O2\nsafety Cc1: O1 & O2\n")
    code, out, _ = cli("filter", "solve", f, "--json", "--order", "O2,O1")
    assert json.loads(out)["equations"] == {"O1": "R_O1 & !R_O2", "O2": "R_O2"}
    code, out, _ = cli("filter", "solve", PLANTS / "seed004_eq22.filter", "--json", "--order", "O2,O1")
    data = json.loads(out)
    assert data["equations"] == {"O1": "R_O1", "O2": "!R_O1 & R_O2"}
    assert data["warnings"] == []


def _table(vals) -> str:
    """An expression over y true exactly on the points listed (y = 0, y = 1)."""
    return " | ".join(t for t, v in zip(("!y", "y"), vals) if v) or "0"


FUNCTIONS = list(product((0, 1), repeat=2))


@pytest.mark.parametrize("sense", ["maximize", "minimize"])
def test_single_output_theorem_corrected(sense):
    """For f0·f1 = 0, the criterion a·x + !a·!x gives x = f0 + a·!f1 (Max) and
    x = f0 + !a·!f1 (Min), for every f0, f1, a of one variable; the printed (19) and (21)
    are wrong somewhere."""
    printed_wrong = 0
    for f0, f1 in product(FUNCTIONS, repeat=2):
        if any(a and b for a, b in zip(f0, f1)):
            continue
        for a in FUNCTIONS:
            text = (f"inputs y\noutputs x\nsafety K: !x & ({_table(f0)}) | x & ({_table(f1)})\n"
                    f"{sense} ({_table(a)}) & x | !({_table(a)}) & !x\n")
            s = synthesis(parse_filter(text, "t.filter"))
            assert s.functional and s.consistent
            got = [s.functions.engine.value(s.output("x"), {"y": bool(p)}) for p in (0, 1)]
            if sense == "maximize":
                want = [bool(z0 or (za and not z1)) for z0, z1, za in zip(f0, f1, a)]
                printed = [bool(z0 or (not za and z1)) for z0, z1, za in zip(f0, f1, a)]  # eq. (19)
            else:
                want = [bool(z0 or (not za and not z1)) for z0, z1, za in zip(f0, f1, a)]
                printed = [bool(z0 or (za and not z1)) for z0, z1, za in zip(f0, f1, a)]  # eq. (21)
            assert got == want, (f0, f1, a)
            printed_wrong += printed != want
    assert printed_wrong > 0


@pytest.mark.parametrize("sense, closed", [("maximize", "f0 | !f1 & a"), ("minimize", "f0 | !f1 & !a")])
def test_single_output_theorem_symbolic(sense, closed):
    """The same with f0, f1, a free variables: optima are pointwise in Y, so this covers
    every function f0, f1, a of any variables at once."""
    s = synthesis(parse_filter(f"inputs f0, f1, a\noutputs x\nassume !(f0 & f1)\n"
                               f"safety K: !x & f0 | x & f1\n{sense} a & x | !a & !x\n", "t.filter"))
    assert s.functional and s.consistent
    assert s.equations == {"x": closed}


def test_max_sim_is_eq21_of_000():
    """Max(Sim) with f(0) = fs1, f(1) = fs0, a = g1 = R_o gives o = !fs0·R_o + fs1."""
    s = synthesis(parse_filter("inputs c, d\noutputs o\nsafety S0: c & d & o\nsafety S1: !c & !o\n", "x.filter"))
    m = s.functions
    want = (~m.fs0["o"] & m.engine.var("R_o")) | m.fs1["o"]
    assert s.output("o") == want
    assert s.equations == {"o": "R_o & !d | !c"}


def test_tri_solve_is_functional_and_safe(cli):
    s = _tri()
    assert s.functional and not s.consistent
    assert s.inconsistent == {"C4": True, "C6^-1": True, "C6": True, "A2^-1": True}
    m = s.functions
    e = m.engine
    # the printed equations, read back with the filter grammar, satisfy every constraint on the care set
    parsed = {o: e.expr(_expr(t)) for o, t in s.equations.items()}
    for o, u in parsed.items():
        assert (~u.equiv(s.output(o)) & s.care) == e.false, o
    for ident, c in m.constraint.items():
        assert (e.let(parsed, c) & s.care) == e.false, ident
    assert s.equations["A1"] == "R_A1 & (!P36 & C4 & !C6 & (R_A2 & !R_A3 | A2^-1) | !C3)"  # as printed in (30)
    assert s.equations["A5"] == "R_A5" and s.equations["A6"] == "R_A6"
    code, out, _ = cli("filter", "solve", PLANTS / "tri.filter", "--json")
    data = json.loads(out)
    assert code == 1 and data["functional"] is True and data["consistent"] is False
    assert data["equations"] == s.equations


def _expr(text: str):
    from synth.filter.language_check import parse_filter as pf

    f = pf("inputs C0, C3, C4, C5, C6, C7, C8\noutputs A0, A1, A2, A3, A4, A5, A6\nobserver P01, P36\n"
           f"equation A0 = {text}\n", "eq.filter")
    return f.equations[0].expr


def test_tri_criteria_without_effect():
    assert _tri().warnings == [
        "criterion 3 has no effect (it removes no solution): "
        "minimize !A4^-1 & R_A4 & (R_A2 | R_A3) & (!A2 | !A3)  (line 33)",
        "criterion 4 has no effect (it removes no solution): "
        "minimize A4^-1 & !R_A4 & (R_A2 | R_A3) & (!A2 | !A3)  (line 34)",
    ]


def test_tri_priorities_translate_to_28():
    """The brackets of Table 3 give (28), except lines 3-4: !(A2 | A3) where 004 prints !A2 | !A3."""
    got = [c.expr.text() for c in priority_criteria(load_filter(PLANTS / "tri.filter"))]
    assert got == [
        "C0 & R_A0 & !R_A1 & A1",
        "C3 & C4 & R_A1 & !R_A2 & A2",
        "!A4^-1 & R_A4 & (R_A2 | R_A3) & !(A2 | A3)",
        "A4^-1 & !R_A4 & (R_A2 | R_A3) & !(A2 | A3)",
        "R_A2 & R_A3 & (A2 | A3)",
    ]


def test_tri_order_of_criteria_matters():
    lines = TRI.splitlines()
    sim = next(l for l in lines if l.startswith("maximize sim"))
    swapped = "\n".join(l for l in lines if l != sim).replace("# (28)", sim + "\n# (28)")
    first, later = _tri(), _tri(swapped)
    assert later.functional
    differ = sorted(o for o in first.equations if first.equations[o] != later.equations[o])
    assert differ == ["A0", "A1", "A2", "A3", "A4"]
    assert later.equations["A0"] == "R_A0 & !P01 & (!P36 & C4 & !C6 | !C0 | !C3)"
    assert len(later.warnings) == 5  # every criterion of (28) comes too late


def test_order_option(cli):
    code, out, err = cli("filter", "solve", PLANTS / "tri.filter", "--order", "A9")
    assert code == 2 and "--order: 'A9' is not an output" in err


def test_not_functional_reports_free_outputs(cli, tmp_path):
    f = tmp_path / "free.filter"
    f.write_text("inputs i\noutputs o1, o2\nsafety K: o1 & o2 & i\nmaximize o1 | o2\n")
    s = synthesis(load_filter(f))
    assert s.functional  # no `maximize sim` line: a Sim per output, implicitly, decides
    assert s.warnings == []  # the implicit ones are never reported
    f.write_text("inputs i\noutputs o1, o2\nsafety K: o1 & o2 & i\nmaximize sim o1\n")
    s = synthesis(load_filter(f))
    assert not s.functional and s.equations == {"o1": "R_o1"}
    assert s.free == {"o2": {"R_o1": False}}
    code, out, _ = cli("filter", "solve", f, "--json")
    data = json.loads(out)
    assert code == 1 and data["functional"] is False and data["free"] == {"o2": {"R_o1": 0}}
    code, out, _ = cli("filter", "solve", f)
    assert "not functional: o2 is free when !R_o1" in out


def test_no_solution_exit_1(cli, tmp_path):
    f = tmp_path / "none.filter"
    f.write_text("inputs i\noutputs o\nsafety K0: i & o\nsafety K1: i & !o\n")
    code, out, _ = cli("filter", "solve", f, "--json")
    data = json.loads(out)
    assert code == 1 and data["consistent"] is False
    assert data["inconsistent"]["counterexample"] == {"i": 1}
    assert data["equations"] == {"o": "R_o"}  # on the care set !i


def test_tri_chained_equations_as_004_prints_them():
    """The text output: an evaluation order where an equation may use earlier outputs;
    pasted back into the file, `check` finds them safe and equal to the synthesis."""
    from synth.filter.coherence import Property, Status, coherence
    from synth.filter.solve import differences

    s = _tri()
    assert list(s.chained) == ["A5", "A6", "A1", "A0", "A3", "A2", "A4"]
    assert s.chained["A0"] == "R_A0 & !P01 & (!C0 | A1)"  # as printed in (30)
    assert s.chained["A4"] == "A4^-1 & (A2 | A3) | R_A4 & !A2 & !A3"
    text = TRI + "".join(f"equation {o} = {t}\n" for o, t in s.chained.items())
    f = parse_filter(text, "chained.filter")
    found = [x for x in coherence(f).findings if x.property is Property.EQUATION]
    assert len(found) == 13 and all(x.status in (Status.HOLDS, Status.ASSUMED) for x in found)
    assert differences(synthesis(f)) == []
