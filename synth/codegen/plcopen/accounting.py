"""The accounting of an import: every meaning-carrying item of the imported SFC POUs
(:mod:`synth.codegen.plcopen.meaning`) is either in the ``.g7`` with the meaning it has on the
PLC, or named by a located warning of the import. An item matched by neither is a
:class:`SilentChange`: the verdict on the ``.g7`` would be about another program.

What "in the ``.g7``" means, per item:

* a qualifier on a variable X of step S: ``N`` a continuous or conditional action on X in S;
  ``S``/``R`` a stored set/reset of X in S; ``D``/``L`` a conditional action on X in S
  reading S's timer of that duration;
* an assignment ``X := v`` of step S: ``TRUE``/``FALSE`` a stored set/reset of X in S on
  activation (``N``, ``P1``, ``S``), deactivation (``P0``) or an event (under ``IF``); an
  expression: an assignment of X in S, or, under ``N``, a conditional action on X when the
  step also resets X on deactivation (what the PLC does then);
* a selection divergence: its branches' receptivities in the ``.g7`` pairwise exclusive (the
  order no longer matters);
* a stateless block: the variables wired into it read by the ``.g7``; ``R_TRIG``/``F_TRIG`` an
  edge of the variable it watches; a timer: a ``.g7`` timer of its duration; any other block
  (a latch, a counter): a warning only.

A warning accounts for an item when it points at one of the item's lines, or names the
item's block instance.

Example
-------
>>> from synth.codegen.plcopen.meaning import meaning_items
>>> xml = ('<project xmlns="http://www.plcopen.org/xml/tc6_0201"><types><pous>'
...        '<pou name="P" pouType="program"><interface><outputVars><variable name="pump"><type><BOOL/></type>'
...        '</variable></outputVars></interface><body><SFC>'
...        '<step localId="1" name="S0" initialStep="true"/>'
...        '<actionBlock localId="2"><connectionPointIn><connection refLocalId="1"/></connectionPointIn>'
...        '<action qualifier="S"><reference name="pump"/></action></actionBlock>'
...        '</SFC></body></pou></pous></types></project>')
>>> from synth.grafcet.language_check import parse_grafcet
>>> g = parse_grafcet("outputs pump\\ngrafcet G { initial step 0: pump }", "p.g7")
>>> [c.text() for c in silent_changes(meaning_items(xml, "p.xml"), g, [])]
['p.xml:1: S action on pump (step S0): not in the .g7 as a stored set of pump, and no warning names it']
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass
from fractions import Fraction
from typing import Callable

from synth.codegen.plcopen.data import FLAG_PREFIX, duration
from synth.codegen.plcopen.mirrors import MIRROR_PREFIX
from synth.codegen.plcopen.shared import shared_assignment
from synth.codegen.plcopen.meaning import STATELESS, ItemKind, MeaningItem
from synth.errors import InputError
from synth.grafcet.language import ASSIGN, CONDITIONAL, CONTINUOUS, ON_ACTIVATION, ON_DEACTIVATION, ON_EVENT, STORED, TIMER_RE, \
    Action, Grafcet, Step, Transition, duration_seconds
from synth.logic.expr import Compare, Edge, Expr, evaluate, names

__all__ = ["SilentChange", "silent_changes", "Accounting", "account_import", "MAX_ATOMS"]

MAX_ATOMS = 12
"""The most atoms two receptivities may read for their exclusivity to be decided by
enumeration; above, the divergence counts as not shown exclusive."""


@dataclass(frozen=True)
class SilentChange:
    """An item of the XML neither in the ``.g7`` nor named by a warning, and what was looked for."""

    item: MeaningItem
    expected: str

    def text(self) -> str:
        where = f"{self.item.location.file}:{self.item.location.line}"
        step = f" (step {self.item.step})" if self.item.step and self.item.kind != ItemKind.PRIORITY else ""
        return f"{where}: {self.item.what}{step}: not in the .g7 as {self.expected}, and no warning names it"


def _same(g7: str, xml: str) -> bool:
    """Whether the ``.g7`` name ``g7`` stands for the XML variable ``xml`` (ST ignores case; a
    dotted global is flattened; several POUs prefix their own variables; a step's flag of a
    shared order, ``_N_RUN_S1``, is the order ``RUN``)."""
    a, b = g7.upper(), xml.upper().replace(".", "_")
    flag = b.startswith(FLAG_PREFIX) and b[len(FLAG_PREFIX):].startswith(a + "_")
    return a == b or a.endswith("_" + b) or flag


def _shared(item: MeaningItem, g: Grafcet, several: bool) -> str | None:
    """``RUN := _N_RUN_S1 OR _N_RUN_S2`` (what ``synth sfc`` writes for an order several steps
    emit): what is missing for each flag's step to emit the order in the ``.g7``, or None."""
    found = shared_assignment(f"{item.names[0]} := {item.value}")
    assert found is not None
    order, flags = found
    names = [f[len(FLAG_PREFIX) + len(order) + 1:] for f in flags]
    silent = [n for n in names if not any(a.kind in (CONTINUOUS, CONDITIONAL)
                                          for a in _actions(_step(g, item.pou, n, several), order))]
    return f"the order {order} emitted by step {', '.join(silent)}" if silent else None


