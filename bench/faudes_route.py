"""The libFAUDES side of the benchmark, done the way a libFAUDES user would do it.

Inputs, written once from the ``.rules`` file (not timed as libFAUDES work):

- one ``.gen`` System per element (``synth.faudes_io.element_generator``: events
  ``X_up``/``X_down``, controllable ones flagged ``+C+``, all states marked);
- one small *observer* Generator per level constraint: its states are the valuations
  of the constraint's variables that do not violate it, its events the edges of those
  variables (``x_up`` from x=0 to x=1, ``x_down`` back), its initial state the initial
  valuation. In the product with the plant the observer's state is always the current
  valuation of its variables, and the product has no state where the constraint holds:
  ``plant ∥ observer`` is the plant restricted to the states legal for that constraint.

libFAUDES work (timed):

1. the plant ``G = E_1 ∥ … ∥ E_N`` (``faudes.Parallel``, pairwise, left to right);
2. the specification ``K = G ∥ (O_1 ∥ … ∥ O_m)``: the observers are composed first
   (they share the sensor events of neighbouring cylinders, so their product stays
   small: 3159 states at N=5), then with the plant. ``K`` is ``G`` restricted to legal
   states, on the plant's whole alphabet, as ``SupConClosed`` requires. (Composing
   the observers one by one into ``G``, or interleaving them with the elements, was
   measured 4x to 40x slower at N=5.)
3. ``S = SupConClosed(G, K)``.

Edge constraints (``↓A & !v = 0``) are not supported here (the line benchmark has none).
"""

from __future__ import annotations

import itertools
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from synth.logic.events import Event
from synth.logic.expr import Edge, evaluate, names  # noqa: E402
from synth.output.faudes import element_generator, generator_text  # noqa: E402
from synth.plant.element import element_automaton  # noqa: E402
from synth.plant.rules import Constraint, RuleSet, VarKind  # noqa: E402

__all__ = ["FaudesInputs", "constraint_observer", "write_inputs", "run_faudes"]


def constraint_observer(rs: RuleSet, c: Constraint) -> tuple[str, set[str]]:
    """The observer generator text of level constraint ``c`` and the variables it reads."""
    occurrences = list(names(c.forbidden))
    if any(isinstance(x, Edge) for x in occurrences):
        raise ValueError(f"constraint {c.id}: edge constraints are not supported by the observer route")
    variables = list(dict.fromkeys(x.name for x in occurrences))
    decls = {}
    for v in variables:
        owner = rs.owner(v)
        if owner is None:
            raise ValueError(f"constraint {c.id}: unknown variable {v}")
        decls[v] = owner.variable(v)
    events: dict[Event, bool] = {}
    for v in variables:
        if not decls[v].held:
            ctrl = decls[v].kind == VarKind.ORDER
            events[Event.rise(v)] = ctrl
            events[Event.fall(v)] = ctrl
    events = dict(sorted(events.items()))
    ev_index = {e: i for i, e in enumerate(events)}
    states = []
    for bits in itertools.product((False, True), repeat=len(variables)):
        val = dict(zip(variables, bits))
        if any(decls[v].held and val[v] != decls[v].initial for v in variables):
            continue
        if not evaluate(c.forbidden, val.__getitem__):
            states.append(bits)
    number = {s: k for k, s in enumerate(states)}
    src, ev, dst = [], [], []
    for s in states:
        for j, v in enumerate(variables):
            if decls[v].held:
                continue
            t = list(s)
            t[j] = not t[j]
            t = tuple(t)
            if t in number:
                src.append(number[s])
                dst.append(number[t])
                ev.append(ev_index[Event.edge(v, t[j])])
    init = tuple(decls[v].initial for v in variables)
    arr = lambda xs: np.asarray(xs, dtype=np.int64)  # noqa: E731
    text = generator_text(f"obs_{c.id}", len(states), number.get(init), events, arr(src), arr(ev), arr(dst))
    return text, set(variables)


@dataclass
class FaudesInputs:
    elements: list[Path]                 # one System file per element, in element order
    observers: list[Path]                # one Generator file per level constraint
    seconds: float                       # time to build and write these files


def write_inputs(rs: RuleSet, directory: str | Path) -> FaudesInputs:
    """Write the element Systems and the constraint observers of ``rs`` into ``directory``."""
    t0 = time.perf_counter()
    d = Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    elements = []
    for e in rs.elements:
        path = d / f"element_{e.name}.gen"
        path.write_text(element_generator(element_automaton(e)), encoding="utf-8")
        elements.append(path)
    observers = []
    for c in rs.constraints:
        text, _ = constraint_observer(rs, c)
        path = d / f"observer_{c.id}.gen"
        path.write_text(text, encoding="utf-8")
        observers.append(path)
    return FaudesInputs(elements, observers, time.perf_counter() - t0)


def run_faudes(inputs: FaudesInputs, faudes) -> dict:
    """Plant, specification and SupConClosed with libFAUDES; timings and the generators."""
    t0 = time.perf_counter()
    elements = [faudes.System(str(p)) for p in inputs.elements]
    observers = [faudes.Generator(str(p)) for p in inputs.observers]
    t_read = time.perf_counter() - t0

    t0 = time.perf_counter()
    plant = elements[0]
    for e in elements[1:]:
        nxt = faudes.System()
        faudes.Parallel(plant, e, nxt)
        plant = nxt
    t_plant = time.perf_counter() - t0

    t0 = time.perf_counter()
    spec = plant
    if observers:
        obs = observers[0]
        for o in observers[1:]:
            nxt = faudes.Generator()
            faudes.Parallel(obs, o, nxt)
            obs = nxt
        spec = faudes.Generator()
        faudes.Parallel(plant, obs, spec)
    t_spec = time.perf_counter() - t0

    t0 = time.perf_counter()
    sup = faudes.System()
    faudes.SupConClosed(plant, spec, sup)
    t_sup = time.perf_counter() - t0
    return {
        "read_s": t_read,
        "plant_s": t_plant,
        "spec_s": t_spec,
        "sup_s": t_sup,
        "total_s": t_plant + t_spec + t_sup,
        "plant": plant,
        "spec": spec,
        "sup": sup,
    }
