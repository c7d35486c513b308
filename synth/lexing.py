"""One regular expression per grammar for lark's contextual lexer.

lark's contextual lexer keeps one scanner per set of terminals a parser state accepts,
each a regular expression of those terminals compiled on first use: 43 of them for a
box-sorting validation, 10 ms of Python's ``re`` compiler in every run, and a lexer object
per set built when the parser is loaded, 2 ms more (docs/performance.md, "Session 28").
:func:`plugins` gives lark a contextual lexer whose states, made on first use, read with one
expression of *all* the grammar's terminals, compiled once, and keep its answer when that
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
state, made then, takes over and reports it as it always did. The tokens, and so the
trees and the error messages, are the same: ``tests/test_lexing.py`` parses every bundled
file and thousands of mutants of them both ways.
"""

from __future__ import annotations

import re
from typing import Any

__all__ = ["plugins", "LARK_TESTED"]


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
    """A parser state's lexer: the shared expression, and lark's lexer of the state (made
    on the first syntax error) for the errors."""

    def __init__(self, shared: _Shared, root: Any, conf: Any, names: frozenset[str]) -> None:
        from lark import Token

        self.token = Token
        self.shared, self.root, self.conf, self.names = shared, root, conf, names
        self.keywords = {r: [s for s, _ in matched if s.name in names]
                         for r, matched in shared.keywords.items() if r in names}
        left_out = {s.name for r in self.keywords for s, out in shared.keywords[r] if out and s.name in names}
        self.scanned = frozenset(names - left_out)
        # the root lexer's terminals are in the scanners' order already
        self.in_order = [(shared.order[t.name], t) for t in root.terminals if t.name in self.scanned]
        self.ignore_types, self.newline_types = root.ignore_types, root.newline_types & names
        self.lark_lexer: Any = None

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

    def lark_state_lexer(self) -> Any:
        """lark's own lexer of the state, as its contextual lexer makes it."""
        if self.lark_lexer is None:
            from copy import copy

            from lark.lexer import BasicLexer

            conf = copy(self.conf)
            conf.terminals = [t for t in self.root.terminals if t.name in self.names]
            conf.skip_validation = True  # the root lexer validated every terminal
            self.lark_lexer = BasicLexer(conf)
        return self.lark_lexer

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
                return self.lark_state_lexer().next_token(lex_state, parser_state)
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


class _Lexers(dict[int, Any]):
    """The lexer of each parser state, made when the parser first stands there (one per set
    of terminals, as lark shares them)."""

    def __init__(self, shared: _Shared, root: Any, conf: Any, states: dict[int, Any]) -> None:
        super().__init__()
        self.shared, self.root, self.conf, self.states = shared, root, conf, states
        self.by_names: dict[frozenset[str], _StateLexer] = {}

    def __missing__(self, state: int) -> _StateLexer:
        names = frozenset(n for n in (*self.states[state], *self.conf.ignore) if n in self.conf.terminals_by_name)
        if (made := self.by_names.get(names)) is None:
            made = self.by_names[names] = _StateLexer(self.shared, self.root, self.conf, names)
        self[state] = made
        return made


LARK_TESTED = ("1.3.",)
"""The lark releases whose lexer internals (``ContextualLexer``'s attributes and
``next_token``) this module was written and tested against; with any other, lark's own
lexer runs (a few milliseconds more per start, never another reading of a file)."""


def plugins() -> dict[str, type]:
    """lark's ``_plugins`` option giving a parser the shared contextual lexer (lark leaves the
    option out of its cache's key, and takes it when it loads a parser from the cache);
    empty (lark's own lexer) on a lark release not in :data:`LARK_TESTED`."""
    from copy import copy

    from lark import __version__ as lark_version
    from lark.lexer import BasicLexer, ContextualLexer

    if not lark_version.startswith(LARK_TESTED):
        return {}

    class SharedContextualLexer(ContextualLexer):
        """lark's contextual lexer, its states reading through one shared expression (the
        module's docstring), each made on first use; lark's own where a grammar or an option
        needs what the shared expression does not do (callbacks, bytes, the ``regex``
        module, terminals with groups of their own, a post-lexer)."""

        def __init__(self, conf: Any, states: dict[int, Any], always_accept: Any = ()) -> None:
            terminals = list(conf.terminals)
            if (conf.re_module is not re or conf.use_bytes or conf.callbacks or always_accept
                    or any(re.search(r"\(\?P[<=]|\\[1-9]", t.pattern.to_regexp()) for t in terminals)):
                super().__init__(conf, states, always_accept)  # group names or back-references would be renumbered
                return
            root_conf = copy(conf)
            root_conf.terminals = terminals
            self.root_lexer = BasicLexer(root_conf)
            self.lexers = _Lexers(_Shared(self.root_lexer), self.root_lexer, root_conf, states)

    return {"ContextualLexer": SharedContextualLexer}