def _step(g: Grafcet, pou: str, name: str, several: bool) -> Step | None:
    """The ``.g7`` step of the XML step ``name`` of POU ``pou`` (``S12`` is ``12``; with
    ``several`` POUs imported, the names are prefixed by the POU's)."""
    plain = [name, name[1:]] if re.fullmatch(r"S\d+", name) else [name]
    wanted = {f"{pou}_{n}" for n in plain} if several else set(plain)
    return next((s for s in g.steps if s.name in wanted), None)


def _actions(step: Step | None, name: str) -> list[Action]:
    return [a for a in step.actions if _same(a.order, name)] if step is not None else []


def _seconds(literal: str) -> Fraction | None:
    """The duration of a TIME literal (``T#2s``), None when it is not one."""
    m = re.fullmatch(r"([0-9.]+)(ms|s|min|h)", duration(literal) or "")
    return duration_seconds(m[1], m[2]) if m else None


def _timers(g: Grafcet, literal: str) -> bool:
    """Whether the ``.g7`` reads a timer of the TIME ``literal``'s duration."""
    seconds = _seconds(literal)
    return seconds is not None and any(t.seconds == seconds for t in g.timers)


def _timed(action: Action, literal: str, step: Step) -> bool:
    """Whether ``action``'s condition reads the timer of ``literal`` on ``step`` (``2s/X1``)."""
    seconds = _seconds(literal)
    for n in names(action.condition) if action.condition is not None else ():
        m = TIMER_RE.match(n.name)
        if m and m[3] == step.name and duration_seconds(m[1], m[2]) == seconds:
            return True
    return False


def _qualifier(item: MeaningItem, g: Grafcet, step: Step | None) -> str | None:
    """What is missing for a qualifier item, or None."""
    name, q = item.names[0], item.qualifier
    if q == "N" and name.upper() == f"{MIRROR_PREFIX}{item.step}".upper():
        return None  # the step's own mirror (synth sfc): its flag, which every .g7 step has
    acts = _actions(step, name)
    if q == "N" and not any(a.kind in (CONTINUOUS, CONDITIONAL) for a in acts):
        return f"a continuous action on {name}"
    if q in ("S", "R") and not any(a.kind == STORED and a.value == (q == "S") for a in acts):
        return f"a stored {'set' if q == 'S' else 'reset'} of {name}"
    if q in ("D", "L") and not any(a.kind == CONDITIONAL and step is not None and _timed(a, item.duration, step)
                                   for a in acts):
        return f"{name} under the timer of {item.duration} on its step"
    if q not in ("N", "S", "R", "D", "L"):
        return f"a {q} action on {name}"
    return None


_TRUE, _FALSE = {"TRUE", "1"}, {"FALSE", "0"}


