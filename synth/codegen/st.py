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
from dataclasses import dataclass
from typing import Callable, Iterable, Sequence

from synth.logic.expr import And, Const, Edge, Expr, Not, Or, Var
from synth.logic.past import pre_name, st_past_name

__all__ = [
    "st_expr",
    "st_expression",
    "st_identifier_problem",
    "Declaration",
    "var_block",
    "header",
    "indent",
]


# IEC 61131-3 keywords and the standard function blocks/functions a variable may not shadow.
_RESERVED = frozenset("""
ABS ACOS ACTION ADD AND ANY ARRAY ASIN AT ATAN BOOL BY BYTE CASE CONCAT CONFIGURATION CONSTANT
COS CTD CTU CTUD DATE DATE_AND_TIME DELETE DINT DIV DO DT DWORD ELSE ELSIF EN ENO END_ACTION
END_CASE END_CONFIGURATION END_FOR END_FUNCTION END_FUNCTION_BLOCK END_IF END_PROGRAM END_REPEAT
END_RESOURCE END_STEP END_STRUCT END_TRANSITION END_TYPE END_VAR END_WHILE EQ EXIT EXP EXPT
F_EDGE F_TRIG FALSE FIND FOR FROM FUNCTION FUNCTION_BLOCK GE GT IF IN INITIAL_STEP INSERT INT
INTERVAL LD LE LEFT LEN LIMIT LINT LN LOG LREAL LT LWORD MAX MID MIN MOD MOVE MUL MUX NE NOT OF
ON OR PROGRAM PT Q R R_EDGE R_TRIG READ_ONLY READ_WRITE REAL REPEAT REPLACE RESOURCE RETAIN RETURN
RIGHT ROL ROR RS S SEL SHL SHR SIN SINT SQRT SR STEP STRING STRUCT SUB TAN TASK THEN TIME
TIME_OF_DAY TO TOD TOF TON TP TRANSITION TRUE TRUNC TYPE UDINT UINT ULINT UNTIL USINT VAR
VAR_ACCESS VAR_CONFIG VAR_EXTERNAL VAR_GLOBAL VAR_IN_OUT VAR_INPUT VAR_OUTPUT VAR_TEMP WHILE WITH
WORD WSTRING XOR
""".split())
_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


def st_identifier_problem(name: str) -> str | None:
    """Why ``name`` cannot be an IEC 61131-3 identifier, or ``None`` when it can."""
    if not _IDENTIFIER.match(name):
        return f"{name} is not an IEC 61131-3 identifier (letters, digits and _ only)"
    if name.upper() in _RESERVED:
        return f"{name} is a reserved word of IEC 61131-3"
    if "__" in name:
        return f"{name} has two underscores in a row"
    if name.endswith("_"):
        return f"{name} ends with an underscore"
    return None


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
        return edge(x) if edge is not None else _edge_default(x, name)

    return st_expr(e, ref)


@dataclass(frozen=True)
class Declaration:
    """One variable line: ``name : TYPE [:= init]; (* comment *)``."""

    name: str
    type: str = "BOOL"
    init: str | None = None
    comment: str = ""

    def text(self) -> str:
        init = f" := {self.init}" if self.init is not None else ""
        comment = f" (* {self.comment} *)" if self.comment else ""
        return f"{self.name} : {self.type}{init};{comment}"


def var_block(keyword: str, declarations: Sequence[Declaration]) -> list[str]:
    """``VAR_INPUT … END_VAR`` (empty list when there is nothing to declare)."""
    if not declarations:
        return []
    return [keyword, *indent([d.text() for d in declarations]), "END_VAR"]


def indent(lines: Iterable[str], level: int = 1) -> list[str]:
    """Lines indented by four spaces per level (empty lines stay empty)."""
    pad = "    " * level
    return [pad + line if line else line for line in lines]


def header(what: str, files: Sequence[str], details: Sequence[str] = ()) -> list[str]:
    """The comment that opens every generated file: which synth and which files made it.
    Nothing in it depends on the time of day, so the same input gives the same bytes."""
    from synth.version import version

    lines = [f"(* {what}, generated by synth {version()} from {', '.join(files)}."]
    lines += [f"   {d}" for d in details]
    lines[-1] += " *)"
    return lines
