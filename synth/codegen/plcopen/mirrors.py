"""Step flags read before their step's declaration: what ``synth sfc`` writes instead, and how
``synth import`` reads it back.

MATIEC (the compiler of Beremiz and OpenPLC) accepts ``S106.X`` only after ``STEP S106`` in
the program's text, and Beremiz writes an SFC depth-first from each initial step, the partial
grafcets one after the other: a receptivity or an action of partial grafcet G1 that reads a
step of G2 is refused (and ``iec2c`` then runs out of memory). So such a step drives a local
BOOL of its own, its *mirror* ``_X_S106``, from an ``N`` action (``TRUE`` while the step is
active, ``FALSE`` from the scan that leaves it; initially ``TRUE`` for an initial step), and the
reads read the mirror. MATIEC updates the variables of ``N`` actions after the scan's
evolution and before it runs the action bodies, so the mirror is the step's flag wherever it
is read: in a transition (the activity the previous scan left) and in an action body (the
activity after this scan's evolution) — measured with Beremiz and ``iec2c``
(``tests/test_sfc_beremiz.py``).

Example
-------
>>> from synth.grafcet.language_check import parse_grafcet
>>> g = parse_grafcet('''grafcet G1 {
...   initial step 0
...   step 1: A if !X11
...   transition 0 -> 1 when X10
...   transition 1 -> 0 when !X10
... }
... grafcet G2 {
...   initial step 10
...   step 11
...   transition 10 -> 11 when X1
...   transition 11 -> 10 when X0
... }''', "two.g7")
>>> sorted(mirrored_steps(g)), mirror_flag("10")
(['10', '11'], '_X_S10')
"""

from __future__ import annotations

import re
from synth.codegen.plcopen.sfc import Chart
from synth.codegen.plcopen.tc6 import sfc_step_name
from synth.grafcet.language import Grafcet
from synth.logic.expr import Expr, Var, names as expr_names

__all__ = ["MIRROR_PREFIX", "mirror_flag", "writing_order", "mirrored_steps", "merge_mirrors"]

MIRROR_PREFIX = "_X_"
"""The prefix of a step's mirror (``_X_S106``)."""


def mirror_flag(step: str) -> str:
    """The local BOOL that mirrors the flag of the ``.g7`` step ``step`` in the SFC."""
    return MIRROR_PREFIX + sfc_step_name(step)


def writing_order(g: Grafcet) -> dict[str, int]:
    """Each step's rank in the program Beremiz generates: depth-first from each initial step
    (in the file's order), the transitions of a step in their order; steps no initial step
    leads to come last, in file order."""
    outgoing: dict[str, list[int]] = {s.name: [] for s in g.steps}
    for i, t in enumerate(g.transitions):
        for s in t.sources:
            outgoing[s].append(i)
    rank: dict[str, int] = {}

    def visit(start: str) -> None:
        stack = [start]
        while stack:
            name = stack.pop()
            if name in rank:
                continue
            rank[name] = len(rank)
            following = [x for i in outgoing[name] for x in g.transitions[i].targets]
            stack.extend(reversed(following))

    for step in g.steps:
        if step.initial:
            visit(step.name)
    for step in g.steps:
        rank.setdefault(step.name, len(rank))
    return rank


def _steps_read(e: Expr, steps: set[str]) -> set[str]:
    return {n.name[1:] for n in expr_names(e) if isinstance(n, Var) and n.name.startswith("X") and n.name[1:] in steps}


def mirrored_steps(g: Grafcet) -> set[str]:
    """The steps whose flag a transition or an action reads before the step's declaration in
    :func:`writing_order` (a transition is placed at the first of its source steps)."""
    rank = writing_order(g)
    steps = set(rank)
    found: set[str] = set()
    for t in g.transitions:
        at = min((rank[s] for s in t.sources), default=len(rank))
        found |= {s for s in _steps_read(t.receptivity, steps) if rank[s] > at}
    for st in g.steps:
        for a in st.actions:
            if a.condition is not None:
                found |= {s for s in _steps_read(a.condition, steps) if rank[s] > rank[st.name]}
    return found


def merge_mirrors(chart: Chart) -> None:
    """``synth import`` of the mirrors: a step whose one action names its own mirror
    (``_X_S106`` on step ``106``) loses that action, and every read of the mirror reads the
    step's flag ``X106`` (the warning that the mirror, a local nothing assigns, is read as an
    input goes with it: the step's action assigns it)."""
    renames: dict[str, str] = {}
    for st in chart.steps:
        own = mirror_flag(st.name)
        if own in st.actions:
            st.actions.remove(own)
            renames[own] = f"X{st.name}"
    if not renames:
        return
    pattern = re.compile(r"(?<![\w/])(" + "|".join(map(re.escape, renames)) + r")(?!\w)")

    def sub(text: str) -> str:
        return pattern.sub(lambda m: renames[m[1]], text)

    for st in chart.steps:
        st.actions = [sub(a) for a in st.actions]
    chart.transitions[:] = [(label, sources, targets, sub(expr), el) for label, sources, targets, expr, el
                            in chart.transitions]
    chart.outputs[:] = [o for o in chart.outputs if o not in renames]
    chart.inputs[:] = [i for i in chart.inputs if i not in renames]
    chart.warnings[:] = [w for w in chart.warnings if not any(w.message.startswith(f"'{f}', declared in <")
                                                              for f in renames)]