def _assignment(item: MeaningItem, items: list[MeaningItem], g: Grafcet, step: Step | None) -> str | None:
    """What is missing for an assignment item, or None."""
    name, value, q = item.names[0], item.value.upper(), item.qualifier
    acts = _actions(step, name)
    constant = value in _TRUE | _FALSE
    when = ON_EVENT if item.conditional else ON_DEACTIVATION if q == "P0" else ON_ACTIVATION
    if constant:
        wanted = value in _TRUE
        stored = [a for a in acts if a.kind == STORED and a.value == wanted and a.when == when]
        assigned = [a for a in acts if a.kind == ASSIGN and a.when == when]
        ends = q == "P0" and not wanted and any(a.kind in (CONTINUOUS, CONDITIONAL) for a in acts)
        if stored or assigned or ends:
            return None
        verb = "set" if wanted else "reset"
        return f"a stored {verb} of {name} on {when}"
    if any(a.kind == ASSIGN for a in acts):
        return None
    reset = any(i.kind == ItemKind.ASSIGNMENT and i.step == item.step and i.qualifier == "P0" and _same(i.names[0], name)
                and i.value.upper() in _FALSE for i in items)
    if q == "N" and reset and any(a.kind in (CONTINUOUS, CONDITIONAL) for a in acts):
        return None
    return f"an assignment of {name} kept once the step is left"


def _exclusive(a: Expr, b: Expr) -> bool | None:
    """Whether ``a & b`` never holds: Boolean variables and edges free, each integer variable
    compared (``Cnt >= 3``) taken around every constant it is compared with; None when there are
    more than :data:`MAX_ATOMS` Boolean atoms or ``2 ** MAX_ATOMS`` cases in all."""
    atoms = list(dict.fromkeys(n for e in (a, b) for n in names(e)))
    compares = [n for n in atoms if isinstance(n, Compare)]
    flags = list(dict.fromkeys(n.text() if isinstance(n, Edge) else n.name for n in atoms if not isinstance(n, Compare)))
    around: dict[str, set[int]] = {}
    for c in compares:
        for x in c.operands():
            around.setdefault(x, {0})
        if isinstance(c.right, int):
            around[c.left] |= {c.right - 1, c.right, c.right + 1}
    numbers = sorted(around)
    cases = 2 ** len(flags)
    for x in numbers:
        cases *= len(around[x])
    if len(flags) > MAX_ATOMS or cases > 2 ** MAX_ATOMS:
        return None
    by_name = {c.name: c for c in compares}
    for bits in itertools.product((False, True), repeat=len(flags)):
        for ints in itertools.product(*(sorted(around[x]) for x in numbers)):
            v, counts = dict(zip(flags, bits)), dict(zip(numbers, ints))

            def value(n: str, v: dict[str, bool] = v, counts: dict[str, int] = counts) -> bool:
                return by_name[n].holds(counts) if n in by_name else v.get(n, False)

            def edge(e: Edge, v: dict[str, bool] = v) -> bool:
                return v[e.text()]

            if evaluate(a, value, edge) and evaluate(b, value, edge):
                return False
    return True


def _divergence(item: MeaningItem, g: Grafcet, several: bool) -> str | None:
    steps = [s for n in item.names if (s := _step(g, item.pou, n, several)) is not None]
    leaving: list[Transition] = [t for t in g.transitions if any(s.name in t.sources for s in steps)]
    for t, u in itertools.combinations(leaving, 2):
        if _exclusive(t.receptivity, u.receptivity) is not True:
            return f"exclusive branches ({t.receptivity.text()} and {u.receptivity.text()} may hold together)"
    return None if len(leaving) > 1 else "two branches or more"


def _g7_reads(g: Grafcet) -> set[str]:
    """Every name the ``.g7`` reads or writes, upper case, with its edges as ``↑X``/``↓X``."""
    exprs = [t.receptivity for t in g.transitions] + [a.condition for s in g.steps for a in s.actions if a.condition]
    out = {n.text().upper() for e in exprs for n in names(e)}
    out |= {n.name.upper() for e in exprs for n in names(e)}
    return out | {a.order.upper() for s in g.steps for a in s.actions}


def _named(name: str, warnings: list[InputError]) -> bool:
    """Whether a warning names ``name`` (as a whole word)."""
    return any(re.search(rf"(?<![\w.]){re.escape(name)}(?!\w)", w.message) for w in warnings)


