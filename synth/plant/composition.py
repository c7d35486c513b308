"""Asynchronous composition of element automata: the plant (docs/method.md, plant).

The plant is never built transition by transition. A global state is the tuple of
the elements' local states, stored as a position in an N-dimensional numpy grid of
shape ``(|Q_1|, ..., |Q_N|)`` (its flat index is the state's code). A transition of
the product is a local transition of one element, the other coordinates unchanged,
so "all global transitions of local transition t of element i" is the pair of grid
slices ``[..., src_t, ...]`` and ``[..., dst_t, ...]`` along axis i: image and
pre-image of a state set are a handful of vectorised slice operations.

Every local state of every element is reachable (element automata keep only
reachable states) and elements move independently, so every grid position is a
reachable plant state: ``|Q| = Π|Q_i|`` and ``|δ| = Σ_i |δ_i| Π_{j≠i} |Q_j|``.

An element that ``reads`` other elements' variables is the exception: its local
transition ``t`` carries ``guard``, a truth table over the codes of the variables it
reads, and its global copies are those whose source satisfies it (``enabled``). Such a
plant (``reads`` true) is explored from its initial state: ``reachable`` is the grid of
its reachable states, ``state_count`` their number, and ``count_transitions`` counts the
enabled transitions leaving them. Still one variable changes per event.

Example
-------
>>> from synth.plant.rules_check import load_rules
>>> p = plant(load_rules(_plants("tri_annex.rules")))
>>> p.size, p.count_transitions(controllable=False) > 0
(15552, True)
"""

from __future__ import annotations

import functools
import math
from functools import cached_property
from pathlib import Path
from typing import Callable, Iterator, Mapping

import numpy as np

from synth.errors import InputError, LimitExceeded, Location, SynthError, close_names, location_in
from synth.frozen import frozen
from synth.logic.events import Event
from synth.plant.element import ElementAutomaton, element_automaton
from synth.plant.rules import RuleSet

__all__ = ["Plant", "plant", "asynchronous_composition", "LocalTransition", "READS_GRID_LIMIT"]

READS_GRID_LIMIT = 50_000_000
"""A plant whose elements read each other is explored on its grid: at most this many states."""


def _plants(name: str) -> str:
    return str(Path(__file__).resolve().parents[2] / "plants" / name)


@frozen
class LocalTransition:
    """A transition of one element, seen from the grid: axis, local source/target, event."""

    axis: int
    src: int
    dst: int
    event: Event
    controllable: bool
    guard: tuple[bool, ...] | None = None  # over the codes of the element's reads; None: always enabled


class _LocalValues(dict[int, dict[str, bool]]):
    """Local state index → its variables' values, for one element, filled on first use."""

    def __init__(self, element: ElementAutomaton) -> None:
        super().__init__()
        self.element = element

    def __missing__(self, k: int) -> dict[str, bool]:
        code = int(self.element.codes[k])
        values = self[k] = {v: bool((code >> b) & 1) for b, v in enumerate(self.element.variables)}
        return values


