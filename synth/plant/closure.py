"""Backward closures of state sets over the plant grid, many sets at once.

"The states from which moves of a kind (uncontrollable ones, say), each guard read
where it occurs, reach a set" is a least fixpoint of :meth:`Plant.preimage`. Computed
set by set on the grid, it cost one pass over every local transition per step and per
set (320 grid pre-images, 3.5 s, for the four-cylinder station's 16 constraint terms).
Here the sets share one pass: each is one bit of an unsigned integer per plant state,
and the plant's moves are in-lists of flat state codes built once per plant and kind;
each step follows only the moves into the states whose bits just changed (a frontier),
so every closure together costs a few passes over the moves.
A plant whose edge arrays would not fit (more than :data:`EDGE_LIMIT` global moves)
falls back to the grid pre-image, set by set: the same fixpoint, the same result.

Example
-------
>>> from synth.plant.rules_check import load_rules
>>> from synth.plant.composition import plant, _plants
>>> p = plant(load_rules(_plants("tri.rules")))
>>> g = np.zeros(p.shape, dtype=bool); g[p.initial] = True
>>> [int(c.sum()) for c in backward_closures(p, [g], controllable=False)] == [int(backward_grid(p, g, False).sum())]
True
"""

from __future__ import annotations

import weakref
from typing import Sequence

import numpy as np

from synth.plant.composition import Plant

__all__ = ["EDGE_LIMIT", "backward_closures", "backward_grid"]

EDGE_LIMIT = 8_000_000
"""At most this many global moves are held as flat code arrays; above, closures run on the grid."""

_BITS = 64
_edges_cache: "weakref.WeakKeyDictionary[Plant, dict[bool | None, tuple[np.ndarray, np.ndarray]]]" = weakref.WeakKeyDictionary()


def _move_bound(p: Plant, controllable: bool | None) -> int:
    """An upper bound on the plant's global moves of the kind (guards not read)."""
    return sum(p.size // p.shape[t.axis] for t in p.transitions if controllable is None or t.controllable == controllable)


def _in_edges(p: Plant, controllable: bool | None) -> tuple[np.ndarray, np.ndarray]:
    """The plant's global moves of the kind whose guard holds at their source, as
    in-lists: the sources of the moves into state ``c`` are ``sources[start[c]:start[c + 1]]``.
    Built once per plant and kind."""
    per_plant = _edges_cache.setdefault(p, {})
    if controllable not in per_plant:
        dtype = np.int32 if p.size < 2**31 else np.int64
        src: list[np.ndarray] = [np.zeros(0, dtype=dtype)]
        dst: list[np.ndarray] = [np.zeros(0, dtype=dtype)]
        flat = np.arange(p.size, dtype=dtype).reshape(p.shape)
        for t in p.transitions:
            if controllable is not None and t.controllable != controllable:
                continue
            s, d = p.slices(t)
            if t.guard is None:
                src.append(flat[s].ravel())
                dst.append(flat[d].ravel())
            else:
                m = np.broadcast_to(p.guard_grid(t), flat[s].shape)
                src.append(flat[s][m])
                dst.append(flat[d][m])
        sources, targets = np.concatenate(src), np.concatenate(dst)
        order = np.argsort(targets, kind="stable")
        start = np.zeros(p.size + 1, dtype=np.int64)
        np.cumsum(np.bincount(targets, minlength=p.size), out=start[1:])
        per_plant[controllable] = (start, sources[order])
    return per_plant[controllable]


def backward_grid(p: Plant, grid: np.ndarray, controllable: bool | None) -> np.ndarray:
    """One closure on the grid: pre-images of the growing set until nothing is added."""
    reach = grid.copy()
    while True:
        more = p.preimage(reach, controllable=controllable) & ~reach
        if not more.any():
            return reach
        reach |= more


def backward_closures(p: Plant, grids: Sequence[np.ndarray], controllable: bool | None) -> list[np.ndarray]:
    """For each grid (a boolean array of the plant's shape), the states from which moves
    of the kind (``None``: every move) reach it, the grid's own states included."""
    if not grids:
        return []
    if _move_bound(p, controllable) > EDGE_LIMIT:
        return [backward_grid(p, g, controllable) for g in grids]
    start, sources = _in_edges(p, controllable)
    out: list[np.ndarray] = []
    for first in range(0, len(grids), _BITS):
        chunk = grids[first:first + _BITS]
        packed = np.zeros(p.size, dtype=np.uint64)
        for k, g in enumerate(chunk):
            packed |= g.reshape(-1).astype(np.uint64) << np.uint64(k)
        touched = np.zeros(p.size, dtype=bool)
        frontier = np.flatnonzero(packed)  # states whose bits are new, and those bits
        delta = packed[frontier]
        while frontier.size:
            lo = start[frontier]
            counts = start[frontier + 1] - lo
            ends = np.cumsum(counts)
            at = np.repeat(lo - (ends - counts), counts) + np.arange(int(ends[-1]))  # the in-moves' positions
            srcs = sources[at]
            bits = np.repeat(delta, counts) & ~packed[srcs]
            hit = np.flatnonzero(bits)
            srcs, bits = srcs[hit], bits[hit]
            touched[srcs] = True
            frontier = np.flatnonzero(touched)
            touched[frontier] = False
            before = packed[frontier]
            np.bitwise_or.at(packed, srcs, bits)
            delta = packed[frontier] & ~before
        for k in range(len(chunk)):
            out.append(((packed >> np.uint64(k)) & np.uint64(1)).astype(bool).reshape(p.shape))
    return out