def _block(item: MeaningItem, g: Grafcet, warnings: list[InputError]) -> str | None:
    kind, fed = item.qualifier, item.names[1:]
    variables = [re.sub(r"^NOT\s+", "", f, flags=re.I) for f in fed if re.fullmatch(r"(NOT\s+)?[A-Za-z_][\w.]*", f, re.I)]
    read = _g7_reads(g)

    def seen(n: str, edge: str = "") -> bool:
        return any(_same(r[len(edge):], n) for r in read if r.startswith(edge)) or \
            any(r.startswith(edge + n.upper().replace(".", "_") + "_") for r in read)  # a declared predicate

    if kind in STATELESS:
        missing = [v for v in variables if not seen(v) and not _named(v, warnings)]  # a warning says what it became
        return f"reads of {', '.join(missing)}" if missing else None
    if kind in ("R_TRIG", "F_TRIG"):
        edge = "↑" if kind == "R_TRIG" else "↓"
        return None if variables and all(seen(v, edge) for v in variables) else f"an edge {edge} of its input"
    return "an equivalent .g7 construct (none exists)"


def _warned(item: MeaningItem, warnings: list[InputError]) -> bool:
    """Whether a warning points at one of the item's lines, names its block instance, or names
    what it assigns from a line between its enclosing element and itself (a body's warning)."""
    first = min(item.lines)
    for w in warnings:
        loc = w.location
        named = bool(item.names and item.names[0]) and _named(item.names[0], [w])
        if loc is not None and loc.file == item.location.file and \
                (loc.line in item.lines or named and first <= loc.line <= item.location.line):
            return True
        if named and item.kind in (ItemKind.BLOCK, ItemKind.TIMER):
            return True
    return False


def silent_changes(items: list[MeaningItem], g: Grafcet, warnings: list[InputError]) -> list[SilentChange]:
    """The items of ``items`` (of the POUs imported into ``g``) that are neither in ``g`` with
    their PLC meaning nor named by one of ``warnings``."""
    several = len({i.pou for i in items}) > 1
    checks: dict[ItemKind, Callable[[MeaningItem], str | None]] = {
        ItemKind.QUALIFIER: lambda i: _qualifier(i, g, _step(g, i.pou, i.step, several)),
        ItemKind.ASSIGNMENT: lambda i: _shared(i, g, several) if shared_assignment(f"{i.names[0]} := {i.value}")
        else _assignment(i, items, g, _step(g, i.pou, i.step, several)),
        ItemKind.PRIORITY: lambda i: _divergence(i, g, several),
        ItemKind.BLOCK: lambda i: _block(i, g, warnings),
        ItemKind.TIMER: lambda i: None if _timers(g, i.duration) else f"a timer of {i.duration or 'its preset'}",
    }
    out = []
    for item in items:
        missing = checks[item.kind](item)
        if missing is not None and not _warned(item, warnings):
            out.append(SilentChange(item, missing))
    return out



@dataclass(frozen=True)
class Accounting:
    """An import and its accounting: the ``.g7`` text, the import's warnings, the items of the
    imported POUs and the silent changes among them."""

    text: str
    warnings: tuple[InputError, ...]
    items: tuple[MeaningItem, ...]
    silent: tuple[SilentChange, ...]


def account_import(data: bytes | str, file: str = "<xml>", pou: str | None = None) -> Accounting:
    """Import the SFC POUs of ``data`` (``pou``: that one) and account for every item; a refused
    import raises its :class:`~synth.errors.InputError`."""
    from synth.codegen.plcopen.importer import import_sfc
    from synth.codegen.plcopen.meaning import meaning_items
    from synth.grafcet.language_check import parse_grafcet

    warnings: list[InputError] = []
    text = import_sfc(data, file, pou=pou, warnings=warnings)
    g = parse_grafcet(text, file + ".g7")
    items = meaning_items(data, file, pou)
    return Accounting(text, tuple(warnings), tuple(items), tuple(silent_changes(items, g, warnings)))
