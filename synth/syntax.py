"""Loading the lark grammars shipped in ``grammars/`` and turning lark errors into
:class:`~synth.errors.InputError` with a caret and what was expected; what the languages
share (expressions, ``inputs``/``outputs`` lines, the error-collecting checker).

Example
-------
>>> try:
...     parse_expression("a &", "--home")
... except InputError as err:
...     print(err.message)
syntax error: unexpected end of file
"""

from __future__ import annotations

import os
import sys
import types
from enum import StrEnum
from functools import lru_cache
from pathlib import Path
from typing import Any, Sequence


class _RegexOnFirstUse(types.ModuleType):
    """What lark's ``import regex`` gets while :func:`_import_lark` runs: the third-party
    ``regex`` module, imported on first use of any of its attributes."""

    def __getattr__(self, name: str) -> Any:
        from importlib import import_module

        return getattr(import_module("regex"), name)


def _import_lark() -> None:
    """Import lark without importing ``regex`` (about 10 ms of every command's start-up).

    lark imports the third-party ``regex`` module whenever it is installed, yet uses it
    only for ``Lark(regex=True)`` and for terminals that ``re`` cannot read; synth's
    grammars need neither. While lark is imported, ``import regex`` gets a stand-in that
    imports the real module on first use, so lark keeps every capability (for any other
    user of lark in the process too); afterwards ``import regex`` gets the real module.
    """
    if "lark" in sys.modules or "regex" in sys.modules:
        return
    from importlib.util import find_spec

    if find_spec("regex") is None:  # not installed: lark already goes without
        return
    sys.modules["regex"] = stand_in = _RegexOnFirstUse("regex")
    try:
        import lark  # noqa: F401
    finally:
        if sys.modules.get("regex") is stand_in:
            del sys.modules["regex"]


_import_lark()

from lark import Lark, Token, Transformer, Tree, UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken, __version__ as lark_version  # noqa: E402,E501

from synth.errors import InputError, InputErrors, Location, location_in, source_lines  # noqa: E402
from synth.lexing import plugins  # noqa: E402
from synth.logic.expr import And, Const, Edge, Expr, Not, Or, Var  # noqa: E402

# ``Token`` is lark's, re-exported: every module of synth imports lark through this one.
__all__ = [
    "grammar_text", "parser", "syntax_error", "read_bytes", "read_source", "ExprTransformer", "VectorKind", "Checker", "raise_all",
    "parse_tree", "parse_expression", "Token"]

# How terminals are shown to a user in "expected ..." lists.
_TERMINAL_TEXT = {
    "NAME": "a name",
    "BIT": "0 or 1",
    "STRING": 'a "quoted text"',
    "RISE": "↑ (or ^)",
    "FALL": "↓ (or _)",
    "NOT": "! (not)",
    "AND": "& (and)",
    "OR": "| (or)",
    "ARROW": "->",
    "LBRACE": "{",
    "RBRACE": "}",
    "LPAR": "(",
    "RPAR": ")",
    "LSQB": "[",
    "RSQB": "]",
    "COLON": ":",
    "SEMICOLON": ";",
    "COMMA": "','",
    "EQUAL": "=",
    "LESSTHAN": "<",
    "SLASH": "/",
    "NUMBER": "a number",
    "SIGNED": "an integer",
    "CMP": "a comparison (>= <= = <> < >)",
    "ADDOP": "+ or -",
    "BOOL": "bool",
    "DURATION": "a duration such as 2s",
    "TIMER": "a timer such as 2s/X12",
    "_NL": "end of line",
    "$END": "end of file",
}


def grammar_text(name: str) -> str:
    """Text of ``grammars/<name>.lark``: installed (a folder read as files, no zipfile) or in the source tree."""
    from importlib import import_module
    from importlib.util import find_spec

    spec, filename = find_spec("synth.grammars"), f"{name}.lark"
    for folder in (spec.submodule_search_locations or []) if spec is not None else []:
        if (Path(folder) / filename).is_file():
            return (Path(folder) / filename).read_text(encoding="utf-8")
    try:  # a zip (importlib.resources: 1 ms, imported only then); no spec: a source tree not installed
        if spec is not None:
            return import_module("importlib.resources").files("synth.grammars").joinpath(filename).read_text(encoding="utf-8")
    except (ModuleNotFoundError, FileNotFoundError):
        pass
    return (Path(__file__).resolve().parent.parent / "grammars" / filename).read_text(encoding="utf-8")


