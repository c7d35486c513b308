"""Shared orders read back (``synth import`` of what ``synth sfc`` writes): an order that several
steps emit is written as one flag per step (``_N_RUN_S1``, driven by that step's own ``N``
action) and an ``S`` action on an initial step, ``RUN := _N_RUN_S1 OR _N_RUN_S2;``, run at every
scan (:func:`synth.codegen.plcopen.export.shared_orders` says why). Read back, each step's action
on its flag is the same action on the order, and the flags disappear.

Example
-------
>>> shared_assignment("RUN := _N_RUN_S1 OR _N_RUN_S2;")
('RUN', ['_N_RUN_S1', '_N_RUN_S2'])
>>> shared_assignment("RUN := a OR b;") is None
True
"""

from __future__ import annotations

import re
from typing import Any, Callable

from synth.codegen.plcopen.data import FLAG_PREFIX
from synth.codegen.plcopen.sfc import Chart
from synth.errors import InputError, Location

__all__ = ["MARK", "shared_assignment", "merge_shared"]

MARK = "\x00shared "
"""How an action string carries a shared order until :func:`merge_shared` distributes it."""


def shared_assignment(body: str) -> tuple[str, list[str]] | None:
    """``(order, flags)`` when ``body`` is ``ORDER := _N_… OR _N_…;``, else None."""
    m = re.fullmatch(r"\s*(\w+)\s*:=\s*(\w+(?:\s+OR\s+\w+)*)\s*;?\s*", body, re.I)
    if m is None:
        return None
    flags = re.split(r"\s+OR\s+", m[2], flags=re.I)
    return (m[1], flags) if all(f.startswith(FLAG_PREFIX) for f in flags) else None


def merge_shared(chart: Chart, at: Callable[[Any], Location]) -> None:
    """Each marked action of ``chart`` (on an initial step, else a located error) distributed:
    the steps' actions on its flags become actions on the order."""
    renames: dict[str, str] = {}
    for st in chart.steps:
        for action in [a for a in st.actions if a.startswith(MARK)]:
            st.actions.remove(action)
            order, flags = action[len(MARK):].split(" := ", 1)
            if not st.initial:
                raise InputError(f"the order {order} written as {flags.replace(' ', ' OR ')} by an S action of step "
                                 f"{st.name}, which is not initial: that action runs only once the step is reached",
                                 at(st.el))
            renames.update({f: order for f in flags.split()})
    if not renames:
        return
    pattern = re.compile(r"(?<![\w/])(" + "|".join(map(re.escape, renames)) + r")(?!\w)")
    for st in chart.steps:
        st.actions = [pattern.sub(lambda m: renames[m[1]], a) for a in st.actions]
    chart.outputs[:] = [o for o in chart.outputs if o not in renames]
    chart.inputs[:] = [i for i in chart.inputs if i not in renames]
