"""The .filter language: what it reads, and every mistake as file:line:col, the line,
a caret, what was expected or meant, exit 2 and never a traceback."""

from __future__ import annotations

from pathlib import Path

import pytest

from conftest import ROOT
from synth.errors import InputError, InputErrors
from synth.filter.language import ConstraintKind, Sense, SimCriterion
from synth.filter.language_check import load_filter, parse_filter

HEAD = "inputs C0, C6\noutputs A0, A1\n"


def _errors(cli, tmp_path: Path, text: str, name: str = "bad.filter") -> str:
    f = tmp_path / name
    f.write_text(text)
    code, out, err = cli("filter", "check", f)
    assert code == 2, err
    assert "Traceback" not in err
    return err.replace(str(f), name)


def test_tri_is_read_and_classified():
    f = load_filter(ROOT / "plants" / "tri.filter")
    assert f.outputs == ("A0", "A1", "A2", "A3", "A4", "A5", "A6")
    assert [s.id for s in f.combined] == ["S2", "S5", "S6", "S8", "S13"]
    assert all(s.kind is ConstraintKind.SIMPLE for s in f.simple) and len(f.simple) == 8
    forced = {s.id: [(c.output, c.value) for c in s.forced] for s in f.combined}
    assert forced == {"S2": [("A0", False)], "S5": [("A1", False)], "S6": [("A4", False)],
                      "S8": [("A4", True)], "S13": [("A2", False), ("A3", False)]}
    assert [c.sense for c in f.criteria[:5]] == [Sense.MIN] * 5
    assert isinstance(f.criteria[5], SimCriterion) and f.criteria[5].outputs == f.outputs
    assert f.safety("S7").expr.text() == "C4 & !↑C6 & ↓A2"


def test_past_values_and_synonyms():
    f = parse_filter(HEAD + "safety K: A0 and not A1 . pre(C6) * C0^-1 + ~A0 & ¬A1 & C6⁻¹ force A1=1", "x.filter")
    assert f.safeties[0].expr.text() == "A0 & !A1 & C6^-1 & C0^-1 | !A0 & !A1 & C6^-1"


def test_unknown_name(cli, tmp_path):
    err = _errors(cli, tmp_path, HEAD + "safety S1: C0 & A0 & !A7\n")
    assert err.splitlines() == [
        "bad.filter:3:23: error: unknown variable 'A7' in constraint S1",
        "  3 | safety S1: C0 & A0 & !A7",
        "    |                       ^~",
        "  = did you mean A1 or A0?",
    ]


def test_unknown_past_value_and_edge(cli, tmp_path):
    err = _errors(cli, tmp_path, HEAD + "safety S1: ↑C7 & A0\nassume !C9^-1\n")
    assert "bad.filter:3:13: error: unknown variable 'C7' in constraint S1" in err
    assert "bad.filter:4:9: error: unknown variable 'C9' in an assumption" in err


def test_syntax_error(cli, tmp_path):
    err = _errors(cli, tmp_path, HEAD + "safety S1: C0 & & A0\n")
    assert err.splitlines() == [
        "bad.filter:3:17: error: syntax error: unexpected '&'",
        "  3 | safety S1: C0 & & A0",
        "    |                 ^",
        "  = expected ! (not), (, 0 or 1, a name, ↑ (or ^), ↓ (or _)",
    ]


def test_no_output_at_t(cli, tmp_path):
    err = _errors(cli, tmp_path, HEAD + "safety S1: C0 & A0^-1\n")
    assert err.splitlines() == [
        "bad.filter:3:8: error: constraint S1 does not involve an output at t",
        "  3 | safety S1: C0 & A0^-1",
        "    |        ^~",
        "  = note: a safety constraint names an output or its edge; past values x^-1 are read-only",
    ]