class Plant:
    """The asynchronous product of element automata (see module docstring)."""

    def __init__(self, elements: tuple[ElementAutomaton, ...], rules: RuleSet | None = None) -> None:
        self.elements = elements
        self.rules = rules
        self.shape = tuple(e.size for e in elements)
        self.ndim = len(elements)
        self.size = math.prod(self.shape) if elements else 0  # a Python int: no overflow
        strides, size = [], 1
        for n in reversed(self.shape):  # row-major strides in one pass (was quadratic in the elements)
            strides.append(size)
            size *= n
        self.strides = tuple(reversed(strides))
        self.owner: dict[str, int] = {v: i for i, e in enumerate(elements) for v in e.variables}
        self.initial = tuple(e.initial for e in elements)
        if rules is not None:
            self.inputs = tuple(rules.inputs)
            self.outputs = tuple(rules.outputs)
        else:
            self.inputs = tuple(v for e in elements for v in e.variables if v not in e.orders)
            self.outputs = tuple(v for e in elements for v in e.variables if v in e.orders)
        self.variables = self.inputs + self.outputs

    def element(self, name: str) -> ElementAutomaton:
        """The automaton of element ``name``; an unknown name is an error that lists the
        close valid names."""
        for a in self.elements:
            if a.name == name:
                return a
        names = [a.name for a in self.elements]
        hint = close_names(name, names)
        where = self.rules.path if self.rules is not None else "the plant"
        raise SynthError(
            f"no element '{name}' in {where}"
            + (f" (did you mean {' or '.join(hint)}?)" if hint else "")
            + f"; elements: {', '.join(names)}"
        )

    @property
    def warnings(self) -> tuple:
        """Warnings found while building the element automata (rules that never apply)."""
        return tuple(w for e in self.elements for w in e.warnings)

    # ------------------------------------------------------------------ structure
    @cached_property
    def transitions(self) -> tuple[LocalTransition, ...]:
        out = []
        for i, e in enumerate(self.elements):
            for t in range(e.src.size):
                out.append(LocalTransition(i, int(e.src[t]), int(e.dst[t]), e.event(t), bool(e.controllable[t]), e.guard(t)))
        return tuple(out)

    # ------------------------------------------------------------------ reads
    @cached_property
    def readers(self) -> tuple[str, ...]:
        """The elements that read other elements' variables, in declaration order."""
        return tuple(e.name for e in self.elements if e.guards is not None and not bool(e.guards.all()))

    @cached_property
    def reads_at(self) -> Location | None:
        """Where the rules say the first ``reads`` (for an error that refuses them), if anywhere."""
        specs = self.rules.elements if self.rules is not None else ()
        return next((r.loc or s.loc for s in specs for r in s.reads if r.loc or s.loc), None)

    @cached_property
    def reads(self) -> bool:
        """Some element reads another's variables: moves depend on the global state."""
        return bool(self.readers)

    def enabled(self, t: LocalTransition, local: tuple[int, ...]) -> bool:
        """Whether ``t`` may occur in the state ``local`` (its source assumed there)."""
        if t.guard is None:
            return True
        val = self.valuation(local)
        return t.guard[sum(1 << j for j, r in enumerate(self.elements[t.axis].reads) if val[r])]

    def enabled_digits(self, t: LocalTransition, digits: np.ndarray) -> np.ndarray:
        """Whether ``t``'s guard holds at each state whose local indices (ndim × n) are given."""
        if t.guard is None:
            return np.ones(digits.shape[1], dtype=bool)
        code = np.zeros(digits.shape[1], dtype=np.int64)
        for j, r in enumerate(self.elements[t.axis].reads):
            a = self.owner[r]
            code |= self.elements[a].value(r)[digits[a]].astype(np.int64) << j
        return np.asarray(t.guard, dtype=bool)[code]

    def guard_grid(self, t: LocalTransition) -> np.ndarray:
        """``t``'s guard as an array broadcastable to the grid of its sources ``[..., src, ...]``
        (built once per transition: read-only)."""
        if t.guard is None:
            return np.ones((1,) * (self.ndim - 1), dtype=bool)
        grid = self._guard_grids.get(t)
        if grid is None:
            grid = self._guard_grids[t] = self._build_guard_grid(t)
            grid.flags.writeable = False
        return grid

    @functools.cached_property
    def _guard_grids(self) -> dict[LocalTransition, np.ndarray]:
        return {}

    def _build_guard_grid(self, t: LocalTransition) -> np.ndarray:
        assert t.guard is not None
        code = np.zeros((1,) * self.ndim, dtype=np.int64)
        for j, r in enumerate(self.elements[t.axis].reads):
            code = code | (self.values(r).astype(np.int64) << j)
        return np.asarray(t.guard, dtype=bool)[code][(slice(None),) * t.axis + (0,)]

    @cached_property
    def reachable(self) -> np.ndarray:
        """The grid of the states reachable from the initial state (every state without reads)."""
        if not self.reads:
            return np.ones(self.shape, dtype=bool)
        if self.size > READS_GRID_LIMIT:
            raise LimitExceeded(
                f"the plant has {self.size} states and elements that read each other's variables; "
                f"its reachable states are computed on its grid, at most {READS_GRID_LIMIT} states"
            )
        reach = np.zeros(self.shape, dtype=bool)
        reach[self.initial] = True
        grow = True
        while grow:
            grow = False
            for t in self.transitions:
                s, d = self.slices(t)
                new = reach[s] & self.guard_grid(t) & ~reach[d]
                if new.any():
                    reach[d] |= new
                    grow = True
        return reach

    @property
    def state_count(self) -> int:
        """The number of reachable plant states (``size`` without reads)."""
        return int(np.count_nonzero(self.reachable)) if self.reads else self.size

    @cached_property
    def events(self) -> dict[Event, bool]:
        """Every event of the plant and whether it is controllable, sorted by name."""
        return dict(sorted({t.event: t.controllable for t in self.transitions}.items()))

    def count_transitions(self, controllable: bool | None = None) -> int:
        """Transitions leaving reachable states (of the given kind)."""
        if self.reads:
            return sum(int(np.count_nonzero(self.reachable[self.slices(t)[0]] & self.guard_grid(t)))
                       for t in self.transitions if controllable is None or t.controllable == controllable)
        total = 0
        for i, e in enumerate(self.elements):
            others = self.size // e.size
            total += e.count(controllable) * others
        return total

    @property
    def initial_index(self) -> int:
        return self.index(self.initial)

    def index(self, local: tuple[int, ...]) -> int:
        return sum(k * st for k, st in zip(local, self.strides))

    def local(self, index: int) -> tuple[int, ...]:
        return tuple((index // st) % n for st, n in zip(self.strides, self.shape))

    # ------------------------------------------------------------------ values
    def values(self, name: str) -> np.ndarray:
        """Value of variable ``name`` as an array broadcastable to the grid."""
        i = self.owner[name]
        v = self.elements[i].value(name)
        shape = [1] * self.ndim
        shape[i] = v.size
        return v.reshape(shape)

    def valuation(self, local: tuple[int, ...]) -> dict[str, bool]:
        """Every variable's value in the state ``local`` (a tuple of local indices)."""
        out: dict[str, bool] = {}
        for values, k in zip(self._local_values, local):
            out.update(values[k])
        return out

    @functools.cached_property
    def _local_values(self) -> tuple[_LocalValues, ...]:
        """Per element, the variables' values of its local states, each decoded once, when
        first met (decoding bit by bit on every call was a quarter of an explicit
        validation's time; a large element is never decoded whole)."""
        return tuple(_LocalValues(e) for e in self.elements)

    def label(self, local: tuple[int, ...]) -> str:
        """``{TAPIS,v10,...}``: the true variables in E-then-Z order."""
        val = self.valuation(local)
        return "{" + ",".join(v for v in self.variables if val[v]) + "}"

    def vectors(self, local: tuple[int, ...]) -> tuple[str, str]:
        """The E and Z vectors as bit strings in declaration order."""
        val = self.valuation(local)
        return ("".join("1" if val[v] else "0" for v in self.inputs), "".join("1" if val[v] else "0" for v in self.outputs))

    def admissible_inputs(self) -> "Callable[[Mapping[str, bool]], bool]":
        """A test of whether an input vector (a mapping over some plant inputs; the others
        are free) agrees with some plant state: each element's inputs must match one of its
        local states. Used to keep a Grafcet's exploration to vectors the plant can produce.

        >>> from synth.plant.rules_check import load_rules
        >>> ok = plant(load_rules(_plants("tri.rules"))).admissible_inputs()
        >>> ok({"cp11": True, "cp12": False}), ok({"cp11": True, "cp12": True})
        (True, False)
        """
        per_element = []
        for e in self.elements:
            names = [v for v in e.variables if v not in e.orders]
            if not names:
                continue
            bits = [e.variables.index(v) for v in names]
            rows = {tuple(bool((int(c) >> b) & 1) for b in bits) for c in e.codes}
            per_element.append((names, rows))

        def admissible(values: Mapping[str, bool]) -> bool:
            for names, rows in per_element:
                known = [(k, values[n]) for k, n in enumerate(names) if n in values]
                if known and not any(all(r[k] == v for k, v in known) for r in rows):
                    return False
            return True

        return admissible

    def parse_state(self, text: str, where: str = "--why") -> tuple[int, ...]:
        """A state written as its true variables (``"TAPIS,v10,v20"`` or ``{...}``); errors are
        located in ``text`` as the option ``where``."""
        import re

        true = set()
        for m in re.finditer(r"[^\s{},]+", text):
            w = m.group()
            if w not in self.owner:
                raise InputError(f"unknown variable '{w}' in the state", location_in(where, text, 1, m.start() + 1, len(w)),
                                 suggestions=close_names(w, self.owner))
            true.add(w)
        local = []
        for e in self.elements:
            code = sum(1 << b for b, v in enumerate(e.variables) if v in true)
            hits = np.nonzero(e.codes == code)[0]
            if hits.size == 0:
                shown = "{" + ",".join(v for v in e.variables if v in true) + "}"
                raise InputError(f"{shown} is not a state of element {e.name}: it is incoherent or unreachable in its rules",
                                 location_in(where, text, 1, 1, max(1, len(text))))
            local.append(int(hits[0]))
        return tuple(local)

    # ------------------------------------------------------------------ moves
    def successors(self, local: tuple[int, ...]) -> Iterator[tuple[LocalTransition, tuple[int, ...]]]:
        """Outgoing transitions of one state, in a stable order."""
        for t in self.transitions:
            if local[t.axis] == t.src and self.enabled(t, local):
                nxt = list(local)
                nxt[t.axis] = t.dst
                yield t, tuple(nxt)

    def drifts_to(self, local: tuple[int, ...], event: Event) -> bool:
        """Whether ``event`` can occur from ``local`` through uncontrollable moves only (the
        orders as they are), each guard read in the state where the move occurs: exact where
        an element's own automaton, which keeps a move some value of its reads allows, is not."""
        seen, todo = {local}, [local]
        while todo:
            for t, nxt in self.successors(todo.pop()):
                if t.controllable:
                    continue
                if t.event == event:
                    return True
                if nxt not in seen:
                    seen.add(nxt)
                    todo.append(nxt)
        return False

    def slices(self, t: LocalTransition) -> tuple[tuple, tuple]:
        """Grid index tuples selecting the sources and targets of ``t`` (views, no copy)."""
        pre = (slice(None),) * t.axis
        return pre + (t.src,), pre + (t.dst,)

    def preimage(self, mask: np.ndarray, controllable: bool | None = None) -> np.ndarray:
        """States with a transition (of the given kind) into ``mask``."""
        out = np.zeros(self.shape, dtype=bool)
        for t in self.transitions:
            if controllable is not None and t.controllable != controllable:
                continue
            s, d = self.slices(t)
            out[s] |= mask[d] & self.guard_grid(t)
        return out

    def transition_arrays(self, keep: np.ndarray | None = None) -> Iterator[tuple[LocalTransition, np.ndarray, np.ndarray]]:
        """For each local transition, flat source and target codes of its global copies
        (restricted to sources and targets in ``keep`` when given, and to the sources where
        its guard holds)."""
        flat = np.arange(self.size, dtype=np.int64).reshape(self.shape)
        for t in self.transitions:
            s, d = self.slices(t)
            src, dst = flat[s], flat[d]
            if keep is not None or t.guard is not None:
                m = np.broadcast_to(self.guard_grid(t), src.shape)
                if keep is not None:
                    m = m & keep[s] & keep[d]
                src, dst = src[m], dst[m]
            yield t, src.ravel(), dst.ravel()


def asynchronous_composition(elements: tuple[ElementAutomaton, ...], rules: RuleSet | None = None) -> Plant:
    """The interleaving product of ``elements``."""
    return Plant(elements, rules)


def plant(rules: RuleSet) -> Plant:
    """The plant of a rule set: its elements' automata, composed asynchronously."""
    return asynchronous_composition(tuple(element_automaton(e) for e in rules.elements), rules)


def load_plant(path: str | Path) -> Plant:
    """Read, parse and check the ``.rules`` file ``path``, and build its plant (its rule set
    is ``.rules``)."""
    from synth.plant.rules_check import load_rules

    return plant(load_rules(path))

