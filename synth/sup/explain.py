"""Why a plant state is kept in SUP or removed from it (``synth sup --why``).

Example
-------
>>> from synth.plant.rules_check import load_rules
>>> from synth.plant.composition import plant, _plants
>>> from synth.sup.supervisor import supremal_controllable
>>> rs = load_rules(_plants("tri_annex.rules"))
>>> sup = supremal_controllable(plant(rs), rs.constraints)
>>> explain(sup, sup.plant.initial).status.value
'kept'
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from enum import StrEnum
from typing import Iterable

import numpy as np

from synth.sup.supervisor import Supervisor

__all__ = ["Status", "Explanation", "explain"]


class Status(StrEnum):
    """Where a plant state stands with respect to SUP."""

    ILLEGAL = "illegal"  # it violates a constraint
    DEFENDED = "defended"  # one uncontrollable event leads to an illegal state
    WEAKLY_DEFENDED = "weakly_defended"  # an uncontrollable path leads to a defended state
    KEPT = "kept"  # in SUP
    UNREACHABLE = "unreachable"  # legal, not defended, but not reachable in SUP


@dataclass(frozen=True)
class Explanation:
    """Why a state is kept in or removed from SUP."""

    state: str
    status: Status
    constraints: tuple[str, ...] = ()
    path: tuple[str, ...] = ()  # uncontrollable events leading to the violation
    forbidden: tuple[tuple[str, tuple[str, ...]], ...] = ()  # (event, constraint ids) cut from here

    def as_dict(self) -> dict:
        return {
            "state": self.state,
            "status": self.status,
            "constraints": list(self.constraints),
            "path": list(self.path),
            "forbidden": [{"event": e, "constraints": list(c)} for e, c in self.forbidden],
        }

    def text(self, labels: dict[str, str] | None = None) -> str:
        labels = labels or {}

        def named(ids: Iterable[str]) -> str:
            return ", ".join(f'{i} "{labels[i]}"' if labels.get(i) else i for i in ids)

        s = self.state
        if self.status is Status.ILLEGAL:
            return f"{s} is illegal: it violates {named(self.constraints)}"
        if self.status is Status.DEFENDED:
            return f"{s} is defended: the uncontrollable event {self.path[0]} leads to a state violating {named(self.constraints)}"
        if self.status is Status.WEAKLY_DEFENDED:
            return (
                f"{s} is weakly defended: the uncontrollable path {' '.join(self.path)} leads to a state "
                f"violating {named(self.constraints)}"
            )
        head = f"{s} is kept in SUP" if self.status is Status.KEPT else f"{s} is legal and not defended, but unreachable in SUP"
        if not self.forbidden:
            return head + "; no controllable event is forbidden there"
        lines = [head + "; forbidden controllable events from it:"]
        for e, ids in self.forbidden:
            lines.append(f"  {e}: {named(ids)}")
        return "\n".join(lines)


def explain(sup: Supervisor, local: tuple[int, ...]) -> Explanation:
    """Why ``local`` is in SUP or not, with the shortest uncontrollable path to a violation."""
    p = sup.plant
    label = p.label(local)
    violated = sup.violated(local)
    if violated:
        return Explanation(label, Status.ILLEGAL, tuple(violated))
    if not sup.kept(local):
        # breadth-first search over uncontrollable moves to the nearest violation
        parent: dict[tuple[int, ...], tuple[tuple[int, ...], str] | None] = {local: None}
        queue = deque([local])
        while queue:
            cur = queue.popleft()
            if sup.violated(cur):
                path = []
                node = cur
                while parent[node] is not None:
                    prev, ev = parent[node]  # type: ignore[misc]
                    path.append(ev)
                    node = prev
                path.reverse()
                status = Status.DEFENDED if len(path) == 1 else Status.WEAKLY_DEFENDED
                return Explanation(label, status, tuple(sup.violated(cur)), tuple(path))
            for t, nxt in p.successors(cur):
                if not t.controllable and nxt not in parent:
                    parent[nxt] = (cur, t.event)
                    queue.append(nxt)
        raise AssertionError("removed state with no uncontrollable path to a violation")  # pragma: no cover
    forbidden = []
    for t, nxt in p.successors(local):
        if t.controllable:
            ok, why = sup.move(t, local)
            if not ok:
                forbidden.append((t.event, tuple(why)))
    inside = bool(sup.contains(np.array([p.index(local)], dtype=np.int64))[0])
    status = Status.KEPT if inside else Status.UNREACHABLE
    return Explanation(label, status, (), (), tuple(forbidden))
