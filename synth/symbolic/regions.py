"""Per-element region closures: the controllable moves SUP allows towards an element's own
emitted orders, as relations, and their forward closures, each computed once.

Both SYNC representations settle a region element by element (inputs do not change in a
region, and an element's controllable moves flip its own orders): the per-situation
path (:mod:`synth.symbolic.situations.sync`) per set of emitted orders, the step path
(:mod:`synth.symbolic.steps.sync`) per element and set of its own orders, selected by
the step variables. This module is what they share.

Relations are over (member ``x'``, next member ``x''``): the next copy is the member, the
auxiliary copy the state one region move further.

Example
-------
>>> from synth.plant.composition import plant, _plants
>>> from synth.plant.rules_check import load_rules
>>> from synth.symbolic.supervisor import SymbolicSupervisor
>>> rs = load_rules(_plants("tri.rules"))
>>> sup = SymbolicSupervisor(plant(rs), rs.constraints)
>>> regions = ElementRegions(sup)
>>> axis = next(a for a, own in enumerate(regions.orders_of) if own)
>>> rel, can, refused = regions.intra(axis, regions.orders_of[axis])
>>> rel != sup.enc.engine.false, regions.reads_others(axis, rel)  # tri's constraints read other orders
(True, True)
>>> pairs = regions.closure(axis, rel)
>>> (pairs & regions.equal) != sup.enc.engine.false  # a region reaches its entry (no move)
True
"""

from __future__ import annotations

from synth.logic.bdd import Function
from synth.logic.events import Event
from synth.symbolic.encoding import Copy
from synth.symbolic.relation import Move
from synth.symbolic.supervisor import SymbolicSupervisor

__all__ = ["ElementRegions"]

Intra = tuple[Function, Function, dict[Event, Function]]  # region moves, where one is left, where SUP refuses one


class ElementRegions:
    """Each element's region moves under its own emitted orders, and their closures."""

    def __init__(self, sup: SymbolicSupervisor) -> None:
        self.sup = sup
        self.enc = sup.enc
        self.engine = sup.enc.engine
        self.false: Function = self.engine.false
        p = sup.plant
        self.orders_of: tuple[frozenset[str], ...] = tuple(frozenset(e.orders) for e in p.elements)
        """Per element, the orders it has (the variables its controllable moves flip)."""
        self.other_orders: tuple[frozenset[str], ...] = tuple(
            frozenset(o + Copy.NEXT.value for b, e in enumerate(p.elements) if b != a for o in e.orders)
            for a in range(p.ndim))
        """Per element, the other elements' orders in the next copy (what a region move must not read)."""
        self._controllable = tuple(tuple(m for m in sup.moves if m.controllable and m.axis == a) for a in range(p.ndim))
        self._moves: dict[int, tuple[Function, Function, Function]] = {}
        self._intras: dict[tuple[int, frozenset[str]], Intra] = {}
        self._eq: Function | None = None

    @property
    def equal(self) -> Function:
        """x = x' on every plant variable."""
        if self._eq is None:
            self._eq = self.engine.conjunction(
                self.engine.var(v).equiv(self.engine.var(v + Copy.NEXT.value)) for v in self.enc.variables)
        return self._eq

    def own(self, axis: int, wanted: frozenset[str]) -> frozenset[str]:
        """The orders of ``wanted`` that element ``axis`` has."""
        return wanted & self.orders_of[axis]

    def intra(self, axis: int, own: frozenset[str]) -> Intra:
        """For element ``axis`` under its own emitted orders ``own``: its region moves as a
        relation over (member x', next member x''), the states with a region move left,
        and per order event the states where SUP refuses that move (cached)."""
        key = (axis, own)
        hit = self._intras.get(key)
        if hit is None:
            rel = progress = self.false
            refused: dict[Event, Function] = {}
            for m in self._controllable[axis]:
                if m.event.rising != (m.variable in own):
                    continue
                shifted, can, bad = self.move(m)
                progress |= can
                if bad != self.false:
                    refused[m.event] = refused.get(m.event, self.false) | bad
                rel |= shifted
            hit = self._intras[key] = (rel, progress, refused)
        return hit

    def move(self, m: Move) -> tuple[Function, Function, Function]:
        """For one controllable move, computed once: its allowed part over (member x',
        next member x''), the states where it is allowed, those where SUP refuses it."""
        hit = self._moves.get(m.key)
        if hit is None:
            ok = self.sup.allowed(m)
            names = self.enc.element_variables[m.axis]
            can = self.enc.exists(ok, Copy.NEXT, names)
            bad = m.guard & ~can  # the guard: where the move exists at all
            shifted = self.enc.rename(self.enc.rename(ok, Copy.NEXT, Copy.AUX, names), Copy.CURRENT, Copy.NEXT)
            hit = self._moves[m.key] = (shifted, can, bad)
        return hit

    def reads_others(self, axis: int, rel: Function) -> bool:
        """Whether the region moves ``rel`` of element ``axis`` read another element's orders
        (then a region is not the product of the elements' closures)."""
        others = self.other_orders[axis]
        return rel != self.false and any(n in others for n in self.engine.support(rel))

    def closure(self, axis: int, rel: Function) -> Function:
        """Pairs (x_a, x'_a) of element ``axis``: x'_a reachable from x_a by its region moves
        ``rel`` (a forward fixpoint over that element's variables only)."""
        names = self.enc.element_variables[axis]
        reach = self.engine.conjunction(self.engine.var(v).equiv(self.engine.var(v + Copy.NEXT.value)) for v in names)
        frontier = reach
        while frontier != self.false and rel != self.false:
            step = self.enc.rename(self.enc.and_exists(frontier, rel, Copy.NEXT, names), Copy.AUX, Copy.NEXT, names)
            frontier = step & ~reach
            reach |= frontier
        return reach
