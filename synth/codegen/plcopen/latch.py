"""An ``SR``/``RS`` bistable wired in an FBD transition condition (``synth import``), as the
Beremiz traffic-light example draws it: ``SR0(S1:=PEDESTRIAN_BUTTON, R:=TON3.Q)`` with
``TON3(IN:=SR0.Q1, PT:=T#2s)`` and the transition reading ``TON3.Q``.

The latch is a two-step partial grafcet ``SR0_SR``: step ``SR0_off`` (initial) and step
``SR0_on``, whose variable ``XSR0_on`` is ``SR0.Q1``. The PLC calls the block while the
transition is evaluated, i.e. while its source step ``S`` is active, so both transitions
read ``XS``:

* ``SR`` (set dominant, ``Q1 := S1 OR (NOT R AND Q1)``): set when ``XS & S1``, reset when
  ``XS & R & !S1``;
* ``RS`` (reset dominant, ``Q1 := NOT R1 AND (S OR Q1)``): set when ``XS & S & !R1``, reset
  when ``XS & R1``.

The latch's output is its state: a network that feeds it back (the TON above) is no loop.
A located warning states the dominance and the one-scan difference (the PLC reads, in the
latch's inputs, the outputs of blocks it calls after the latch from the previous scan; ``.g7``
sets and resets the latch in the evolution where its conditions hold).

Example
-------
>>> conjunction("XS2", "(a | b)", "!(c)")
'XS2 & (a | b) & !c'
"""

from __future__ import annotations

import re

from synth.codegen.plcopen.blocks import warn_block
from synth.codegen.plcopen.data import DATA, HelperChart
from synth.errors import InputError, Location

__all__ = ["LATCH_BLOCKS", "conjunction", "latch_step", "latch_chart"]

LATCH_BLOCKS = {"SR": ("S1", "R"), "RS": ("S", "R1")}
"""The bistables read in an FBD transition condition, with their set and reset inputs."""


def _bare(text: str) -> str:
    """``text`` without the parentheses around it when they enclose all of it."""
    while text.startswith("(") and text.endswith(")"):
        depth = 0
        for i, ch in enumerate(text):
            depth += {"(": 1, ")": -1}.get(ch, 0)
            if depth == 0 and i < len(text) - 1:
                return text
        text = text[1:-1]
    return text


def conjunction(*terms: str) -> str:
    """The ``.g7`` conjunction of ``terms``, each parenthesised unless it is a literal (a
    negation ``!(x)`` of a literal loses its parentheses)."""
    out = []
    for term in terms:
        neg = term.startswith("!")
        inner = _bare(term[1:] if neg else term)
        simple = re.fullmatch(r"!?[\w/.↑↓]+", inner) is not None and not (neg and inner.startswith("!"))
        out.append(("!" if neg else "") + (inner if simple else f"({inner})"))
    return " & ".join(out)


def latch_step(instance: str) -> str:
    """``Q1`` of the latch ``instance``: the variable of the step ``instance_on``."""
    scope = DATA.get()
    return f"X{scope.prefix if scope is not None else ''}{instance}_on"


def latch_chart(kind: str, instance: str, set_in: str, reset_in: str, sources: list[str], where: Location) -> None:
    """The partial grafcet of the latch ``instance`` (``SR`` or ``RS``: ``kind``) with its set and
    reset inputs ``set_in``/``reset_in`` (``.g7`` texts), read in the condition of a
    transition leaving ``sources``."""
    scope = DATA.get()
    if scope is None or len(sources) != 1:
        raise InputError(f"{kind} {instance} in the condition of a transition with {len(sources)} source steps: "
                         ".g7 reads the latch while the one step the PLC evaluates it in is active", where)
    step = sources[0]
    on = latch_step(instance)[1:]
    off = on.removesuffix("_on") + "_off"
    s, r = _bare(set_in), _bare(reset_in)
    if kind == "SR":
        set_c, reset_c = conjunction(f"X{step}", s), conjunction(f"X{step}", r, f"!({s})")
        rule = "set dominant: Q1 := S1 OR (NOT R AND Q1)"
    else:
        set_c, reset_c = conjunction(f"X{step}", s, f"!({r})"), conjunction(f"X{step}", r)
        rule = "reset dominant: Q1 := NOT R1 AND (S OR Q1)"
    name = f"{instance}_{kind}"
    chart: HelperChart = (name, [(off, True, []), (on, False, [])], [([off], [on], set_c), ([on], [off], reset_c)])
    if any(c[0] == name and c != chart for c in scope.extra_charts):
        raise InputError(f"{kind} {instance} is read in the conditions of transitions leaving different steps: .g7 "
                         "reads one latch per step", where)
    if chart not in scope.extra_charts:
        scope.extra_charts.append(chart)
    warn_block(f"the {kind} {instance} wired to the condition of a transition leaving step {step}: {instance}.Q1 is read "
          f"as X{on}, the activity of step {on} of the partial grafcet {name}, set when {set_c} and reset when "
          f"{reset_c} ({rule}); the PLC calls {instance} only while the transition is evaluated and reads the outputs "
          "of the blocks it calls after the latch from the previous scan, .g7 sets and resets the latch in the "
          "evolution where its conditions hold (one scan earlier)", where)