@lru_cache(maxsize=None)
def parser(name: str, start: str = "start", text: str | None = None) -> Lark:
    """A cached LALR parser for ``grammars/<name>.lark`` (or the grammar ``text`` called ``name``) from rule ``start``."""
    options = dict(parser="lalr", propagate_positions=True, maybe_placeholders=True, start=start, _plugins=plugins())
    text = grammar_text(name) if text is None else text
    cache = _cache_file(name, start, text)
    if cache is not None:
        try:  # the compiled LALR tables, in the user's cache folder
            return Lark(text, cache=str(cache), **options)
        except OSError:  # an unwritable cache folder: build the tables again
            pass
    return Lark(text, **options)


def _cache_file(name: str, start: str, text: str) -> Path | None:
    """Where lark keeps the tables of one grammar: ``$XDG_CACHE_HOME/synth`` (by default
    ``~/.cache/synth``), one file per grammar text, start rule and lark version (never the
    shared temporary folder); ``None`` when there is no home to cache in."""
    import zlib  # a checksum for the file name (hashlib loads OpenSSL: 3 ms of every command)

    home = os.path.expanduser("~")
    base = os.environ.get("XDG_CACHE_HOME") or (os.path.join(home, ".cache") if home != "~" else "")
    if not base:
        return None
    try:
        (folder := Path(base) / "synth").mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    return folder / f"lark-{name}-{start}-{zlib.crc32(text.encode()):08x}-{lark_version}.cache"


def _shown(terminal: str, p: Lark) -> str:
    if terminal in _TERMINAL_TEXT:
        return _TERMINAL_TEXT[terminal]
    try:
        pattern = p.get_terminal(terminal).pattern
    except KeyError:
        return terminal.lower()
    if pattern.type == "str":
        return f"'{pattern.value}'"
    return terminal.lower()


def syntax_error(err: UnexpectedInput, file: str, source: str, p: Lark) -> InputError:
    """An :class:`InputError` for a lark parse error, with what would have been accepted."""
    line = getattr(err, "line", None) or 1
    column = getattr(err, "column", None) or 1
    if isinstance(err, UnexpectedEOF) or (
        isinstance(err, UnexpectedToken) and err.token.type == "$END"
    ):
        lines = source_lines(source)
        line = len(lines)
        column = len(lines[-1]) + 1
        found = "end of file"
        width = 1
        expected = err.expected
    elif isinstance(err, UnexpectedToken):
        found = f"'{err.token}'"
        width = max(1, len(str(err.token)))
        expected = err.accepts or err.expected
        history = getattr(err, "token_history", None) or ()
        prev = history[-1] if history else None
        if prev is not None and prev.end_line is not None and prev.end_line < line:
            # the line ended too early (a missing ')' or operand): point where it is missing
            line, column = prev.end_line, prev.end_column or 1
            found = f"end of line after '{prev}'"
            width = 1
    elif isinstance(err, UnexpectedCharacters):
        pos = err.pos_in_stream if err.pos_in_stream is not None else len(source)
        if pos < len(source):
            char = source[pos]
            found = f"character '{char}'" if char.isprintable() else f"control character U+{ord(char):04X}"
        else:
            found = "end of file"
        width = 1
        expected = err.allowed or set()
    else:  # pragma: no cover - lark has no other kinds
        found, width, expected = "input", 1, set()
    shown = sorted({_shown(t, p) for t in expected if not t.startswith("__ANON")})
    here = location_in(file, source, line, column, width)
    opened = _unclosed_parenthesis(source, err) if "RPAR" in expected else None
    if opened is not None and opened[0] != line:  # a '(' left open on an earlier line: report it there
        o_line, o_column = opened
        return InputError(
            "syntax error: '(' is never closed",
            location_in(file, source, o_line, o_column, 1),
            notes=(f"expected ')' before {found} at {line}:{column}",),
        )
    return InputError(f"syntax error: unexpected {found}", here, expected=shown[:12])


def _unclosed_parenthesis(source: str, err: UnexpectedInput) -> tuple[int, int] | None:
    """(line, column) of the innermost '(' still open where the parser stopped, or ``None``.
    Everything before that point was accepted, so its parentheses balance but for the open
    ones: the first unmatched '(' found walking back is the innermost."""
    pos = getattr(err, "pos_in_stream", None)
    token = getattr(err, "token", None)
    if pos is None and token is not None:
        pos = getattr(token, "start_pos", None)
    if pos is None:
        pos = len(source)
    depth = 0
    for i in range(min(pos, len(source)) - 1, -1, -1):
        c = source[i]
        if c == ")":
            depth += 1
        elif c == "(":
            if depth == 0:
                line = source.count("\n", 0, i) + 1
                return line, i - (source.rfind("\n", 0, i) + 1) + 1
            depth -= 1
    return None


MAX_SOURCE_BYTES = 64 * 1024 * 1024
"""The largest input file synth reads (a model of a real machine is a few hundred kB)."""


