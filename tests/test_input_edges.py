"""Inputs at the edges (issue 24): expressions nested deeper than the readers can follow
(~500 consecutive ``!`` ended in a RecursionError traceback in every language), bad ``use``
paths, very many elements: a located error with exit 2, or an answer, never a traceback."""

from __future__ import annotations

import pytest

from conftest import ROOT
from synth.cli.main import main
from synth.syntax import MAX_DEPTH

DEEP = "!" * 600


def _run(argv: list[str], capsys) -> tuple[int, str]:
    code = main(argv)
    return code, capsys.readouterr().err


def test_deep_negation_in_rules(tmp_path, capsys):
    text = (ROOT / "tests/data/home/cylinder.rules").read_text().replace("↑AVANCER [v0]", f"↑AVANCER [{DEEP}v0]")
    (tmp_path / "deep.rules").write_text(text)
    code, err = _run(["plant", str(tmp_path / "deep.rules")], capsys)
    line = next(i for i, t in enumerate(text.splitlines(), 1) if DEEP in t)
    assert code == 2
    assert f"deep.rules:{line}:" in err and "nested too deeply" in err and "Traceback" not in err


def test_deep_negation_in_grafcet(tmp_path, capsys):
    text = (ROOT / "tests/data/home/production_loop.g7").read_text().replace("when v1", f"when {DEEP}v1")
    (tmp_path / "deep.g7").write_text(text)
    code, err = _run(["validate", str(tmp_path / "deep.g7"), "--plant", str(ROOT / "tests/data/home/cylinder.rules")], capsys)
    assert code == 2
    assert "deep.g7:8:" in err and "nested too deeply" in err


def test_deep_negation_in_filter(tmp_path, capsys):
    (tmp_path / "deep.filter").write_text(f"outputs o1, o2\n\nsafety CSc1: {DEEP}o1 & o2   keep o1\n")
    code, err = _run(["filter", "check", str(tmp_path / "deep.filter")], capsys)
    assert code == 2
    assert "deep.filter:3:" in err and "nested too deeply" in err


@pytest.mark.parametrize("home", [DEEP + "X1", "X1 & (" * 300 + "X1" + ")" * 300])
def test_deep_home_condition(home, capsys):
    code, err = _run(["validate", str(ROOT / "tests/data/home/production_loop.g7"), "--plant",
                      str(ROOT / "tests/data/home/cylinder.rules"), "--home", home], capsys)
    assert code == 2
    assert "--home:1:" in err and f"more than {MAX_DEPTH} levels" in err


def test_nesting_within_the_limit_and_redundant_parentheses_are_read(capsys):
    for home in ("!" * 150 + "X1", "(" * 5000 + "X1" + ")" * 5000):
        code, _ = _run(["validate", str(ROOT / "tests/data/home/production_loop.g7"), "--plant",
                        str(ROOT / "tests/data/home/cylinder.rules"), "--home", home, "--json"], capsys)
        assert code in (0, 1)


@pytest.mark.parametrize("use,message", [
    ('"a\x00b"', "embedded null byte"),
    ('"/dev/zero"', "not a regular file"),
    ('"' + "a" * 5000 + '"', "cannot read"),
    ('"."', "Is a directory"),
])
def test_bad_use_paths_are_located(use, message, tmp_path, capsys):
    """A NUL byte, a device that never ends (it hung and grew to 3.4 GB), a name longer than
    the system allows (it said "cannot write" with no location), a folder."""
    (tmp_path / "p.rules").write_text(f"use {use}\nfree x = 0\n")
    code, err = _run(["plant", str(tmp_path / "p.rules")], capsys)
    assert code == 2
    assert "p.rules:1:5: error: " in err and message in err and "Traceback" not in err


def _free_inputs(n: int) -> None:
    from synth.plant.composition import plant
    from synth.plant.rules_check import parse_rules

    p = plant(parse_rules("".join(f"free i{k} = {k % 2}\n" for k in range(n))))
    assert p.size == 2**n and len(p.elements) == n
    local = tuple(k % 2 for k in range(n))
    assert p.strides[-1] == 1 and p.strides[0] == 2 ** (n - 1)
    assert p.local(p.index(local)) == local


