"""synth's ST grammar derived at run time from the installed blark's ``iec.lark``: the
operations on blark's definitions, the fast path off (every text to blark's Earley parser) when
blark's grammar is not the one the derivation was written for, the parser cached by blark's
version and the derived text. That its trees are blark's is ``tests/test_st_parsing.py``."""

from __future__ import annotations

import zlib
from pathlib import Path
from typing import Iterator

import pytest

pytest.importorskip("blark")

from synth.codegen.interpreter import st_grammar  # noqa: E402
from synth.codegen.interpreter.grammar_edit import (  # noqa: E402
    Alternatives, Drop, InlineFlags, Keep, Never, Op, Priority, Rename, Required, Run, Semicolons, Words,
    derive_definitions)
from synth.codegen.interpreter.parsing import fast_tree, parse_st  # noqa: E402
from synth.codegen.interpreter.st_grammar import DERIVATION, derive, installed_grammar, st_parser  # noqa: E402
from synth.syntax import parser  # noqa: E402

INSTALLED = installed_grammar()
assert INSTALLED is not None
VERSION, BLARK = INSTALLED
PROGRAM = "PROGRAM p\nVAR x : BOOL; END_VAR\nx := NOT x;\nEND_PROGRAM\n"


@pytest.mark.parametrize("grammar, op, derived", [
    ('a: b | c "x" | d -> e', Keep(("c", "d")), 'a: c "x" | d -> e'),
    ('a: [ b ] ( c | d | e )', Keep(("d",)), "a: [ b ] ( d )"),
    ('A: "1" | "T"i', Alternatives((1,)), 'A: "T"i'),
    ("A: _B | _C", Never(), "A: /(?!)A/"),
    ('a: b ";"* ( c ";"+ )* ";"*', Semicolons(Run.ONE), 'a: b ";"? ( c ";" )* ";"?'),
    ('a: ";"* ( c ";"+ )* d ";"*', Semicolons(Run.NONE), 'a: ( c ";" )* d'),
    ('a: [ "1#" ] b ( "B#"i )? c ","? [ d ]', Drop(), "a: b c [ d ]"),
    ("a: b ( X b )* [ X ] X", Drop(("X",)), "a: b X"),
    ("a: [ X ] b ( X | c )", Rename("X", "Y"), "a: [ Y ] b ( Y | c )"),
    ('a: [ b ] c ";"+', Required("b"), 'a: b c ";"+'),
    ("A: /(?s){[^}]*?}/ B*", InlineFlags(), "A: /{[^}]*?}/s B*"),
    ("A.1: _X", Priority(2), "A.2: _X"),
])
def test_an_operation_edits_blarks_definition(grammar: str, op: Op, derived: str) -> None:
    name = grammar.split(":")[0].split(".")[0]
    assert derive_definitions(grammar, {name: (op,)}) == derived


def test_a_terminal_of_keywords_is_one_expression_of_its_words_in_blarks_order() -> None:
    grammar = "A: B | _C\nB: _D | /\\bE\\b/i\n_C: /\\bC\\b/i\n_D: /\\bD\\b/i\n"
    assert derive_definitions(grammar, {"A": (Words(),), "_C": (Words(),)}) == "A: /\\b(D|E|C)\\b/i\n_C: /\\bC\\b/i"


@pytest.mark.parametrize("grammar, op", [
    ("a: b | c", Keep(("d",))),
    ("a: b | c", Alternatives((2,))),
    ("a: b", Never()),
    ('a: b ";"', Semicolons(Run.ONE)),
    ("a: b c", Drop()),
    ("a: b", Rename("c", "d")),
    ("a: b", Required("b")),
    ('A: "x"i', Words()),
    ("A: /x/", InlineFlags()),
])
def test_an_operation_that_does_not_apply_gives_none(grammar: str, op: Op) -> None:
    assert derive_definitions(grammar, {grammar.split(":")[0]: (op,)}) is None


def test_the_installed_grammar_gives_every_definition_of_the_subset_once() -> None:
    derived = derive(BLARK)
    assert derived is not None
    names = [line.split(":")[0].lstrip("?").split(".")[0] for line in derived.splitlines() if not line.startswith("%")]
    assert sorted(names) == sorted([*DERIVATION, "located_body", "FIELD_DEREFERENCED"])
    assert 'exit_statement.1: _EXIT ";"' in derived.splitlines()
    assert "_statement: assignment_statement | return_statement | function_call_statement | if_statement" in derived


@pytest.mark.parametrize("change", [
    ("\nexit_statement.1:", "\nleave_statement.1:"),          # a definition the subset needs is gone
    ('_RETURN ";"+', '_RETURN ";"'),                          # an operation no longer applies
    ("          | boolean_literal\n", ""),                    # an alternative kept by name is gone
    ('TRUE_VALUE: "1" | "TRUE"i', 'TRUE_VALUE: "TRUE"i'),     # one kept by position
    ("_BOOL: /\\bBOOL\\b/i", '_BOOL: "BOOL"i'),               # a type name is no longer a keyword terminal
])
def test_an_altered_blark_grammar_turns_the_fast_path_off(change: tuple[str, str]) -> None:
    assert change[0] in BLARK
    assert derive(BLARK.replace(*change)) is None


@pytest.fixture
def fresh() -> Iterator[None]:
    st_parser.cache_clear()
    yield
    st_parser.cache_clear()


def test_with_the_fast_path_off_every_text_goes_to_blark(monkeypatch: pytest.MonkeyPatch, fresh: None) -> None:
    assert fast_tree(PROGRAM) is not None
    st_parser.cache_clear()
    monkeypatch.setattr(st_grammar, "installed_grammar", lambda: (VERSION, BLARK.replace('_EXIT ";"+', '_EXIT ";"')))
    assert st_parser("iec_source") is None and fast_tree(PROGRAM) is None
    result = parse_st(PROGRAM, "p.st")
    assert result.exception is None and type(result.transform().items[0]).__name__ == "Program"


def test_a_grammar_lark_refuses_turns_the_fast_path_off(monkeypatch: pytest.MonkeyPatch, fresh: None) -> None:
    # derivable, but a definition kept as blark writes it now names a rule outside the subset
    altered = BLARK.replace("_for_list: expression _TO expression", "_for_list: for_range _TO expression")
    assert altered != BLARK and derive(altered) is not None
    monkeypatch.setattr(st_grammar, "installed_grammar", lambda: (VERSION, altered))
    assert st_parser("statement_list") is None


def test_the_parser_is_cached_by_blarks_version_and_the_derived_text(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, fresh: None) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    parser.cache_clear()
    try:
        assert st_parser("statement_list") is not None
    finally:
        parser.cache_clear()
    text = derive(BLARK)
    assert text is not None
    assert [p.name.rsplit("-", 1)[0] for p in (tmp_path / "synth").iterdir()] == [
        f"lark-st-blark{VERSION}-statement_list-{zlib.crc32(text.encode()):08x}"]
