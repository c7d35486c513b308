"""synth's LALR grammar of the ST it emits (derived at run time from the installed blark's grammar: ``synth.codegen.interpreter.st_grammar``) against blark's Earley
parser, the oracle: the same lark tree (rules, tokens and their types, every position) on
the programs synth writes — bundled Grafcets, each target, the filter blocks, random
Grafcets — and, on mutants of small programs, never a text it reads that blark reads
otherwise or refuses. What the grammar refuses goes to blark: the language, the trees and
the errors stay blark's."""

from __future__ import annotations

import random
from pathlib import Path

import pytest

pytest.importorskip("blark")

from blark import util  # noqa: E402
from blark.parse import get_parser  # noqa: E402
from blark.solution import TcSource  # noqa: E402
from blark.transform import transform  # noqa: E402
from lark import LarkError, Token, Tree  # noqa: E402

from conftest import ROOT  # noqa: E402
from randgrafcet import random_grafcet  # noqa: E402
from synth.cli.main import main  # noqa: E402
from synth.codegen.filter_st import filter_block  # noqa: E402
from synth.codegen.grafcet_st import generate_program  # noqa: E402
from synth.codegen.interpreter.machine import load_st  # noqa: E402
from synth.codegen.interpreter.parsing import fast_tree, parse_st  # noqa: E402
from synth.codegen.targets import Target, st_of  # noqa: E402
from synth.errors import InputError  # noqa: E402
from synth.filter.cycle import Algorithm, Mode  # noqa: E402
from synth.filter.language_check import load_filter  # noqa: E402
from synth.grafcet.language_check import load_grafcet, parse_grafcet  # noqa: E402

_META = ("line", "column", "end_line", "end_column", "start_pos", "end_pos", "empty")


def difference(a: object, b: object, path: str = "") -> str | None:
    """Where two lark trees differ: rule, children, token type, text or position, a node's
    position; ``None`` when equal."""
    if isinstance(a, Tree) and isinstance(b, Tree):
        here = f"{path}/{a.data}"
        if a.data != b.data or len(a.children) != len(b.children):
            return f"{here}: {a.data}{len(a.children)} vs {b.data}{len(b.children)}"
        for key in _META:
            if getattr(a.meta, key, None) != getattr(b.meta, key, None):
                return f"{here}: {key} {getattr(a.meta, key, None)} vs {getattr(b.meta, key, None)}"
        return next((d for i, (x, y) in enumerate(zip(a.children, b.children))
                     if (d := difference(x, y, f"{here}[{i}]"))), None)
    if isinstance(a, Token) and isinstance(b, Token):
        keys = ("type", "value", "line", "column", "end_line", "end_column", "start_pos", "end_pos")
        return None if all(getattr(a, k) == getattr(b, k) for k in keys) else f"{path}: {a!r} vs {b!r}"
    return None if a is None and b is None else f"{path}: {a!r} vs {b!r}"


def earley(text: str, start: str = "iec_source") -> Tree | None:
    """blark's own parse of ``text`` (comments blanked as blark does), ``None`` if it refuses it."""
    _, clean = util.find_and_clean_comments(text)
    try:
        return get_parser().parse(clean, start=start)
    except LarkError:
        return None


def assert_same_tree(text: str, start: str = "iec_source") -> None:
    """synth's grammar reads ``text`` into blark's Earley tree, and so into the same blark
    dataclasses (their ``repr`` holds every position)."""
    fast, slow = fast_tree(text, start), earley(text, start)
    assert fast is not None, "synth's grammar refuses a text synth writes"
    assert difference(fast, slow) is None
    comments, _ = util.find_and_clean_comments(text)
    assert repr(transform(source_code=text, tree=fast, comments=comments)) == repr(
        transform(source_code=text, tree=slow, comments=comments))


def _program(path: str, **options: object) -> str:
    return generate_program(load_grafcet(ROOT / path), version="test", **options).text  # type: ignore[arg-type]


def _cli(tmp_path: Path, *args: str) -> str:
    out = tmp_path / "p.st"
    assert main(["st", *args, "-o", str(out)]) == 0
    return out.read_text(encoding="utf-8")


@pytest.mark.parametrize("name", ["timers.g7", "conditional.g7"])
def test_a_bundled_programs_tree_is_blarks(name: str) -> None:
    assert_same_tree(_program(f"grafcets/{name}", comments=False))


def test_a_filter_block_with_its_tables_is_blarks() -> None:
    f = load_filter(ROOT / "plants/loop_a.filter")
    assert_same_tree(filter_block(f, Algorithm.LOOP, Mode.BLOCKING).text)


def test_a_program_with_its_filter_located_variables_and_comments_is_blarks(tmp_path: Path) -> None:
    data = ROOT / "tests/data/filter"
    assert_same_tree(_cli(tmp_path, str(data / "two.g7"), "--plant", str(data / "two.rules"),
                          "--filter", str(data / "two_no_edge.filter"), "--io", "plain"))


