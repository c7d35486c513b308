"""Writing IEC 61131-3 Structured Text: expressions, identifiers, declarations, the header.

One place for what every generated POU shares (the Grafcet program and the safety filter
block), so that the same Boolean expression always becomes the same ST text.

Example
-------
>>> from synth.logic.expr import And, Edge, Not, Or, Var
>>> st_expression(Or((And((Var("a"), Not(Var("b^-1")))), Edge(True, "c"))), st_past_name)
'a AND NOT b_1 OR c AND NOT c_1'
>>> st_identifier_problem("IN"), st_identifier_problem("a__b"), st_identifier_problem("V1")
('IN is a reserved word of IEC 61131-3', 'a__b has two underscores in a row', None)
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from enum import StrEnum
from fractions import Fraction
from typing import Callable, Iterable, Mapping, Sequence

from synth.errors import InputError, Location
from synth.grafcet.language import DURATION_RE
from synth.logic.expr import And, Const, Edge, Expr, Not, Or, Var
from synth.logic.past import pre_name, st_past_name

__all__ = [
    "st_expr",
    "declaration_lines",
    "st_expression",
    "st_identifier_problem",
    "name_problem",
    "NameProblem",
    "time_literal",
    "timer_literal",
    "Declaration",
    "PouKind",
    "SectionKind",
    "VarSection",
    "Pou",
    "located",
    "pou_lines",
    "header",
    "indent",
]


# IEC 61131-3 keywords, standard functions and standard function blocks a variable may not be
# named (case does not matter), and IN and PT, which the generated code passes to its timers
# (``_Tmr1(IN := X1, PT := T#2s)``). The one-letter formal parameters S, R and Q stay usable.
_RESERVED = frozenset("""
ABS ACOS ACTION ADD AND ANY ARRAY ASIN AT ATAN BOOL BY BYTE CASE CONCAT CONFIGURATION CONSTANT COS
CTD CTU CTUD DATE DATE_AND_TIME DELETE DINT DIV DO DT DWORD ELSE ELSIF EN END_ACTION END_CASE
END_CONFIGURATION END_FOR END_FUNCTION END_FUNCTION_BLOCK END_IF END_PROGRAM END_REPEAT
END_RESOURCE END_STEP END_STRUCT END_TRANSITION END_TYPE END_VAR END_WHILE ENO EQ EXIT EXP EXPT
FALSE FIND FOR FROM FUNCTION FUNCTION_BLOCK F_EDGE F_TRIG GE GT IF IN INITIAL_STEP INSERT INT
INTERVAL LE LEFT LEN LIMIT LINT LN LOG LREAL LT LWORD MAX MID MIN MOD MOVE MUL MUX NE NOT OF ON OR
PROGRAM PT READ_ONLY READ_WRITE REAL REPEAT REPLACE RESOURCE RETAIN RETURN RIGHT ROL ROR RS R_EDGE
R_TRIG SEL SHL SHR SIN SINT SQRT SR STEP STRING STRUCT SUB TAN TASK THEN TIME TIME_OF_DAY TO TOD
TOF TON TP TRANSITION TRUE TRUNC TYPE UDINT UINT ULINT UNTIL USINT VAR VAR_ACCESS VAR_CONFIG
VAR_EXTERNAL VAR_GLOBAL VAR_INPUT VAR_IN_OUT VAR_OUTPUT VAR_TEMP WHILE WITH WORD WSTRING XOR
""".split())
_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


class NameProblem(StrEnum):
    """Why a name cannot be an IEC 61131-3 variable: the one rule every generator applies
    (``synth st``, ``synth sfc``, ``synth filter st``), each saying it in its own sentence."""

    NOT_IDENTIFIER = "is not an IEC 61131-3 identifier (letters, digits and _ only)"
    RESERVED = "is a reserved word of IEC 61131-3"
    DOUBLE_UNDERSCORE = "has two underscores in a row"
    TRAILING_UNDERSCORE = "ends with an underscore"


def name_problem(name: str) -> NameProblem | None:
    """Why ``name`` cannot be an IEC 61131-3 variable (a keyword, a standard function or
    function block, a malformed identifier), or ``None`` when it can.

    >>> [str(name_problem(n)) for n in ("ON", "left", "TON", "a__b")]
    ['is a reserved word of IEC 61131-3', 'is a reserved word of IEC 61131-3', 'is a reserved word of IEC 61131-3', 'has two underscores in a row']
    >>> name_problem("S"), name_problem("V1")
    (None, None)
    """
    if not _IDENTIFIER.match(name):
        return NameProblem.NOT_IDENTIFIER
    if name.upper() in _RESERVED:
        return NameProblem.RESERVED
    if "__" in name:
        return NameProblem.DOUBLE_UNDERSCORE
    if name.endswith("_"):
        return NameProblem.TRAILING_UNDERSCORE
    return None


def st_identifier_problem(name: str) -> str | None:
    """Why ``name`` cannot be an IEC 61131-3 identifier, as a sentence, or ``None`` when it can."""
    problem = name_problem(name)
    return None if problem is None else f"{name} {problem}"


def time_literal(seconds: Fraction, loc: Location | None = None, written: str | None = None) -> str:
    """The one IEC ``TIME`` literal of a timer duration, for every generated file (ST program,
    SFC, PLCopen XML): as the Grafcet writes it when ``written`` (``2min`` is ``T#2m``, ``2000ms``
    ``T#2000ms``, so an SFC imported back keeps its timers), else in whole seconds or
    milliseconds. A duration that is not a whole number of milliseconds is refused.

    >>> time_literal(Fraction(120), written="2min"), time_literal(Fraction(2), written="2000ms")
    ('T#2m', 'T#2000ms')
    >>> time_literal(Fraction(2)), time_literal(Fraction(3, 2)), time_literal(Fraction(120))
    ('T#2s', 'T#1500ms', 'T#120s')
    """
    ms = seconds * 1000
    if ms.denominator != 1 or ms <= 0:
        raise InputError(f"a timer of {float(seconds)} s cannot be written in whole milliseconds", loc)
    found = DURATION_RE.fullmatch(written) if written else None
    if found:
        return f"T#{found[1]}{'m' if found[2] == 'min' else found[2]}"
    n = int(ms)
    return f"T#{n // 1000}s" if n % 1000 == 0 else f"T#{n}ms"


def timer_literal(timer_id: str, seconds: Fraction, loc: Location | None = None) -> str:
    """:func:`time_literal` of a timer ``2s/X1`` as the Grafcet writes it."""
    return time_literal(seconds, loc, timer_id.split("/", 1)[0])


def _edge_default(e: Edge, name: Callable[[str], str]) -> str:
    now, before = name(e.name), name(pre_name(e.name))
    return f"{now} AND NOT {before}" if e.rising else f"NOT {now} AND {before}"


_PREC = {Or: 1, And: 2, Not: 3}


def st_expr(e: Expr, ref: Callable[[Expr], str], parent: int = 0) -> str:
    """``e`` in ST: ``!`` → ``NOT``, ``&`` → ``AND``, ``|`` → ``OR``, parentheses only where needed;
    ``ref`` names a variable, timer or edge.

    >>> from synth.logic.expr import Var, Not, And, Or
    >>> st_expr(And((Or((Var("a"), Var("b"))), Not(Var("c")))), lambda v: v.name)
    '(a OR b) AND NOT c'
    """
    if isinstance(e, Const):
        return "TRUE" if e.value else "FALSE"
    if isinstance(e, (Var, Edge)):
        text = ref(e)  # an edge may be written as a conjunction: parenthesised under NOT
        return f"({text})" if parent > _PREC[And] and " " in text else text
    if isinstance(e, Not):
        text = "NOT " + st_expr(e.arg, ref, 4)
    else:
        op = " AND " if isinstance(e, And) else " OR "
        text = op.join(st_expr(a, ref, _PREC[type(e)]) for a in e.args)
    return f"({text})" if _PREC[type(e)] < parent else text



def st_expression(
    e: Expr,
    name: Callable[[str], str] = st_past_name,
    edge: Callable[[Edge], str] | None = None,
) -> str:
    """``e`` in ST (:func:`st_expr`) with ``name`` mapping synth names to ST variables; an
    edge is ``x AND NOT x_1`` (``↑x``) unless ``edge`` says otherwise."""

    def ref(x: Expr) -> str:
        if isinstance(x, Var):
            return name(x.name)
        assert isinstance(x, Edge)  # st_expr asks ref for variables and edges only
        return edge(x) if edge is not None else _edge_default(x, name)

    return st_expr(e, ref)


@dataclass(frozen=True)
class Declaration:
    """One variable line: ``name [AT %IX0.0] : TYPE [:= init]; (* comment *)``; ``location``
    makes it a located variable (``synth st --io``)."""

    name: str
    type: str = "BOOL"
    init: str | None = None
    comment: str = ""
    location: str | None = None

    def text(self) -> str:
        init = f" := {self.init}" if self.init is not None else ""
        comment = f" (* {self.comment} *)" if self.comment else ""
        at = f" AT {self.location}" if self.location else ""
        return f"{self.name}{at} : {self.type}{init};{comment}"


class PouKind(StrEnum):
    """The kinds of program organisation unit synth writes."""

    PROGRAM = "PROGRAM"
    FUNCTION_BLOCK = "FUNCTION_BLOCK"


class SectionKind(StrEnum):
    """A variable section, as its keyword reads."""

    INPUT = "VAR_INPUT"
    OUTPUT = "VAR_OUTPUT"
    IN_OUT = "VAR_IN_OUT"
    LOCAL = "VAR"
    CONSTANT = "VAR CONSTANT"
    TEMP = "VAR_TEMP"


@dataclass(frozen=True)
class VarSection:
    """``VAR_INPUT … END_VAR``: a section's kind and its declarations."""

    kind: SectionKind
    declarations: tuple[Declaration, ...]


@dataclass(frozen=True)
class Pou:
    """A generated ``PROGRAM`` or ``FUNCTION_BLOCK`` as data: what every writer renders
    (the ST text, the PLCopen XML project), so no writer reads another's text.

    >>> pou = Pou(PouKind.PROGRAM, "P", (VarSection(SectionKind.INPUT, (Declaration("a"),)),), ("y := a;",))
    >>> print("\\n".join(pou_lines(pou)))
    PROGRAM P
    VAR_INPUT
        a : BOOL;
    END_VAR
    y := a;
    END_PROGRAM
    """

    kind: PouKind
    name: str
    sections: tuple[VarSection, ...]
    body: tuple[str, ...]


def located(pou: Pou, where: Mapping[str, str]) -> Pou:
    """``pou`` with the variables ``where`` names located (``name → %IX0.0``): each leaves its
    ``VAR_INPUT``/``VAR_OUTPUT`` for one ``VAR`` section of located variables, in their order,
    since IEC 61131-3 places a directly represented variable in ``VAR``, never in a POU's interface.

    >>> pou = Pou(PouKind.PROGRAM, "P", (VarSection(SectionKind.INPUT, (Declaration("a"), Declaration("b"))),), ("",))
    >>> print("\\n".join(declaration_lines(located(pou, {"a": "%IX0.0"}))))
    PROGRAM P
    VAR_INPUT
        b : BOOL;
    END_VAR
    VAR
        a AT %IX0.0 : BOOL;
    END_VAR
    """
    upper = {k.upper(): v for k, v in where.items()}
    kept: list[VarSection] = []
    moved: list[Declaration] = []
    for section in pou.sections:
        mine = [d for d in section.declarations if d.name.upper() in upper
                and section.kind in (SectionKind.INPUT, SectionKind.OUTPUT)]
        moved += [replace(d, location=upper[d.name.upper()]) for d in mine]
        rest = tuple(d for d in section.declarations if d not in mine)
        if rest:
            kept.append(VarSection(section.kind, rest))
    at = next((i for i, s in enumerate(kept) if s.kind not in (SectionKind.INPUT, SectionKind.OUTPUT)), len(kept))
    sections = [*kept[:at], VarSection(SectionKind.LOCAL, tuple(moved)), *kept[at:]] if moved else kept
    return replace(pou, sections=tuple(sections))


def declaration_lines(pou: Pou, pad: str = "    ") -> list[str]:
    """The head of ``pou``: its kind and name, then every variable section (indented by ``pad``)."""
    lines = [f"{pou.kind} {pou.name}"]
    for section in pou.sections:
        lines += [str(section.kind), *(pad + d.text() for d in section.declarations), "END_VAR"]
    return lines


def pou_lines(pou: Pou, pad: str = "    ") -> list[str]:
    """The ST lines of ``pou``, its declarations indented by ``pad`` (every section given is written)."""
    return [*declaration_lines(pou, pad), *pou.body, f"END_{pou.kind}"]


def indent(lines: Iterable[str], level: int = 1) -> list[str]:
    """Lines indented by four spaces per level (empty lines stay empty)."""
    pad = "    " * level
    return [pad + line if line else line for line in lines]


def header(what: str, files: Sequence[str], details: Sequence[str] = (), *, version: str | None = None) -> list[str]:
    """The comment that opens every generated file: which synth made it from which files,
    with their SHA-256 (:mod:`synth.codegen.provenance`), then ``details``."""
    from synth.codegen.provenance import provenance_lines

    first, *rest = provenance_lines(what, files, version=version)
    lines = [f"(* {first}"] + [f"   {d}" for d in (*rest, *details)]
    lines[-1] += " *)"
    return lines
