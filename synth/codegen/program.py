"""A generated program as data, and its names: the filter block a program calls, the
result of ``synth st`` (text, POUs, renamings), the ``PROGRAM``'s default name, the one
name check of the generated variables (ST program and SFC alike), where a name is first
used in a Grafcet, and the compact form of the text (for blark's Earley parser).

Example
-------
>>> program_name("grafcets/tri.g7"), program_name("x/2-axes.g7")
('tri', 'G_2_axes')
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable, Mapping

from synth.codegen.st import NameProblem, Pou, name_problem
from synth.errors import InputError, Location
from synth.grafcet.language import Grafcet
from synth.logic.expr import names

__all__ = ["FilterCall", "StProgram", "program_name", "filter_call", "check_variable_name", "first_location",
           "compact", "Configuration", "configuration", "case_aliases", "renamed_note", "with_locations"]


@dataclass(frozen=True)
class FilterCall:
    """A safety filter run after the Grafcet: the text of its function block, its type and
    instance names, and which of its inputs are requests (``R_<order>``).

    The program passes the Grafcet's order ``o`` as ``R_o`` (``FALSE`` for an output the Grafcet
    never orders) and every other name as the program's input of that name (declared when the
    Grafcet does not read it), then copies the block's outputs to its own ``VAR_OUTPUT``.
    """

    fb_text: str
    fb_type: str
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    fb_pou: Pou
    instance: str = "_Filter"


@dataclass(frozen=True)
class StProgram:
    """Generated Structured Text: the whole file, the ``PROGRAM``'s name, and the ST name of
    every plant input/output and step variable that had to be renamed (case clashes)."""

    text: str
    program: str
    renamed: tuple[tuple[str, str], ...] = field(default=())
    pous: tuple[Pou, ...] = ()  # the filter's block (when called) and the program, as data

    def st_name(self, name: str) -> str:
        """The ST variable of a plant input/output or step variable ``X<step>``."""
        return dict(self.renamed).get(name, name)


def with_locations(program: StProgram, where: Mapping[str, str], note: str = "") -> StProgram:
    """``program`` with its plant inputs and outputs located (``name → %IX0.0``, plant names):
    the ``PROGRAM``'s data re-rendered by :func:`~synth.codegen.st.located`, its text rewritten
    from the ``PROGRAM`` line on, ``note`` (a comment) just above it."""
    from synth.codegen.st import located, pou_lines

    *others, pou = program.pous
    new = located(pou, {program.st_name(n): a for n, a in where.items()})
    lines = program.text.rstrip("\n").split("\n")
    start = max(k for k, line in enumerate(lines) if line.startswith(f"PROGRAM {pou.name}"))
    head = [*lines[:start], *([f"(* {note} *)"] if note else [])]
    return StProgram("\n".join([*head, *pou_lines(new, "  ")]) + "\n", program.program, program.renamed, (*others, new))


def program_name(path: str) -> str:
    """The default ``PROGRAM`` name for a ``.g7`` file: its stem as an IEC identifier.

    """
    stem = re.sub(r"[^A-Za-z0-9]+", "_", Path(path).stem).strip("_") or "Grafcet"
    if not stem[0].isalpha():
        stem = "G_" + stem
    return stem


def filter_call(block: object) -> FilterCall:
    """The :class:`FilterCall` of a :class:`synth.codegen.filter_st.FilterBlock`."""
    return FilterCall(block.text, block.name, tuple(block.inputs), tuple(block.outputs), block.pou)  # type: ignore[attr-defined]


def check_variable_name(n: str, loc: Location | None) -> None:
    """A plant or step name the generated program (ST or SFC) declares: the one rule of
    :func:`~synth.codegen.st.name_problem`, the same located error from ``synth st`` and ``synth sfc``."""
    problem = name_problem(n)
    if problem is NameProblem.RESERVED:
        why = "is an IEC 61131-3 keyword or standard name"
    elif problem is not None:
        why = "is not an IEC 61131-3 identifier (letters, digits, single underscores)"
    else:
        return
    raise InputError(f"'{n}' {why}: Structured Text cannot use it as a variable", loc,
                     notes=("rename it in the Grafcet (and the plant)",))


def case_aliases(names: Iterable[str], taken: Iterable[str] = ()) -> dict[str, str]:
    """IEC 61131-3 ignores case: of user names differing in case only (or from a name in
    ``taken``, the generated code's own), the later one is renamed ``<name>_<k>``. The one
    rule of ``synth st`` and ``synth sfc``; the result maps each renamed name to its new name.

    >>> case_aliases(["a", "A", "x"], taken=["X"])
    {'A': 'A_1', 'x': 'x_1'}
    """
    used = {n.upper() for n in taken}
    out: dict[str, str] = {}
    for n in names:
        alias, k = n, 1
        while alias.upper() in used:
            alias, k = f"{n}_{k}", k + 1
        used.add(alias.upper())
        if alias != n:
            out[n] = alias
    return out


def renamed_note(aliases: Mapping[str, str]) -> str:
    """The header line that lists :func:`case_aliases`' renames."""
    return "renamed (Structured Text ignores case): " + ", ".join(f"{a} -> {b}" for a, b in aliases.items())


def first_location(g: Grafcet, name: str) -> Location | None:
    """Where ``name`` first appears in the Grafcet (a receptivity, condition or action), if anywhere."""
    for t in g.transitions:
        for n in names(t.receptivity):
            if n.name == name:
                return n.loc or t.loc
    for s in g.steps:
        for a in s.actions:
            if a.order == name:
                return a.loc
            if a.condition is not None:
                for n in names(a.condition):
                    if n.name == name:
                        return n.loc or a.loc
    return None


_COMMENT = re.compile(r"\s*\(\*.*?\*\)")
_SHORT = {"Fired": "Fd", "Fire": "F", "Leave": "L", "Enter": "E", "Rounds": "N", "FirstCycle": "I",
          "InputEvent": "V", "MAX_ROUNDS": "M", "Prev_": "P_", "RE_": "R_", "FE_": "D_", "Mem_": "S_",
          "Order_": "O_", "Tmr": "T", "TE": "Q", "Filter": "Fl"}
_INTERNAL = re.compile(r"(?<![A-Za-z0-9_])_(" + "|".join(_SHORT) + ")")
_BOOL_DECL = re.compile(r"^(\w+) : BOOL;$")
_BOOL_LIST = re.compile(r"^\w+(, \w+)* : BOOL;$")


def compact(lines: list[str]) -> list[str]:
    """No comments, no indentation, shorter internal names (they all start with ``_``, plant
    names never do) and one declaration line per run of plain ``BOOL`` variables: the same
    program in fewer characters."""
    bare = [c for c in (_COMMENT.sub("", line).strip() for line in lines) if c]
    out: list[str] = []
    for line in (_INTERNAL.sub(lambda m: "_" + _SHORT[m[1]], x) for x in bare):
        m = _BOOL_DECL.match(line)
        if m and out and _BOOL_LIST.match(out[-1]):
            out[-1] = out[-1][: -len(" : BOOL;")] + ", " + m[1] + " : BOOL;"
        else:
            out.append(line)
    return out


@dataclass(frozen=True)
class Configuration:
    """``--task 10ms``: one resource, one periodic task, one instance of the program, so the
    file builds as it is in Beremiz and OpenPLC. Written as ST (:meth:`lines`) or as TC6 XML
    (:func:`synth.codegen.plcopen.export.st_project_xml`)."""

    program: str
    interval: str  # the TIME literal, T#10ms
    name: str = "Config0"
    resource: str = "Res0"
    task: str = "MainTask"
    instance: str = "Inst0"
    priority: int = 0

    def lines(self) -> list[str]:
        return [f"CONFIGURATION {self.name}", f"  RESOURCE {self.resource} ON PLC",
                f"    TASK {self.task}(INTERVAL := {self.interval}, PRIORITY := {self.priority});",
                f"    PROGRAM {self.instance} WITH {self.task} : {self.program};", "  END_RESOURCE",
                "END_CONFIGURATION"]


def configuration(program: str, task: str) -> Configuration:
    """The :class:`Configuration` of ``--task PERIOD`` (a located error for a bad period).

    >>> print("\\n".join(configuration("tri", "10ms").lines()))
    CONFIGURATION Config0
      RESOURCE Res0 ON PLC
        TASK MainTask(INTERVAL := T#10ms, PRIORITY := 0);
        PROGRAM Inst0 WITH MainTask : tri;
      END_RESOURCE
    END_CONFIGURATION
    """
    from synth.codegen.st import time_literal
    from synth.grafcet.language import DURATION_RE, duration_seconds

    where = Location("--task", 1, 1, task, max(1, len(task)))
    found = DURATION_RE.fullmatch(task.strip())
    if found is None:
        raise InputError("not a period", where, expected=("a period such as 10ms, 0.5s or 1min",))
    return Configuration(program, time_literal(duration_seconds(found[1], found[2]), where, found[0]))
