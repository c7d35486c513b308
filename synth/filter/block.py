"""The filter block's equations: one model of what ``synth filter st`` emits, which
``synth filter run``, ``verify`` and the closed loop evaluate, so what is verified is
exactly what runs, on and off the care set.

- :func:`algebraic_equations`: the chained equations of the synthesis, in evaluation order
  (each may read the outputs assigned before it, as seed 004's eq. (30) does). Off the care
  set they are what the block computes, not the flat Y-only equations of ``solve --flat``
  (both agree on the care set only).
- :func:`loop_model`: the correction loop's data: fs0/fs1 per output, the combined
  constraints, and the relief matrices MC0/MC1 (outputs × combined constraints).

Example
-------
>>> from synth.filter.language_check import parse_filter
>>> from synth.filter.solve import synthesis
>>> f = parse_filter("outputs o1, o2\\nsafety K: o1 & o2 keep o1", "a.filter")
>>> [(o, e.text()) for o, e in algebraic_equations(synthesis(f))]
[('o1', 'R_o1'), ('o2', 'R_o2 & !o1')]
>>> loop_model(synthesis(f).functions).mc0
((False,), (True,))
"""

from __future__ import annotations

from dataclasses import dataclass

from synth.errors import LimitExceeded
from synth.filter.language_reader import filter_expression
from synth.filter.model import FilterFunctions
from synth.filter.solve import Synthesis
from synth.logic.expr import Expr

__all__ = ["Equations", "algebraic_equations", "LoopModel", "loop_model"]

Equations = tuple[tuple[str, Expr], ...]  # (output, expression), in evaluation order


def algebraic_equations(s: Synthesis) -> Equations:
    """The block's assignments ``o := expr``, in order (the determined outputs only); a
    filter on truth tables (``s.plan``) has none: :class:`LimitExceeded`."""
    if s.plan is not None:
        raise LimitExceeded(f"{s.functions.filter.file}: the filter is its chain of narrowings on truth tables "
                            "(too large for equations: see synth filter solve); it has no equations")
    return tuple((o, filter_expression(text, f"equation {o}")) for o, text in s.chained.items())


@dataclass(frozen=True)
class LoopModel:
    """The correction loop (docs/filter.md) as data: per output (in ``outputs`` order) where a simple
    constraint forces it to 0 / 1, the combined constraints (id, expression), and
    ``mc0[k][i]`` / ``mc1[k][i]``: relieving combined constraint i forces output k to 0 / 1."""

    fs0: tuple[Expr, ...]
    fs1: tuple[Expr, ...]
    combined: tuple[tuple[str, Expr], ...]
    mc0: tuple[tuple[bool, ...], ...]
    mc1: tuple[tuple[bool, ...], ...]


def loop_model(m: FilterFunctions) -> LoopModel:
    """The loop's data of a filter (fs0/fs1 printed from their BDDs, exactly)."""
    e, f = m.engine, m.filter

    def text(u: object) -> Expr:
        return filter_expression(e.text(u), "fs")

    def matrix(value: bool) -> tuple[tuple[bool, ...], ...]:
        return tuple(tuple(any(c.output == o and c.value == value for c in s.forced) for s in f.combined)
                     for o in f.outputs)

    return LoopModel(tuple(text(m.fs0[o]) for o in f.outputs), tuple(text(m.fs1[o]) for o in f.outputs),
                     tuple((s.id, s.expr) for s in f.combined), matrix(False), matrix(True))
