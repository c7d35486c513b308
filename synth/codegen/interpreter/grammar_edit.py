"""Editing a lark grammar's definitions by name: a definition read as a small tree of choices,
sequences and groups, and operations on it (keep some alternatives, drop optional parts, a
terminal that never matches...), each raising :class:`Underivable` when it does not apply.
``synth.codegen.interpreter.st_grammar`` uses them to derive synth's ST grammar from blark's.

Example
-------
>>> rules = {"exit_statement": (Semicolons(Run.ONE),), "flag": (Alternatives((1,)),)}
>>> derive_definitions('exit_statement.1: _EXIT ";"+\\nflag: "0" | "1"\\n', rules)
'exit_statement.1: _EXIT ";"\\nflag: "1"'
>>> derive_definitions('exit_statement.1: _EXIT\\n', rules) is None
True
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from enum import Enum
from functools import cached_property
from typing import Union

__all__ = ["Underivable", "Definition", "definitions", "derive_definitions", "Run", "Op", "Keep", "Alternatives", "Never",
           "Semicolons", "Drop", "Rename", "Required", "Words", "Priority", "InlineFlags"]


class Underivable(Exception):
    """blark's grammar is not the one the derivation was written for."""


# ---- blark's definitions, as a small tree of choices, sequences and groups -------------------

_TOKEN = re.compile(r'\s*(?:("(?:\\.|[^"\\])*"i?)|(/(?:\\.|[^/\\\n])+/[imslux]*)|(->)|([A-Za-z_][A-Za-z_0-9]*)|([()\[\]|?*+]))')


@dataclass
class Group:
    """``( choice )`` or ``[ choice ]`` (``bracket``: the optional form)."""
    choice: list[Alternative]
    bracket: bool


@dataclass
class Item:
    """A name, a literal or a group, with its suffix (``?``, ``*``, ``+`` or none)."""
    atom: Union[str, Group]
    suffix: str = ""

    def optional(self) -> bool:
        return self.suffix in ("?", "*") or isinstance(self.atom, Group) and self.atom.bracket


@dataclass
class Alternative:
    items: list[Item]
    alias: str | None = None


def _tokens(text: str) -> list[str]:
    out, pos = [], 0
    while text[pos:].strip():
        match = _TOKEN.match(text, pos)
        if match is None:
            raise Underivable(f"cannot read {text[pos:pos + 20]!r}")
        out.append(next(g for g in match.groups() if g is not None))
        pos = match.end()
    return out


def _choice(tokens: list[str], at: int) -> tuple[list[Alternative], int]:
    choice = [Alternative([])]
    while at < len(tokens) and tokens[at] not in (")", "]"):
        token, at = tokens[at], at + 1
        if token == "|":
            choice.append(Alternative([]))
        elif token == "->":
            choice[-1].alias, at = tokens[at], at + 1
        elif token in "?*+" and choice[-1].items:
            choice[-1].items[-1].suffix = token
        elif token in ("(", "["):
            inner, at = _choice(tokens, at)
            choice[-1].items.append(Item(Group(inner, token == "[")))
            at += 1
        else:
            choice[-1].items.append(Item(token))
    return choice, at


def _text(choice: list[Alternative]) -> str:
    def item(i: Item) -> str:
        if isinstance(i.atom, Group):
            inner = _text(i.atom.choice)
            return (f"[ {inner} ]" if i.atom.bracket else f"( {inner} )") + i.suffix
        return i.atom + i.suffix
    return " | ".join(" ".join(item(i) for i in a.items) + (f" -> {a.alias}" if a.alias else "") for a in choice)


def _mentions(a: Alternative | Item, names: frozenset[str]) -> bool:
    items = a.items if isinstance(a, Alternative) else [a]
    return any(i.atom in names if isinstance(i.atom, str) else any(_mentions(b, names) for b in i.atom.choice)
               for i in items)


def _named(a: Alternative | Item) -> bool:
    """Whether ``a`` holds a rule or terminal name (else only literals)."""
    items = a.items if isinstance(a, Alternative) else [a]
    return any(re.fullmatch(r"\w+", i.atom) is not None if isinstance(i.atom, str) else any(_named(b) for b in i.atom.choice)
               for i in items)


def _items(choice: list[Alternative]) -> list[Item]:
    """Every item of ``choice``, at every depth."""
    out = []
    for a in choice:
        for i in a.items:
            out.append(i)
            if isinstance(i.atom, Group):
                out += _items(i.atom.choice)
    return out