def read_bytes(path: str | Path, at: Location | None = None) -> bytes:
    """The bytes of a user file; an unreadable, non-regular (``/dev/zero``, a folder, a named
    pipe: refused before it is opened, which would wait for a writer) or over-large file is an
    :class:`InputError` "cannot read", located at ``at`` (the ``use`` that names it) when given.

    >>> read_bytes("/dev/zero")
    Traceback (most recent call last):
    ...
    synth.errors.InputError: error: cannot read '/dev/zero': not a regular file
    """
    import stat

    shown = str(path) if len(str(path)) <= 200 else str(path)[:200] + "…"
    try:
        mode = os.stat(path).st_mode
        if not stat.S_ISREG(mode):
            raise InputError(f"cannot read '{shown}': {'Is a directory' if stat.S_ISDIR(mode) else 'not a regular file'}", at)
        with open(path, "rb") as fh:
            info = os.fstat(fh.fileno())
            if not stat.S_ISREG(info.st_mode):
                raise InputError(f"cannot read '{shown}': not a regular file", at)
            if info.st_size > MAX_SOURCE_BYTES:
                raise InputError(f"cannot read '{shown}': {info.st_size} bytes, more than the {MAX_SOURCE_BYTES} synth reads", at)
            return fh.read(MAX_SOURCE_BYTES + 1)
    except OSError as exc:
        raise InputError(f"cannot read '{shown}': {exc.strerror or exc}", at) from None
    except ValueError as exc:  # a NUL byte in the name
        raise InputError(f"cannot read {shown!r}: {exc}", at) from None


def read_source(path: str | Path, at: Location | None = None) -> str:
    """The text of a user file (:func:`read_bytes`); a non-UTF-8 file is an
    :class:`InputError` located at its first bad byte."""
    data = read_bytes(path, at)
    try:
        return data.decode("utf-8-sig")  # a byte-order mark is dropped
    except UnicodeDecodeError as exc:
        start = data.rfind(b"\n", 0, exc.start) + 1
        line = data.count(b"\n", 0, exc.start) + 1
        text = data[start:].split(b"\n", 1)[0].decode("utf-8", errors="replace")
        column = len(data[start:exc.start].decode("utf-8", errors="replace")) + 1
        raise InputError(
            f"not UTF-8 text: byte 0x{data[exc.start]:02x} cannot start or continue a character",
            Location(str(path), line, column, text, 1),
            notes=("save the file as UTF-8 (synth reads ↑, ↓ and accented names in UTF-8)",),
        ) from None


class ExprTransformer(Transformer):
    """The expression rules shared by both grammars (``var``, ``const``, ``rise``,
    ``fall``, ``neg``, ``and_expr``, ``or_expr``) → :mod:`synth.logic.expr` objects that keep
    their :class:`~synth.errors.Location`."""

    def __init__(self, file: str, source: str) -> None:
        super().__init__()
        self.file = file
        self.source = source

    def _loc(self, tok: Token | Tree, width: int | None = None) -> Location:
        if isinstance(tok, Token):
            return location_in(self.file, self.source, tok.line or 1, tok.column or 1, width or len(str(tok)))
        meta = tok.meta
        return location_in(self.file, self.source, meta.line, meta.column, width or 1)

    def var(self, items: list) -> Var:
        (tok,) = items
        return Var(str(tok), self._loc(tok))

    def const(self, items: list) -> Const:
        (tok,) = items
        return Const(str(tok) == "1", self._loc(tok))

    def rise(self, items: list) -> Edge:
        _, tok = items
        return Edge(True, str(tok), self._loc(tok))

    def fall(self, items: list) -> Edge:
        _, tok = items
        return Edge(False, str(tok), self._loc(tok))

    def neg(self, items: list) -> Not:
        return Not(items[-1])

    def and_expr(self, items: list) -> And:
        return And(tuple(i for i in items if not isinstance(i, Token)))

    def or_expr(self, items: list) -> Or:
        return Or(tuple(i for i in items if not isinstance(i, Token)))


class VectorKind(StrEnum):
    """Which vector an ``inputs …`` or ``outputs …`` line lists (rules and ``.g7`` files)."""

    INPUTS = "inputs"
    OUTPUTS = "outputs"


def raise_all(errors: Sequence[InputError]) -> None:
    """Raise the errors of one file together (one :class:`InputError`, or :class:`InputErrors`)."""
    if len(errors) == 1:
        raise errors[0]
    if errors:
        raise InputErrors(errors)