def test_a_twincat_pous_declaration_and_body_are_blarks(tmp_path: Path) -> None:
    path = tmp_path / "timers.TcPOU"
    assert main(["st", str(ROOT / "grafcets/timers.g7"), "--target", "twincat", "-o", str(path)]) == 0
    parts = [p for item in TcSource.from_contents(path.read_bytes(), filename=None).to_blark() for p in item.parts]
    assert [p.grammar_rule for p in parts] == ["program_declaration", "statement_list"]
    for part in parts:
        assert_same_tree(part.get_code_and_line_map()[0], part.grammar_rule)


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 6, 7, 16])
def test_an_array_initialiser_nests_as_earley_nests_it(n: int) -> None:
    values = ", ".join(random.Random(n).choice(["TRUE", "FALSE", "0", "-3", "7"]) for _ in range(n))
    assert_same_tree(f"PROGRAM p\nVAR\n  a : ARRAY[1..{n}] OF INT := [{values}];\nEND_VAR\nEND_PROGRAM\n")


LOCATED = """PROGRAM p
VAR
  x AT %QX0.0 : BOOL;
  y AT %QX0.1 : BOOL := TRUE;
END_VAR
VAR
  a AT %IX0.0 : BOOL;
  b, c : BOOL;
END_VAR
VAR_OUTPUT z AT %QX0.2 : BOOL; END_VAR
VAR RETAIN w AT %MW3 : INT; END_VAR
END_PROGRAM
FUNCTION_BLOCK f
VAR x AT %QX1.0 : BOOL; END_VAR
END_FUNCTION_BLOCK
"""


def test_located_declarations_are_read_as_blark_reads_them() -> None:
    assert_same_tree(LOCATED)
    program, block = fast_tree(LOCATED).children
    assert [b.data for b in program.children[1].children] == [
        "located_var_declarations", "var_declarations", "output_declarations", "located_var_declarations"]
    assert block.children[5].data == "var_declarations"


def test_what_the_grammar_refuses_goes_to_blark() -> None:
    text = "PROGRAM p\nVAR x : INT; END_VAR\nCASE x OF 1: x := 2; END_CASE;\nEND_PROGRAM\n"
    assert fast_tree(text) is None and earley(text) is not None
    assert type(parse_st(text, "c.st").transform().items[0]).__name__ == "Program"
    initialised = "PROGRAM p\nVAR a : ARRAY[1..2] OF INT := [x, 1]; END_VAR\nEND_PROGRAM\n"
    assert fast_tree(initialised) is None  # not a list of constants: Earley's nesting is not assumed
    empty = "PROGRAM p\nVAR\nEND_VAR\nEND_PROGRAM\n"
    assert fast_tree(empty) is None and earley(empty) is not None  # Earley reads another rule than VAR's
    with pytest.raises(InputError) as error:  # an error is blark's, at blark's place
        load_st("PROGRAM P\nVAR x : BOOL; END_VAR\nx := x AND ;\nEND_PROGRAM\n", "bad.st")
    assert (error.value.location.line, error.value.location.column) == (3, 12)


SMALL = """PROGRAM p
VAR_INPUT a, b : BOOL; END_VAR
VAR_OUTPUT q : BOOL; END_VAR
VAR tm : TON; k : INT := 0; f : ARRAY[1..3] OF BOOL := [TRUE, FALSE, TRUE]; END_VAR
VAR CONSTANT m : INT := 2; END_VAR
tm(IN := a, PT := T#1s500ms);
f[k + 1] := a AND NOT b OR tm.Q;
IF k >= m THEN q := f[1] XOR b; ELSIF k <> 1 THEN k := -k * 2 MOD 3; ELSE EXIT; END_IF;
FOR k := 1 TO 3 BY 1 DO q := (q OR f[k]) = TRUE; END_FOR;
WHILE FALSE DO RETURN; END_WHILE;
REPEAT k := k - 1; UNTIL k < 0 END_REPEAT;
END_PROGRAM
"""

# words and signs a mutant puts in: keywords, type names, literals, operators, blark's other constructs
SPARE = ["TRUE", "FALSE", "T", "TIME", "INT", "BOOL", "CONSTANT", "RETAIN", "ARRAY", "OF", "POINTER", "TO", "^",
         ":=", "=>", ";", ";;", ",", ".", "..", "#", "T#2s", "1", "-1", "1.5", "16#F", "INT#3", "%IX0.0", "AT", "(",
         ")", "[", "]", "x", "NOT", "AND", "OR", "=", "<>", "<", "<=", "+", "-", "*", "END_IF", "ELSE", "'s'", "S=",
         "DO", "THEN", "END_VAR", "VAR_TEMP", "R_EDGE", "{attribute 'x'}", "(* c *)", "// c\n"]