def test_two_thousand_free_inputs():
    """The plant's strides are computed in one pass (they were quadratic in the elements:
    24 s for 10 000 free inputs); the mixed-radix code of 2^2000 states still reads back its
    local indices. (At 10 000, nightly, the rules check's reads take most of the time.)"""
    _free_inputs(2_000)


@pytest.mark.nightly
def test_ten_thousand_free_inputs():
    _free_inputs(10_000)


@pytest.mark.parametrize("argv,note", [
    (["validate", "grafcets/tri.g7", "--plant", "grafcets/tri.g7"],
     "grafcets/tri.g7 is a Grafcet file (.g7), not a plant's rules file (.rules)"),
    (["validate", "plants/tri.rules", "--plant", "plants/tri.rules"],
     "plants/tri.rules is a plant's rules file (.rules), not a Grafcet file (.g7)"),
    (["filter", "check", "plants/tri.rules"],
     "plants/tri.rules is a plant's rules file (.rules), not a safety filter file (.filter)"),
])
def test_a_file_of_another_language_says_which(argv, note, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    code, err = _run(argv, capsys)
    assert code == 2
    assert f"= note: {note}: check the order of the arguments" in err
    assert ",," not in err  # the comma is quoted in the expected list, not a stray ",,"


def test_an_unclosed_parenthesis_is_reported_where_it_opens(tmp_path, capsys):
    (tmp_path / "p.g7").write_text("grafcet G {\n  initial step 0\n  step 1\n"
                                   "  transition 0 -> 1 when (dcy & v0\n  transition 1 -> 0 when v1\n}\n")
    code, err = _run(["validate", str(tmp_path / "p.g7"), "--plant", str(ROOT / "tests/data/home/cylinder.rules")], capsys)
    assert code == 2
    assert "p.g7:4:26: error: syntax error: '(' is never closed" in err
    assert "  4 |   transition 0 -> 1 when (dcy & v0" in err


@pytest.mark.parametrize("bad", ['refLocalId="x1"', 'refLocalId="²"', 'refLocalId=""'])
def test_a_non_numeric_reference_in_plcopen_xml_is_located(bad, tmp_path, capsys):
    """A connection's refLocalId that is no number (it was a ValueError traceback)."""
    from synth.codegen.plcopen.export import sfc_project_xml
    from synth.grafcet.language_check import parse_grafcet

    g = parse_grafcet("grafcet G { initial step 0 step 1: A transition 0 -> 1 when a transition 1 -> 0 when !a }", "g.g7")
    xml = sfc_project_xml(g, version="test").decode()
    first = xml.index('refLocalId="')
    xml = xml[:first] + bad + xml[xml.index('"', first + len('refLocalId="')) + 1:]
    (tmp_path / "p.xml").write_text(xml, encoding="utf-8")
    line = xml[:first].count("\n") + 1
    code, err = _run(["import", str(tmp_path / "p.xml"), "-o", str(tmp_path / "g.g7")], capsys)
    assert code == 2 and not (tmp_path / "g.g7").exists()
    assert f"p.xml:{line}:" in err and "refLocalId must be a number" in err and "Traceback" not in err


def test_running_out_of_memory_stops_with_exit_2(tmp_path, capsys, monkeypatch):
    """A closed loop larger than the machine (it ended in a traceback with exit 1, the
    'unsafe' code): exit 2 and a message naming the budget options."""
    import synth.filter.loop.verify as closed_loop

    def exhausted(*args: object, **kwargs: object) -> None:
        raise MemoryError

    monkeypatch.setattr(closed_loop, "verify", exhausted)
    skeleton = tmp_path / "F.filter"
    assert main(["filter", "from-rules", str(ROOT / "plants/tri.rules"), "-o", str(skeleton)]) == 0
    code, err = _run(["filter", "verify", str(skeleton), "--plant", str(ROOT / "plants/tri.rules"), "--any-control"], capsys)
    assert code == 2
    assert err.endswith("stopped: out of memory; bound the exploration with --max-states (or --max-nodes)\n")
