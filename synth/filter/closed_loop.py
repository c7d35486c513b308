"""``synth filter verify``: the filter in closed loop with synth's plant (FILTER.md §3.4).

The explored product has one node per (plant state, filter memory, Blocked latch,
Grafcet situation). One **PLC cycle** from a node:

1. the plant makes zero or one uncontrollable event (its asynchronous semantics; with
   a Grafcet, a running timer may elapse instead);
2. the PLC reads Y (the plant's inputs; observers are the Grafcet's step variables);
3. the requests R: the Grafcet reacts and its orders are R (``--grafcet``), or R is any
   of the 2^|O| vectors (``--any-control``); in blocking mode ``Ack`` is free too;
4. the filter computes O (:class:`~synth.filter.cycle.FilterCycle`);
5. the orders that change are applied as the plant's controllable events, **falls
   first, then rises, each in the plant's output order** (an order is released before
   another is taken); with ``atomic=True`` all at once (one step, no intermediate state).

Plant orders the filter does not declare are passed through (O = R for them); an order
the rules ``hold`` is requested at its held value.

Verdicts, over everything reachable:

- (a) *safe*: no node (a plant state once the PLC has written its outputs) violates a
  level constraint of the rules, no output event breaks an edge constraint, and the
  plant accepts every output change. The filter's constraints hold *at the end of
  every cycle*; between the plant's event and the next write the plant may briefly be
  in a violating state the filter could not prevent (the PLC is synchronous, the plant
  asynchronous): such *transient* states — and the intermediate states of an ordered
  write — are counted and shown but fail the verdict only with ``strict=True``. Nodes
  outside SUP (a violation reachable by uncontrollable events alone) are counted, and
  fail the verdict only with ``require_sup=True``;
- (b) *coherent*: the loop never falls back and the algebraic filter never meets a Y
  outside its care set;
- (c) with a Grafcet: the cycles where O ≠ R and the largest Hamming distance.

Every finding comes with a shortest trace (breadth-first, in cycles). The exploration is
explicit (numpy arrays over the plant's state codes, one level of the breadth-first
search at a time) and stops after ``max_states`` nodes. The parts: the product's arrays
(:mod:`~synth.filter.product`), the search (:mod:`~synth.filter.explorer`, one cycle's
outcomes in :mod:`~synth.filter.outcomes`) and what it finds
(:mod:`~synth.filter.verification`); :mod:`synth.output.filter_text` prints it.

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.filter.from_rules import skeleton
>>> sk = skeleton(_plants("tri.rules"), _plants("F.filter"))  # the text only: nothing is written
>>> v = verify(sk.filter, _plants("tri.rules"), any_control=True)
>>> v.safe, v.coherent, v.states > 1000
(True, True, True)
"""

from __future__ import annotations

import time

from synth.errors import InputError
from synth.filter.cycle import Algorithm, Mode
from synth.filter.explorer import Explorer
from synth.filter.language import Filter
from synth.filter.product import Product
from synth.filter.verification import ANY_CONTROL, FindingKind, Verification

__all__ = ["verify"]


def verify(f: Filter, rules_path: str, grafcet: str | None = None, *, any_control: bool = False,
           algorithm: Algorithm = Algorithm.ALGEBRAIC, mode: Mode = Mode.SUPERVISOR, atomic: bool = False,
           strict: bool = False, require_sup: bool = False, max_states: int = 1_000_000) -> Verification:
    """Explore the closed loop (see the module docstring)."""
    if (grafcet is None) == (not any_control):
        raise InputError("verify needs a request source: --grafcet G.g7 or --any-control (one of them)", None)
    started = time.perf_counter()
    pr = Product(f, rules_path, grafcet, Algorithm(algorithm), Mode(mode), atomic)
    ex = Explorer(pr, max_states)
    ex.run()
    findings = ex.findings()
    if not require_sup:
        findings.pop(FindingKind.OUTSIDE_SUP, None)
    return Verification(
        f.file, rules_path, grafcet if grafcet is not None else ANY_CONTROL, pr.cycle.algorithm, pr.cycle.mode,
        atomic, strict, len(ex.seen_keys), len({k % pr.size for k in ex.seen_keys}), ex.cycles, ex.complete,
        time.perf_counter() - started, len(ex.outside_sup), findings, ex.corrected, ex.max_distance)