def test_relief_errors(cli, tmp_path):
    err = _errors(cli, tmp_path, HEAD + (
        "safety S2: A0 & A1 keep C0\n"
        "safety S3: A0 & !A0 & A1 keep A1\n"
        "safety S4: (A0 | A1) & C0 force A0=0\n"
        "safety S5: A0 & A1 force A0=0, A0=1\n"
        "safety S6: A0 & A1 keep A0 & A1\n"))
    assert "bad.filter:3:25: error: keep: 'C0' is not an output of S2 at t" in err
    assert ("bad.filter:4:8: error: keep: cannot tell the value to force on 'A0' in S3, "
            "it occurs both negated and not") in err
    assert "  = note: write the relief as `force A0=0` or `force A0=1`" in err
    assert "bad.filter:5:8: error: the relief of S4 does not make it false: A0=0 leaves it satisfiable" in err
    assert "bad.filter:6:32: error: 'A0' is forced twice in S5" in err
    assert "bad.filter:7:8: error: keep: S6 keeps every output, nothing is left to force" in err


def test_declarations(cli, tmp_path):
    err = _errors(cli, tmp_path, "inputs C0, R_A0\noutputs A0, C0\nsafety S1: A0\nsafety S1: !A0\n")
    assert "bad.filter:2:13: error: 'C0' is declared twice" in err
    assert "  = note: first declared as input at bad.filter:1:8" in err
    assert "bad.filter:1:12: error: 'R_A0' is the implicit request of output A0; it cannot be declared" in err
    assert "bad.filter:4:8: error: constraint 'S1' is declared twice" in err


def test_statement_errors(cli, tmp_path):
    err = _errors(cli, tmp_path, HEAD + "safety S1: A0 & A1 keep A0\nassume C0 & A1\nmaximize sim A0, B1\n"
                  "equation A3 = C0\nequation A0 = C0\nequation A0 = A1\n")
    assert "bad.filter:4:13: error: an assumption cannot use the output 'A1' at t" in err
    assert "bad.filter:5:18: error: maximize sim: 'B1' is not an output" in err
    assert "bad.filter:6:10: error: equation: 'A3' is not an output" in err
    assert "bad.filter:8:10: error: output 'A0' has two equations" in err


def test_no_outputs(cli, tmp_path):
    err = _errors(cli, tmp_path, "inputs C0\n")
    assert err.splitlines()[0] == "bad.filter:1:1: error: no outputs declared"


def test_simple_constraint_relief_is_a_warning(cli, tmp_path):
    f = tmp_path / "w.filter"
    f.write_text(HEAD + "safety S1: C0 & A0 keep A0\n")
    code, out, err = cli("filter", "check", f)
    assert code == 0
    assert "warning: S1 is a simple constraint (output A0): its relief is implied, keep/force is ignored" in err


def test_equation_cycle(cli, tmp_path):
    f = tmp_path / "e.filter"
    f.write_text(HEAD + "safety S1: C0 & A0\nequation A0 = A1\nequation A1 = A0 & C6\n")
    code, out, err = cli("filter", "check", f)
    assert code == 2 and "Traceback" not in err
    assert "e.filter:4:10: error: the equations of A0, A1 depend on each other in a cycle" in err


def test_errors_are_collected():
    with pytest.raises(InputErrors) as info:
        parse_filter(HEAD + "safety S1: A9 & A0\nsafety S2: A8 & A0\n", "x.filter")
    assert len(info.value.errors) == 2
    with pytest.raises(InputError):
        parse_filter(HEAD + "safety S1: A9 & A0\n", "x.filter")


def test_use_plant(tmp_path):
    (tmp_path / "p.filter").write_text('use "%s"\nsafety K: AVANCER3 & AVANCER1 keep AVANCER1\n'
                                       % (ROOT / "plants" / "tri.rules"))
    f = load_filter(tmp_path / "p.filter")
    assert "AVANCER3" in f.outputs and "v11" in f.inputs
    assert f.safeties[0].forced[0].output == "AVANCER3"


def test_observers_and_criteria_are_kept():
    f = parse_filter(HEAD + 'observer P01, X31 = grafcet "obs.g7"\nsafety S: X31 & A0\n'
                     "minimize R_A0 & A1\nmaximize sim A1\n", "x.filter")
    assert [(d.name, d.grafcet) for d in f.observers] == [("P01", None), ("X31", "obs.g7")]
    assert f.requests == ("R_A0", "R_A1")
    assert [type(c).__name__ for c in f.criteria] == ["Criterion", "SimCriterion"]
    assert f.criteria[0].expr.text() == "R_A0 & A1" and f.criteria[0].loc.line == 5
