"""Every mistake in a .rules file: file:line:col, the line, a caret, suggestions, exit 2."""

from __future__ import annotations

from pathlib import Path

import pytest

from conftest import ROOT

V1 = """element V1 {
    orders AVANCER1 = 0, RECULER1 = 0
    sensors v10 = 1, v11 = 0
    incoherent v10 & v11
    ↑AVANCER1 [v10] -> ↓v10
}
"""


def _run(cli, tmp_path: Path, text: str, name: str = "bad.rules"):
    f = tmp_path / name
    f.write_text(text)
    code, out, err = cli("sup", f)
    assert code == 2, err
    assert "Traceback" not in err
    return err.replace(str(f), name)


def test_syntax_error(cli, tmp_path):
    err = _run(cli, tmp_path, V1 + "constraint C1 \"x\": AVANCER1 & = 0\n")
    lines = err.splitlines()
    assert lines[0] == "bad.rules:7:31: error: syntax error: unexpected '='"
    assert lines[1] == '  7 | constraint C1 "x": AVANCER1 & = 0'
    assert lines[2] == "    |                               ^"
    assert lines[3].startswith("  = expected ") and "a name" in lines[3]


def test_unknown_name_in_element(cli, tmp_path):
    err = _run(cli, tmp_path, V1.replace("[v10]", "[v01]"))
    assert err.splitlines()[0] == "bad.rules:5:16: error: unknown variable 'v01' in element V1"
    assert "  = did you mean v11 or v10?" in err
    assert "    |                ^~~" in err


def test_variable_owned_by_two_elements(cli, tmp_path):
    err = _run(cli, tmp_path, V1 + "element V2 {\n  order AVANCER2 = 0\n  sensor v10 = 0\n}\n")
    assert err.splitlines()[0] == (
        "bad.rules:9:10: error: variable 'v10' is declared by element V2 but already belongs to element V1"
    )
    assert "V1 declares it at bad.rules:3:13" in err


def test_unknown_model(cli, tmp_path):
    lib = (ROOT / "plants" / "lib" / "double_acting.rules").read_text()
    err = _run(cli, tmp_path, lib + "element V1 = double_actin(AVANCER=A1, RECULER=R1, v0=v10, v1=v11)\n")
    assert "error: unknown model 'double_actin' for element V1" in err
    assert "did you mean double_acting?" in err


def test_incoherent_initial_state(cli, tmp_path):
    err = _run(cli, tmp_path, V1.replace("v11 = 0", "v11 = 1"))
    assert err.splitlines()[0] == (
        "bad.rules:4:16: error: the initial state of element V1 is incoherent: v10 & v11 holds initially"
    )


def test_constraint_on_undeclared_name(cli, tmp_path):
    err = _run(cli, tmp_path, V1 + 'constraint C1 "V1": AVANCR1 & RECULER1 = 0\n')
    assert err.splitlines()[0] == "bad.rules:7:21: error: constraint C1 uses undeclared variable 'AVANCR1'"
    assert "  = did you mean AVANCER1?" in err
    assert "    |                     ^~~~~~~" in err


def test_empty_plant(cli, tmp_path):
    err = _run(cli, tmp_path, "# nothing here\n")
    assert err.splitlines()[0] == "bad.rules:1:1: error: the plant is empty: no element is declared"


def test_rule_producing_another_elements_sensor(cli):
    """The thesis's expert error (§4.2.2) is caught when the rules are read."""
    code, _, err = cli("plant", ROOT / "plants" / "tri_wrong_v1.rules")
    assert code == 2
    first = err.splitlines()[0]
    assert first.endswith("error: rule of element V1 produces ↑v21, but v21 is a sensor of element V2")
    line = int(first.split(":")[1])
    assert "-> ↑v21" in (ROOT / "plants" / "tri_wrong_v1.rules").read_text().splitlines()[line - 1]