@dataclass
class Definition:
    """One definition of a lark grammar, ``?name.2: body``; its body read into choices when an
    operation or the text needs it."""
    prefix: str
    name: str
    priority: str
    body: str

    @cached_property
    def choice(self) -> list[Alternative]:
        tokens = _tokens(self.body)
        choice, at = _choice(tokens, 0)
        if at != len(tokens):
            raise Underivable(f"unbalanced {self.name}")
        return choice

    def text(self) -> str:
        return f"{self.prefix}{self.name}{self.priority}: {_text(self.choice)}"


_HEAD = re.compile(r"([!?]*)([A-Za-z_]\w*)(\.-?\d+)?\s*:(?!=)(.*)")


def definitions(grammar: str) -> tuple[dict[str, Definition], list[str]]:
    """The definitions of the lark ``grammar`` by name, and its ``%`` directives."""
    found: dict[str, tuple[str, str, list[str]]] = {}
    directives: list[str] = []
    current: list[str] | None = None
    for line in grammar.splitlines():
        head = _HEAD.fullmatch(line)
        if head is not None:
            current = [head.group(4)]
            found[head.group(2)] = (head.group(1), head.group(3) or "", current)
        elif line[:1].isspace() and line.strip() and current is not None:
            current.append(line)
        else:
            current = None
            if line.startswith("%"):
                directives.append(line.strip())
    return {name: Definition(prefix, name, priority, " ".join(lines)) for name, (prefix, priority, lines) in found.items()}, directives


# ---- the operations ------------------------------------------------------------------------


class Run(Enum):
    """What becomes of a run of ``";"``: ``ONE`` (``";"+`` one, ``";"*`` at most one), ``NONE``
    (``";"*`` dropped, ``";"+`` one)."""
    ONE = "one"
    NONE = "none"


@dataclass(frozen=True)
class Keep:
    """In every choice where some alternative mentions one of ``names``, only those alternatives."""
    names: tuple[str, ...]

    def apply(self, d: Definition, grammar: dict[str, Definition]) -> None:
        names, found = frozenset(self.names), set[str]()

        def filtered(choice: list[Alternative]) -> list[Alternative]:
            if len(choice) > 1 and any(_mentions(a, names) for a in choice):
                choice = [a for a in choice if _mentions(a, names)]
                found.update(n for n in names if any(_mentions(a, frozenset([n])) for a in choice))
            for group in (i.atom for a in choice for i in a.items if isinstance(i.atom, Group)):
                group.choice = filtered(group.choice)
            return choice
        d.choice = filtered(d.choice)
        if found != names:
            raise Underivable(f"{d.name} has no alternative {sorted(names - found)}")


@dataclass(frozen=True)
class Alternatives:
    """The alternatives at ``positions`` (from 0) of the definition."""
    positions: tuple[int, ...]

    def apply(self, d: Definition, grammar: dict[str, Definition]) -> None:
        if max(self.positions) >= len(d.choice):
            raise Underivable(f"{d.name} has {len(d.choice)} alternatives")
        d.choice = [d.choice[p] for p in self.positions]


@dataclass(frozen=True)
class Never:
    """A terminal that never matches: blark's optional parts holding it stay as placeholders."""

    def apply(self, d: Definition, grammar: dict[str, Definition]) -> None:
        if not d.name.isupper():
            raise Underivable(f"{d.name} is not a terminal")
        d.choice = [Alternative([Item(f"/(?!){d.name}/")])]


@dataclass(frozen=True)
class Semicolons:
    """Runs of ``";"`` (``";"*``, ``";"+``, at any depth) made as :class:`Run` says."""
    run: Run

    def apply(self, d: Definition, grammar: dict[str, Definition]) -> None:
        runs = 0

        def mended(choice: list[Alternative]) -> None:
            nonlocal runs
            for a in choice:
                kept = []
                for i in a.items:
                    if isinstance(i.atom, Group):
                        mended(i.atom.choice)
                    elif i.atom == '";"' and i.suffix in ("*", "+"):
                        runs += 1
                        if i.suffix == "*" and self.run is Run.NONE:
                            continue
                        i.suffix = "?" if i.suffix == "*" else ""
                    kept.append(i)
                a.items = kept
        mended(d.choice)
        if not runs:
            raise Underivable(f"{d.name} has no run of ';'")


