"""Every mistake in a .rules file: file:line:col, the line, a caret, suggestions, exit 2."""

from __future__ import annotations

import shutil
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


def test_typo_in_an_instantiation_is_reported_at_the_typo(cli, tmp_path):
    (tmp_path / "lib").mkdir()
    shutil.copy(ROOT / "plants/lib/double_acting.rules", tmp_path / "lib")
    shutil.copy(ROOT / "plants/lib/single_acting.rules", tmp_path / "lib")
    shutil.copy(ROOT / "plants/lib/conveyor.rules", tmp_path / "lib")
    text = (ROOT / "plants/tri.rules").read_text().replace("AVANCER=AVANCER2, RECULER", "AVANCER=AVANCR2, RECULER")
    lines = _run(cli, tmp_path, text).splitlines()
    assert lines == [
        "bad.rules:12:36: error: element V2 renames AVANCER to 'AVANCR2', which the file never uses; "
        "the vectors and constraints use 'AVANCER2' (lines 4, 18, 21)",
        "  12 | element V2 = double_acting(AVANCER=AVANCR2, RECULER=RECULER2, v0=v20, v1=v21)",
        "     |                                    ^~~~~~~",
        "  = did you mean AVANCER2?",
    ]


def test_missing_parenthesis_is_reported_where_it_is_missing(cli, tmp_path):
    text = "element V = m(A=B\nconstraint K \"k\": B = 0\n"
    lines = _run(cli, tmp_path, text).splitlines()
    assert lines[:3] == [
        "bad.rules:1:18: error: syntax error: unexpected end of line after 'B'",
        "  1 | element V = m(A=B",
        "    |                  ^",
    ]
    assert lines[3].startswith("  = expected ") and ")" in lines[3]


@pytest.mark.parametrize("sep", ["\f", "\r"])
def test_control_characters_do_not_shift_line_numbers(cli, tmp_path, sep):
    text = f"free dcy = 0\nelement E {{{sep} order A = 0  sensor a = 0  ↑A -> ↑a  ↓A -> ↓b }}\n"
    lines = _run(cli, tmp_path, text).splitlines()
    shown = chr(0x2400 + ord(sep))
    assert lines[:3] == [
        "bad.rules:2:58: error: unknown variable 'b' in element E",
        f"  2 | element E {{{shown} order A = 0  sensor a = 0  ↑A -> ↑a  ↓A -> ↓b }}",
        "    |                                                          ^",
    ]


@pytest.mark.parametrize("sep", ["\x0b", "\x1c"])
def test_other_control_characters_are_named(cli, tmp_path, sep):
    text = f"free dcy = 0\nelement E {{{sep} order A = 0 }}\n"
    lines = _run(cli, tmp_path, text).splitlines()
    assert lines[:3] == [
        f"bad.rules:2:12: error: syntax error: unexpected control character U+{ord(sep):04X}",
        f"  2 | element E {{{chr(0x2400 + ord(sep))} order A = 0 }}",
        "    |            ^",
    ]


def test_crlf_files_read_like_lf_files(cli, tmp_path):
    text = "free dcy = 0\r\nelement E { order A = 0  sensor a = 0  ↑A -> ↑a  ↓A -> ↓b }\r\n"
    lines = _run(cli, tmp_path, text).splitlines()
    assert lines[0] == "bad.rules:2:57: error: unknown variable 'b' in element E"
    assert lines[1] == "  2 | element E { order A = 0  sensor a = 0  ↑A -> ↑a  ↓A -> ↓b }"


def test_non_utf8_file_points_at_the_first_bad_byte(cli, tmp_path):
    f = tmp_path / "bad.rules"
    f.write_bytes("free dcy = 0\n# caf\xe9 ↑\nelement E { order A = 0 }\n".encode("latin-1", errors="replace"))
    code, out, err = cli("sup", f)
    assert code == 2 and "Traceback" not in err
    lines = err.replace(str(f), "bad.rules").splitlines()
    assert lines[:3] == [
        "bad.rules:2:6: error: not UTF-8 text: byte 0xe9 cannot start or continue a character",
        "  2 | # caf\ufffd ?",
        "    |      ^",
    ]