def test_edge_of_input_in_constraint(cli, tmp_path):
    err = _run(cli, tmp_path, V1 + 'constraint C1 "x": ↑v10 & AVANCER1 = 0\n')
    assert "edges in constraints must be edges of orders" in err


def test_missing_file(cli, tmp_path):
    code, _, err = cli("plant", tmp_path / "nope.rules")
    assert code == 2 and "cannot read" in err


@pytest.mark.parametrize("text,needle", [
    ("element A {\n order X = 0\n}\nelement A {\n order Y = 0\n}\n", "element 'A' is declared twice"),
    (V1 + 'constraint C1 "a": v10 = 0\nconstraint C1 "b": v11 = 0\n', "constraint id 'C1' is used twice"),
    (V1 + "hold v10 = 1\n", "only orders can be held"),
    (V1 + "outputs AVANCER1, v10\n", "outputs: 'v10' is an input of element V1"),
    (V1 + "inputs v10, v10\n", "'v10' is listed twice in the vectors"),
    (V1 + "inputs v01\n", "did you mean v11 or v10?"),
    (V1 + 'constraint C1 "x": ↑AVANCER1 = 1\n', "constraint C1: an edge cannot be negated"),
    (V1 + 'constraint C1 "x": !(↑AVANCER1 & v10) = 0\n', "constraint C1: an edge cannot be negated"),
    (V1.replace("↑AVANCER1 [v10] -> ↓v10", "↑v10: ↓v10 < ↑v11"), "the cause must be an edge of one of its orders"),
    ("free E = 0\nelement E {\n order A = 0\n}\n", "element 'E' is declared twice"),
    ((ROOT / "plants" / "lib" / "single_acting.rules").read_text()
     + "element V3 = single_acting(AVANCER=A3, AVANCER=B3)\n", "'AVANCER' is renamed twice"),
    (V1.replace("↑AVANCER1 [v10] -> ↓v10", "↑v10 -> ↓v11"), "the cause of a rule must be an edge of one of V1's orders"),
])
def test_other_checks(cli, tmp_path, text, needle):
    assert needle in _run(cli, tmp_path, text)


def test_not_keyword_and_byte_order_mark(cli, tmp_path):
    f = tmp_path / "bom.rules"
    f.write_bytes("\ufeff".encode() + (V1 + 'constraint C1 "x": not v10 & not v11 & AVANCER1 = 0\n').encode())
    code, out, err = cli("sup", f)
    assert code == 0, err


def test_constraint_too_large(cli, tmp_path):
    big = " | ".join(f"(A{i} & B{i})" for i in range(13))
    decl_a = ", ".join(f"A{i} = 0" for i in range(13))
    decl_b = ", ".join(f"B{i} = 0" for i in range(13))
    text = f"element EA {{ orders {decl_a} }}\nelement EB {{ orders {decl_b} }}\nconstraint C1 \"pairs\": {big} = 1\n"
    err = _run(cli, tmp_path, text)
    assert "constraint C1 is too large once expanded" in err


@pytest.mark.parametrize("text,where,name", [
    ("element E { order A = 0  sensor a = 0  free b = 0  ↑A -> ↑a  ↓A -> ↓a  ↑A -> ↑b }\n", "1:79", "b"),
    ("free dcy = 0\nelement E { order A = 0  sensor a = 0  ↑A -> ↑a  ↑A -> ↑dcy }\n", "2:57", "dcy"),
])
def test_rule_producing_a_free_input_is_an_error(cli, tmp_path, text, where, name):
    """Decision (docs/rules.md): free inputs are the operator's; a rule that produces one
    is bad input, not a rule that silently never applies."""
    err = _run(cli, tmp_path, text)
    assert err.splitlines()[0] == (
        f"bad.rules:{where}: error: rule of element E produces ↑{name}, but {name} is a free input: "
        "an operator changes it at any time, no rule produces it"
    )
    assert err.splitlines()[3] == f"  = note: declare {name} as a sensor of E if the element drives it"