MAX_DEPTH = 200
"""How deeply a parse tree may nest (``!``, ``&``, ``|`` and parentheses around operators
each add a level; ``((x))`` adds none): the readers and every walker over expressions
recurse, and a deeper input is refused with a located error instead of exhausting the
interpreter's stack."""


# What each language's files look like: a suffix, and keywords only its statements open with.
_KINDS = {
    "rules": (".rules", "a plant's rules file (.rules)", ("element ", "free ", "constraint ", "model ")),
    "grafcet": (".g7", "a Grafcet file (.g7)", ("grafcet ",)),
    "filter": (".filter", "a safety filter file (.filter)", ("safety ",)),
    "xml": (".xml", "a PLCopen XML file (.xml)", ("<?xml", "<project")),
    "st": (".st", "a Structured Text file (.st)", ("PROGRAM ", "FUNCTION_BLOCK ")),
}


def file_kind_hint(grammar: str, file: str, source: str) -> str | None:
    """When a file that fails to parse as ``grammar`` is another language's file (by its
    suffix, or, without its own suffix, by the keyword of a statement), say so.

    >>> file_kind_hint("rules", "tri.g7", "outputs A")
    "tri.g7 is a Grafcet file (.g7), not a plant's rules file (.rules): check the order of the arguments"
    >>> file_kind_hint("grafcet", "tri.g7", "grafcet G {") is None
    True
    >>> file_kind_hint("xml", "tri.g7", "grafcet G {")
    'tri.g7 is a Grafcet file (.g7), not a PLCopen XML file (.xml): check the order of the arguments'
    """
    if grammar not in _KINDS:
        return None
    own_suffix, own_what, _ = _KINDS[grammar]
    starts = [ln.strip() for ln in source.splitlines()[:200]]
    for other, (suffix, what, openers) in _KINDS.items():
        if other != grammar and (file.endswith(suffix) or (
                not file.endswith(own_suffix) and any(ln.startswith(openers) for ln in starts))):
            return f"{file} is {what}, not {own_what}: check the order of the arguments"
    return None


def _parsed(p: Lark, source: str, file: str, grammar: str) -> Tree:
    """``source`` parsed by ``p``: a syntax error, or a tree nested deeper than
    :data:`MAX_DEPTH`, becomes a located :class:`InputError`."""
    try:
        tree = p.parse(source)
    except UnexpectedInput as err:
        error = syntax_error(err, file, source, p)
        hint = file_kind_hint(grammar, file, source)
        if hint:
            error.notes = (*error.notes, hint)
        raise error from None
    stack: list[tuple[Tree, int]] = [(tree, 1)]
    while stack:  # iterative: the check itself must not recurse
        node, depth = stack.pop()
        if depth > MAX_DEPTH:
            meta = node.meta
            line, column = (meta.line, meta.column) if not meta.empty else (1, 1)
            raise InputError(
                f"expression nested too deeply: more than {MAX_DEPTH} levels of '!', '&', '|' or parentheses",
                location_in(file, source, line, column, 1),
                notes=("write !!x as x, and a long chain a & (b & (c & …)) as a & b & c & …",),
            )
        stack.extend((c, depth + 1) for c in node.children if isinstance(c, Tree))
    return tree


def parse_tree(grammar: str, source: str, file: str, transformer: Transformer) -> Any:
    """Parse ``source`` with ``grammars/<grammar>.lark`` and transform it; a syntax error
    becomes a located :class:`InputError`, and so does every error the transformer collected
    in an ``errors`` list."""
    tree = _parsed(parser(grammar), source, file, grammar)
    result = transformer.transform(tree)
    raise_all(getattr(transformer, "errors", ()))
    return result


def parse_expression(source: str, file: str, grammar: str = "rules", transformer: Transformer | None = None) -> Expr:
    """One Boolean expression in the syntax of ``grammars/<grammar>.lark`` (default: the
    rules syntax, as for a command-line condition such as ``--home "X0 & v10"``), its names
    located in ``file`` (the option's name).

    >>> parse_expression("X0 & !v10", "--home").text()
    'X0 & !v10'
    """
    tree = _parsed(parser(grammar, "expr"), source, file, "")
    return (transformer or ExprTransformer(file, source)).transform(tree)


class Checker:
    """Base of the checkers of every language: collects each located error of a file,
    so that a user sees all mistakes at once, then raises them together.

    >>> c = Checker()
    >>> c.fail("unknown variable 'x'", Location("a.g7", 1, 1, "x", 1), suggestions=("y",))
    >>> len(c.errors)
    1
    """

    def __init__(self) -> None:
        self.errors: list[InputError] = []

    def fail(self, message: str, location: Location | None, **details: Any) -> None:
        self.errors.append(InputError(message, location, **details))

    def raise_errors(self) -> None:
        raise_all(self.errors)