def mutants(text: str, seed: int, count: int) -> list[str]:
    """``count`` mutants of ``text``: a token deleted, doubled or replaced by a spare word."""
    rnd, words = random.Random(seed), text.replace("\n", " \n ").split(" ")
    out = []
    for _ in range(count):
        w, i = list(words), rnd.randrange(len(words))
        kind = rnd.randrange(3)
        w[i:i + 1] = [] if kind == 0 else [w[i], w[i]] if kind == 1 else [rnd.choice(SPARE)]
        out.append(" ".join(w).replace(" \n ", "\n"))
    return out


# Texts where blark's grammar is ambiguous or close to the subset's edge: each one the grammar
# reads gives blark's tree, the others go to blark (an empty statement after END_VAR, a variable
# named like the T# prefix in an expression, a run of ';').
EDGES = ["x := 1;", "x := TRUE;", "k := -1;", "t(IN := a, PT := t#2m5s);", "t(IN := a, PT := TIME#2ms);", "t(a, T#1.5s);",
         "IF a THEN END_IF x := 0;", "IF a THEN x := 1; END_IF;;", "REPEAT RETURN; UNTIL a END_REPEAT; IF a THEN ; END_IF;",
         "x := a = b = x;", "T := 1;", "k := T;", "x := a.1;", "x := 1; {pragma}; x := 2;", "x := CONSTANT;"]
DECLARATIONS = ["VAR x : BOOL := 1; END_VAR", "VAR x : TIME := T#1s; y : TOD; END_VAR", "VAR_OUTPUT x : BOOL; END_VAR;",
                "VAR x : ARRAY[1..2] OF LREAL := [1, -1]; END_VAR", "VAR x : MyFb; END_VAR", "VAR x : BOOL;; END_VAR"]


@pytest.mark.parametrize("text", [
    *(f"PROGRAM p\nVAR_INPUT a, b : BOOL; END_VAR\nVAR x : BOOL; k : INT; t : TON; END_VAR\n{body}\nEND_PROGRAM\n" for body in EDGES),
    *(f"FUNCTION_BLOCK f\n{declaration}\nEND_FUNCTION_BLOCK\n" for declaration in DECLARATIONS)])
def test_an_edge_of_the_subset_is_blarks_or_goes_to_blark(text: str) -> None:
    fast = fast_tree(text)
    assert fast is None or difference(fast, earley(text)) is None


def test_the_small_program_is_read_and_is_blarks() -> None:
    assert_same_tree(SMALL)


def test_a_mutant_the_grammar_reads_is_blarks_tree() -> None:
    read = 0
    for seed in range(4):
        for text in mutants(SMALL, seed, 12):
            if (fast := fast_tree(text)) is not None:
                read += 1
                assert difference(fast, earley(text)) is None, text
    assert read == 7  # the other 41 go to blark


@pytest.mark.nightly  # minutes of blark's Earley parser: pytest -m nightly
def test_every_generated_program_is_blarks(tmp_path: Path) -> None:
    texts = []
    for path in sorted((ROOT / "grafcets").glob("*.g7")):
        texts += [_program(f"grafcets/{path.name}"), _program(f"grafcets/{path.name}", comments=False)]
    for path in sorted((ROOT / "plants").glob("*.filter")):
        for algorithm in Algorithm:
            for mode in Mode:
                try:
                    texts.append(filter_block(load_filter(path), algorithm, mode).text)
                except InputError:  # no block for this filter and algorithm
                    pass
    tri = [str(ROOT / "grafcets/tri.g7"), "--plant", str(ROOT / "plants/tri.rules"), "--filter", str(ROOT / "plants/tri.filter")]
    for target in Target:
        out = tmp_path / target.value
        assert main(["st", *tri, "--target", target.value, "-o", str(out / "x") if target is Target.TWINCAT else str(out)]) == 0
        files = sorted((p.name, p.read_bytes()) for p in ((out / "x").iterdir() if target is Target.TWINCAT else [out]))
        texts.append(st_of(target, files, "tri"))
    for text in texts:
        assert_same_tree(text)


@pytest.mark.nightly
@pytest.mark.parametrize("block", range(4))
def test_random_grafcets_programs_are_blarks(block: int) -> None:
    for seed in range(1 + 50 * block, 51 + 50 * block):
        g = parse_grafcet(random_grafcet(seed, data=seed % 2 == 0), f"random{seed}.g7")
        assert_same_tree(generate_program(g, version="test", comments=False).text)


@pytest.mark.nightly
@pytest.mark.parametrize("seed", range(4, 40))
def test_more_mutants(seed: int) -> None:
    for text in mutants(SMALL, seed, 12):
        fast = fast_tree(text)
        assert fast is None or difference(fast, earley(text)) is None, text