@dataclass(frozen=True)
class Drop:
    """The optional or repeated parts that mention one of ``names`` (none given: the ones
    holding only literals, which leave no placeholder in the tree)."""
    names: tuple[str, ...] = ()

    def apply(self, d: Definition, grammar: dict[str, Definition]) -> None:
        names, dropped = frozenset(self.names), 0

        def gone(i: Item) -> bool:
            return i.optional() and (_mentions(i, names) if names else not _named(i))
        choices = [d.choice, *(i.atom.choice for i in _items(d.choice) if isinstance(i.atom, Group))]
        for a in (a for choice in choices for a in choice):
            dropped += sum(map(gone, a.items))
            a.items = [j for j in a.items if not gone(j)]
        if not dropped:
            raise Underivable(f"{d.name} has no optional part to drop")


@dataclass(frozen=True)
class Rename:
    """The symbol ``old`` read as ``new`` (a rule or terminal of synth's)."""
    old: str
    new: str

    def apply(self, d: Definition, grammar: dict[str, Definition]) -> None:
        _replace([i for i in _items(d.choice) if i.atom == self.old], self.new, f"{d.name} does not mention {self.old}")


def _replace(items: list[Item], atom: str, missing: str) -> None:
    """Every one of ``items`` made ``atom``; :class:`Underivable` (``missing``) when there is none."""
    if not items:
        raise Underivable(missing)
    for i in items:
        i.atom = atom


@dataclass(frozen=True)
class Required:
    """``[ name ]`` made ``name``: the form without it is left to blark's parser."""
    name: str

    def apply(self, d: Definition, grammar: dict[str, Definition]) -> None:
        items = [i for i in _items(d.choice) if isinstance(i.atom, Group) and i.atom.bracket
                 and _text(i.atom.choice) == self.name]
        _replace(items, self.name, f"{d.name} has no optional {self.name}")


@dataclass(frozen=True)
class Words:
    """A terminal made of blark's keyword terminals (``/\\bWORD\\b/i``, directly or through
    other terminals) as one regular expression of its words, in blark's order."""

    def apply(self, d: Definition, grammar: dict[str, Definition]) -> None:
        words = _words(d, grammar)
        d.choice = [Alternative([Item(f"/\\b({'|'.join(words)})\\b/i" if len(words) > 1 else f"/\\b{words[0]}\\b/i")])]


def _words(d: Definition, grammar: dict[str, Definition]) -> list[str]:
    out = []
    for a in d.choice:
        atom = a.items[0].atom if len(a.items) == 1 and not a.items[0].suffix else None
        word = re.fullmatch(r"/\\b(\w+)\\b/i", atom) if isinstance(atom, str) else None
        if word is not None:
            out.append(word.group(1))
        elif isinstance(atom, str) and atom in grammar:
            out += _words(grammar[atom], grammar)
        else:
            raise Underivable(f"{d.name} is not made of keywords")
    return out


@dataclass(frozen=True)
class Priority:
    """A priority given to the definition (ahead of the identifiers the words also are)."""
    value: int

    def apply(self, d: Definition, grammar: dict[str, Definition]) -> None:
        d.priority = f".{self.value}"


@dataclass(frozen=True)
class InlineFlags:
    """A regular expression's leading ``(?s)`` flags moved to its suffix (Python's ``re``
    refuses global flags once lark has put the expression in a group)."""

    def apply(self, d: Definition, grammar: dict[str, Definition]) -> None:
        items = [i for i in _items(d.choice) if isinstance(i.atom, str) and re.match(r"/\(\?[a-z]+\)", i.atom)]
        if not items:
            raise Underivable(f"{d.name} has no leading flags")
        for i in items:
            assert isinstance(i.atom, str)
            flags, rest = i.atom[3:].split(")", 1)
            body, suffix = rest.rsplit("/", 1)
            i.atom = f"/{body}/{suffix}{flags}"


Op = Union[Keep, Alternatives, Never, Semicolons, Drop, Rename, Required, Words, Priority, InlineFlags]


def derive_definitions(grammar: str, rules: dict[str, tuple[Op, ...]], own: tuple[str, ...] = ()) -> str | None:
    """The definitions ``rules`` names, derived from the lark ``grammar`` in its order, then the
    definitions ``own`` and the grammar's directives, one a line; ``None`` when a definition is
    missing or an operation does not apply."""
    found, directives = definitions(grammar)
    if set(rules) - set(found):
        return None
    out = []
    try:
        for name, d in found.items():
            if name in rules:
                for op in rules[name]:
                    op.apply(d, found)
                out.append(d.text())
    except Underivable:
        return None
    return "\n".join([*out, *own, *directives])
