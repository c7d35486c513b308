"""``synth filter verify --engine symbolic``: the verdict and the counts of
:class:`~synth.filter.loop.symbolic.rings.SymbolicLoop`, and the shortest traces of the
explicit engine (which engine runs is decided by :mod:`synth.engines`).

The symbolic search knows at which level each kind of finding first appears; the
explicit engine (:class:`~synth.filter.loop.explorer.Explorer`) then runs that many levels
only, so every trace is exactly the one the explicit engine prints, found in the part
of the closed loop before the first finding. When that part is larger than
:data:`TRACE_BUDGET` nodes, or the plant has more states than ``--engine auto`` leaves to
the explicit engine (:data:`synth.engines.VERIFY_THRESHOLD`), the
traces are walked back through the rings (:class:`~synth.filter.loop.symbolic.walk.Walk`):
shortest ones, not necessarily the explicit engine's choice.

Example
-------
>>> from synth.plant.composition import _plants, load_plant
>>> from synth.filter.from_rules import skeleton
>>> sk = skeleton(_plants("tri.rules"), _plants("F.filter"))  # the text only: nothing is written
>>> v = verify_symbolic(sk.filter, load_plant(_plants("tri.rules")))
>>> v.safe, v.coherent, v.states > 1000
(True, True, True)
"""

from __future__ import annotations

import time
from typing import Callable

import numpy as np

from synth.choices import EngineChoice
from synth.engines import VERIFY_THRESHOLD
from synth.filter.cycle import Algorithm, Mode
from synth.filter.language import Filter
from synth.filter.loop.product import rules_of
from synth.filter.loop.verification import ANY_CONTROL, Control, ControlKind, Finding, FindingKind, Verification
from synth.plant.composition import Plant

__all__ = ["verify_symbolic", "TRACE_BUDGET"]

TRACE_BUDGET = 1_000_000
"""The nodes the explicit engine may visit to render the symbolic engine's traces."""


def explicit_findings(f: Filter, p: Plant, algorithm: Algorithm, mode: Mode, atomic: bool, k: int,
                      levels: int, budget: int) -> dict[FindingKind, Finding] | None:
    """The explicit engine's findings after ``levels`` levels of its search (None: the
    plant has more than :data:`~synth.engines.VERIFY_THRESHOLD` states, or the part
    explored does not fit the budget)."""
    from synth.filter.loop.explorer import Explorer
    from synth.filter.loop.product import Product

    if p.size > VERIFY_THRESHOLD:  # where auto runs this engine: the traces walked back, as they always were
        return None
    pr = Product(f, p, None, algorithm, mode, atomic)
    ex = Explorer(pr, budget, k)
    frontier = np.array([ex.key0], dtype=np.int64)
    for _ in range(levels):
        if not ex.complete:  # stopped before the last level: the parents may be missing
            return None
        frontier = ex.level(frontier)
    return ex.findings()


def verify_symbolic(f: Filter, p: Plant, *, algorithm: Algorithm = Algorithm.ALGEBRAIC,
                    mode: Mode = Mode.SUPERVISOR, atomic: bool = False, strict: bool = False,
                    require_sup: bool = False, max_states: int | None = None, events_per_cycle: int = 1,
                    trace_budget: int = TRACE_BUDGET, report: Callable[[str], None] | None = None) -> Verification:
    """The closed loop under any control on the symbolic engine. Every count is the
    explicit engine's; each finding's trace is the explicit engine's shortest one or, when
    the explicit engine cannot render it within ``trace_budget`` nodes (see the module
    docstring), a shortest one walked back through the rings."""
    from synth.filter.loop.symbolic.rings import SymbolicLoop

    started = time.perf_counter()
    loop = SymbolicLoop(f, p, Algorithm(algorithm), Mode(mode), atomic, events_per_cycle, max_states)
    loop.report = report
    loop.run()
    counts = loop.counts()
    kinds = [k for k in FindingKind if k in loop.first_level and (require_sup or k is not FindingKind.OUTSIDE_SUP)]
    findings: dict[FindingKind, Finding] = {}
    if kinds:
        levels = max(loop.first_level[k] for k in kinds) + 1
        shown = explicit_findings(f, p, algorithm, mode, atomic, events_per_cycle, levels, trace_budget)
        if shown is None:  # a walk back through the rings instead
            from synth.filter.loop.symbolic.walk import Walk

            walk = Walk(loop)
            for k in kinds:
                ids, rows = walk.finding(k)
                findings[k] = Finding(k, ids, tuple(rows), counts[k])
        else:
            for k in kinds:
                if k not in shown:
                    raise AssertionError(f"the explicit engine does not find {k} within {levels} levels")
                findings[k] = Finding(k, shown[k].constraints, shown[k].trace, counts[k])
    return Verification(
        f.file, rules_of(p).path, ANY_CONTROL, Algorithm(algorithm), Mode(mode), atomic, strict, loop.states,
        loop.plant_states, loop.cycles, loop.complete, time.perf_counter() - started, loop.outside_sup, findings,
        0, 0, events_per_cycle, None, Control(ControlKind.ANY), EngineChoice.SYMBOLIC)
