"""One identifier rule and one TIME literal for every generator (issue 20): ``synth st``,
``synth sfc`` and ``synth filter st`` refuse the same names, each at its ``file:line:col``,
and ``2min/X1`` is the same literal in the ST program and in the SFC."""

from __future__ import annotations

import pytest

from synth.cli.main import main


def _grafcet(tmp_path, name: str) -> str:
    path = tmp_path / "g.g7"
    path.write_text(f"grafcet G {{\n  initial step 0\n  step 1: A\n  transition 0 -> 1 when {name}\n"
                    "  transition 1 -> 0 when 2min/X1\n}\n")
    return str(path)


def test_a_timer_in_minutes_is_one_literal_everywhere(tmp_path, capsys):
    g7 = _grafcet(tmp_path, "go")
    assert main(["st", g7, "-o", str(tmp_path / "g.st")]) == 0
    assert main(["sfc", g7, "-o", str(tmp_path / "g.xml")]) == 0
    assert main(["st", g7, "--xml", "-o", str(tmp_path / "p.xml")]) == 0
    capsys.readouterr()
    st, sfc = (tmp_path / "g.st").read_text(), (tmp_path / "g.xml").read_text()
    assert "PT := T#2m)" in st and "S1.T >= T#2m)" in sfc and "PT := T#2m)" in (tmp_path / "p.xml").read_text()
    assert "T#120s" not in st + sfc


@pytest.mark.parametrize("name", ["ON", "LEFT", "RIGHT", "TON", "in", "mod"])
def test_a_name_refused_by_one_generator_is_refused_by_all(name, tmp_path, capsys):
    g7 = _grafcet(tmp_path, name)
    where = f"{g7}:4:26: error: '{name}' is an IEC 61131-3 keyword or standard name"
    for argv in (["st", g7], ["sfc", g7], ["st", g7, "--xml"]):
        assert main([*argv, "-o", str(tmp_path / "out")]) == 2
        assert capsys.readouterr().err.startswith(where)
        assert not (tmp_path / "out").exists()
    f = tmp_path / "f.filter"
    f.write_text(f"inputs i\noutputs {name}, o2\n\nsafety S1: i & {name}\n")
    assert main(["filter", "st", str(f), "--algorithm", "loop"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"{f}:4:") and f"{name} is a reserved word of IEC 61131-3" in err


@pytest.mark.parametrize("name", ["Start_1", "S", "r"])
def test_a_plain_name_passes_every_generator(name, tmp_path, capsys):
    g7 = _grafcet(tmp_path, name)
    for argv in (["st", g7], ["sfc", g7]):
        assert main([*argv, "-o", str(tmp_path / "out")]) == 0
    capsys.readouterr()


def test_a_reserved_name_no_constraint_reads_is_located_at_its_declaration(tmp_path, capsys):
    """It pointed at the first constraint (another token), or nowhere without constraints."""
    f = tmp_path / "f.filter"
    f.write_text("inputs i, ON\noutputs o1, o2\n\nsafety S1: i & o1\n")
    assert main(["filter", "st", str(f)]) == 2
    assert capsys.readouterr().err.startswith(f"{f}:1:11: error: cannot write the filter as Structured Text: "
                                              "ON is a reserved word of IEC 61131-3\n  1 | inputs i, ON\n")
