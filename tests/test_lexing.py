"""``synth.lexing``: lark's contextual lexer reading through one expression per grammar
gives the same tokens, trees and errors as lark's own, on every bundled file and on
mutants of them (docs/performance.md, "Session 28")."""

from __future__ import annotations

import random
from functools import lru_cache
from pathlib import Path

import pytest
from lark import Lark, Token, Tree, UnexpectedInput

from conftest import ROOT
from synth.lexing import LARK_TESTED, plugins
from synth.syntax import grammar_text, parser

SUFFIX = {".rules": "rules", ".g7": "grafcet", ".filter": "filter"}
FILES = sorted(p for p in ROOT.rglob("*") if p.suffix in SUFFIX and ".venv" not in p.parts and p.is_file())


@lru_cache(maxsize=None)
def lark_own(grammar: str, start: str = "start") -> Lark:
    """The parser ``synth.syntax.parser`` makes, with lark's own lexer."""
    return Lark(grammar_text(grammar), parser="lalr", propagate_positions=True, maybe_placeholders=True, start=start)


def shape(node: object) -> object:
    """A tree with every token's type and position (lark compares tokens as text only)."""
    if isinstance(node, Tree):
        meta = node.meta
        where = () if meta.empty else (meta.line, meta.column, meta.end_line, meta.end_column, meta.start_pos, meta.end_pos)
        return (node.data, where, [shape(c) for c in node.children])
    if isinstance(node, Token):
        return (node.type, str(node), node.line, node.column, node.end_line, node.end_column, node.start_pos, node.end_pos)
    return node


def outcome(p: Lark, text: str) -> object:
    try:
        return shape(p.parse(text))
    except UnexpectedInput as err:
        token = getattr(err, "token", None)
        lines = str(err).splitlines()  # the expected terminals are listed in a set's order
        return (type(err).__name__, [ln for ln in lines if not ln.startswith("\t*")], sorted(ln for ln in lines if ln.startswith("\t*")),
                err.line, err.column, sorted(getattr(err, "expected", None) or ()), None if token is None else shape(token))


def test_synth_parsers_use_the_shared_scanner() -> None:
    """Not vacuous: the parsers of synth.syntax read through synth.lexing, their states'
    lexers made as the parser meets them (on the lark releases it was written for)."""
    from lark import __version__ as lark_version

    if not lark_version.startswith(LARK_TESTED):
        pytest.skip(f"lark {lark_version}: synth.lexing leaves the lexing to lark")
    for grammar in ("rules", "grafcet", "filter"):
        lexer = parser(grammar).parser.lexer
        assert type(lexer).__name__ == "SharedContextualLexer", grammar
        parser(grammar).parse(next(p for p in FILES if SUFFIX[p.suffix] == grammar and "bad" not in p.parts).read_text(encoding="utf-8"))
        assert {type(s).__name__ for s in lexer.lexers.values()} == {"_StateLexer"}, grammar
        assert 0 < len(lexer.lexers) < len(parser(grammar).parser.parser.parser.parse_table.states), grammar
    assert len(FILES) > 60


@pytest.mark.parametrize("path", FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_bundled_file_lexes_and_parses_alike(path: Path) -> None:
    grammar = SUFFIX[path.suffix]
    text = path.read_text(encoding="utf-8")
    assert outcome(parser(grammar), text) == outcome(lark_own(grammar), text)


def mutants(text: str, rng: random.Random, count: int) -> list[str]:
    """``text`` with one character deleted, doubled or replaced by one of the file's own,
    or a word swapped with the next, or cut short."""
    alphabet = sorted(set(text)) + ["\n", "#", "&", "|", "!", "(", ")", "^", "_", "1", "x"]
    out = []
    for _ in range(count):
        i = rng.randrange(len(text))
        kind = rng.randrange(5)
        if kind == 0:
            out.append(text[:i] + text[i + 1:])
        elif kind == 1:
            out.append(text[:i] + text[i] + text[i:])
        elif kind == 2:
            out.append(text[:i] + rng.choice(alphabet) + text[i + 1:])
        elif kind == 3:
            words = text.split(" ")
            j = rng.randrange(max(1, len(words) - 1))
            words[j:j + 2] = words[j:j + 2][::-1]
            out.append(" ".join(words))
        else:
            out.append(text[:i])
    return out


def test_mutants_lex_parse_and_fail_alike() -> None:
    """Four hundred mutants of the bundled files: the same tree, or the same error (its
    kind, text, position, expected terminals and unexpected token)."""
    rng = random.Random(28)
    seen = {"tree": 0, "error": 0}
    for path in FILES:
        grammar = SUFFIX[path.suffix]
        for text in mutants(path.read_text(encoding="utf-8"), rng, 5):
            mine, theirs = outcome(parser(grammar), text), outcome(lark_own(grammar), text)
            assert mine == theirs, (path, text)
            seen["error" if isinstance(mine, tuple) and isinstance(mine[0], str) and mine[0].startswith("Unexpected") else "tree"] += 1
    assert seen["tree"] > 60 and seen["error"] > 60, seen  # both paths are exercised


def test_expressions_alike() -> None:
    for text in ["X0 & !v10", "↑a | ↓b & (c)", "a &", "2s/X1 & x", "cnt >= 3 & y", "a ^b", "(((a)))", "a | | b"]:
        for grammar in ("rules", "grafcet", "filter"):
            assert outcome(parser(grammar, "expr"), text) == outcome(lark_own(grammar, "expr"), text), (grammar, text)


def test_what_the_shared_lexer_leaves_to_lark() -> None:
    """Terminals with group names of their own, or lexer callbacks: lark's own states."""
    for grammar, options in [('start: WORD ("=" WORD)*\nWORD: /(?P<w>[a-z]+)/\n%ignore " "', {}),
                             ('start: WORD ("=" WORD)*\nWORD: /[a-z]+/\n%ignore " "', {"lexer_callbacks": {"WORD": lambda t: t}})]:
        p = Lark(grammar, parser="lalr", _plugins=plugins(), **options)
        assert {type(s).__name__ for s in p.parser.lexer.lexers.values()} == {"BasicLexer"}
        assert [str(t) for t in p.parse("ab = c").children] == ["ab", "c"]
    p = Lark('start: WORD ("=" WORD)*\nWORD: /[a-z]+/\n%ignore " "', parser="lalr", _plugins=plugins())
    assert [str(t) for t in p.parse("ab = c").children] == ["ab", "c"]
    assert {type(s).__name__ for s in p.parser.lexer.lexers.values()} == {"_StateLexer"}
