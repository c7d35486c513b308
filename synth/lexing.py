"""One regular expression per grammar for lark's contextual lexer.

lark's contextual lexer keeps one scanner per set of terminals a parser state accepts,
each a regular expression of those terminals compiled on first use: 43 of them for a
box-sorting validation, 10 ms of Python's ``re`` compiler in every run (docs/performance.md,
"Session 28"). :func:`share_scanners` gives each state a lexer that first tries one
expression of *all* the grammar's terminals, compiled once, and keeps its answer when that
is the state's own answer, which it provably is whenever the terminal found is one the
state's scanner holds:

- a scanner tries its terminals in one order (priority, longest possible match, longest
  text, name), the same order for every set of terminals, and takes the first that
  matches; the terminals before the one found in the whole order did not match, and
  neither did the state's own terminals among them, so the state's scanner finds the same
  terminal, and the same text (an alternative of an expression matches what it matches
  alone); when the state does not hold the terminal found, its own terminals after it
  in that order are tried one by one (each compiled once per grammar), the first that
  matches being, by the same argument, the state's answer;
- a keyword that a regular terminal of the state also matches (``inputs`` and ``NAME``) is
  not in the state's scanner but read back from the regular terminal's text, as lark does.

Where none of the state's terminals matches (a syntax error), lark's own lexer of the
state takes over and reports it as it always did. The tokens, and so the
trees and the error messages, are the same: ``tests/test_lexing.py`` parses every bundled
file and thousands of mutants of them both ways.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from lark import Lark

__all__ = ["share_scanners"]


class _Shared:
    """The expression of all of a grammar's terminals (the root lexer's order), and which
    string terminals each regular terminal reads as a keyword (lark's *unless* pairs)."""

    def __init__(self, root: Any) -> None:
        terminals = root.terminals
        self.regex = re.compile("|".join(f"(?P<{t.name}>{t.pattern.to_regexp()})" for t in terminals),
                                root.g_regex_flags)
        self.flags = root.g_regex_flags
        self.order = {t.name: i for i, t in enumerate(terminals)}
        self.alone: dict[str, re.Pattern[str]] = {}
        # per regular terminal: the strings whose whole text is what it matches in them, in
        # the scanners' order, and whether lark leaves each out of the scanner (its flags
        # within the terminal's); one expression tries every regular terminal at once, each
        # in a lookahead that keeps the text it matches alone
        regular = [t for t in terminals if t.pattern.type == "re"]
        each = re.compile("".join(f"(?:(?=(?P<{t.name}>{t.pattern.to_regexp()}))|)" for t in regular), self.flags)
        self.keywords: dict[str, list[tuple[Any, bool]]] = {t.name: [] for t in regular}
        for s in terminals:
            if s.pattern.type == "str" and (m := each.match(s.pattern.value)) is not None:
                for t in regular:
                    if s.priority == t.priority and m.group(t.name) == s.pattern.value:
                        self.keywords[t.name].append((s, s.pattern.flags <= t.pattern.flags))

    def plain(self, t: Any) -> bool:
        """A string terminal without flags: read by comparing text, no expression."""
        return bool(t.pattern.type == "str" and not t.pattern.flags and not self.flags)

    def match_alone(self, t: Any, text: str, pos: int, end: int) -> str | None:
        """What terminal ``t`` alone matches at ``pos`` (its expression compiled on first use)."""
        if self.plain(t):
            value = t.pattern.value
            return value if pos + len(value) <= end and text.startswith(value, pos) else None
        if (compiled := self.alone.get(t.name)) is None:
            compiled = self.alone[t.name] = re.compile(t.pattern.to_regexp(), self.flags)
        m = compiled.match(text, pos, end)
        return None if m is None else m.group(0)


class _StateLexer:
    """A parser state's lexer: the shared expression, and lark's lexer of the state
    (``lark_lexer``) for the errors."""

    def __init__(self, shared: _Shared, lark_lexer: Any) -> None:
        from lark import Token

        self.token = Token
        self.shared, self.lark_lexer = shared, lark_lexer
        names = {t.name for t in lark_lexer.terminals}
        self.keywords = {r: [s for s, _ in matched if s.name in names]
                         for r, matched in shared.keywords.items() if r in names}
        left_out = {s.name for r in self.keywords for s, out in shared.keywords[r] if out and s.name in names}
        self.scanned = frozenset(names - left_out)
        self.in_order = [(shared.order[t.name], t) for t in lark_lexer.terminals if t.name in self.scanned]
        self.ignore_types, self.newline_types = lark_lexer.ignore_types, lark_lexer.newline_types

    def match(self, text: Any, pos: int) -> tuple[str, str] | None:
        """The text and terminal of the state's scanner at ``pos`` (``None``: none matches)."""
        m = self.shared.regex.match(text.text, pos, text.end)
        if m is None:
            return None
        found = str(m.lastgroup)
        if found in self.scanned:
            return m.group(0), found
        after = self.shared.order[found]
        for i, t in self.in_order:
            if i > after and (alone := self.shared.match_alone(t, text.text, pos, text.end)) is not None:
                return alone, str(t.name)
        return None

    def keyword(self, type_: str, value: str) -> str:
        """The keyword ``value`` stands for in this state, or ``type_`` (lark's ``UnlessCallback``)."""
        for s in self.keywords.get(type_, ()):
            if value == s.pattern.value if self.shared.plain(s) else re.fullmatch(s.pattern.to_regexp(), value, self.shared.flags):
                return str(s.name)
        return type_

    def next_token(self, lex_state: Any, parser_state: Any = None) -> Any:
        """lark's ``BasicLexer.next_token``, reading with the shared expression."""
        line_ctr, text = lex_state.line_ctr, lex_state.text
        while line_ctr.char_pos < text.end:
            if (found := self.match(text, line_ctr.char_pos)) is None:  # an error: lark's own message
                return self.lark_lexer.next_token(lex_state, parser_state)
            value, type_ = found
            if type_ in self.ignore_types:
                line_ctr.feed(value, type_ in self.newline_types)
                continue
            t = self.token(self.keyword(type_, value), value, line_ctr.char_pos, line_ctr.line, line_ctr.column)
            line_ctr.feed(value, type_ in self.newline_types)
            t.end_line, t.end_column, t.end_pos = line_ctr.line, line_ctr.column, line_ctr.char_pos
            lex_state.last_token = t
            return t
        raise EOFError(self)


def share_scanners(p: Lark) -> Lark:
    """``p`` with its contextual lexer's states reading through one shared expression (the
    module's docstring); ``p`` unchanged when its lexer is not lark's plain contextual one
    (another lexer, callbacks, bytes, the ``regex`` module, terminals with groups of their own)."""
    from lark.lexer import BasicLexer, ContextualLexer

    lexer = getattr(p.parser, "lexer", None)
    if type(lexer) is not ContextualLexer or type(lexer.root_lexer) is not BasicLexer:
        return p
    root = lexer.root_lexer
    if root.re is not re or root.use_bytes or root.user_callbacks or any(
            type(s) is not BasicLexer for s in lexer.lexers.values()):
        return p
    if any(re.search(r"\(\?P[<=]|\\[1-9]", t.pattern.to_regexp()) for t in root.terminals):
        return p  # group names or back-references of their own would be renumbered
    try:
        shared = _Shared(root)
    except (re.error, AssertionError, OverflowError):
        return p
    mine: dict[int, _StateLexer] = {}  # lark shares one lexer among the states of one set of terminals
    for s in lexer.lexers.values():
        if id(s) not in mine:
            mine[id(s)] = _StateLexer(shared, s)
    states: dict[int, Any] = {state: mine[id(s)] for state, s in lexer.lexers.items()}
    lexer.lexers = states
    return p
