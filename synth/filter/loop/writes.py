"""Two steps of a PLC cycle in ``synth filter verify``, on whole arrays of plant states:
the plant's events before the scan merged per (node, state) (:func:`merge_events`), and the
write of the orders, falls first, then rises (:func:`write`).

Example
-------
>>> import numpy as np
>>> fi, post, seq, bits = merge_events([np.array([0, 0]), np.array([5, 5]), np.array([1, 2]),
...                                     np.array([1, 2], dtype=np.uint64)], 10, np.array([3]), False)
>>> fi.tolist(), post.tolist(), seq.tolist(), bits.tolist()
([0], [5], [1], [3])
"""

from __future__ import annotations

import numpy as np

from synth.filter.loop.product import Product
from synth.logic.events import Event

__all__ = ["merge_events", "write"]


def write(pr: Product, post: np.ndarray, targets: np.ndarray
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[str], np.ndarray]:
    """Step 5 for arrays of (state, target orders): the state after the write (-1 when
    refused), refused, edge constraint broken (and by which events), and an
    intermediate state violating a constraint."""
    cur, before = post.copy(), post
    bits = np.stack([pr.val[z][post] for z in pr.orders], axis=1)  # the orders now
    refused = np.zeros(post.size, dtype=bool)
    edge_bad = np.zeros(post.size, dtype=bool)
    edge_events: list[str] = []
    middle_bad = np.zeros(post.size, dtype=bool)
    for rising in (False, True):  # falls first, then rises, each in output order
        for z, name in enumerate(pr.orders):
            idx = np.nonzero((targets[:, z] == rising) & (bits[:, z] != rising) & ~refused)[0]
            if not idx.size:
                continue
            ev = Event.edge(name, rising)
            c = cur[idx]
            if ev in pr.forbid:
                hit = pr.forbid[ev][before[idx] if pr.atomic else c]
                if hit.any():
                    edge_bad[idx[hit]] = True
                    edge_events.append(ev)
            nxt = pr.toggle[ev][c]
            no = nxt < 0
            if no.any():
                refused[idx[no]] = True
                cur[idx[no]] = -1
                idx, nxt = idx[~no], nxt[~no]
            cur[idx] = nxt
            bits[idx, z] = rising
            if not pr.atomic:
                middle_bad[idx] |= pr.illegal[nxt]
    return cur, refused, edge_bad, edge_events, middle_bad


def merge_events(arrays: list[np.ndarray], size: int, frontier: np.ndarray, by_events: bool) -> list[np.ndarray]:
    """(node index, state, events id, bits) with one row per (node index, state) -- and
    events, ``by_events`` (a Grafcet reacts to the events) --: the first row's events, the
    union of the rows' bits; in the search's order (by the node's aux, the events, the node)."""
    fi, post, seq, mask = arrays
    order = np.lexsort((np.arange(fi.size), seq if by_events else np.zeros_like(seq), post, fi))
    same = (fi[order][1:] == fi[order][:-1]) & (post[order][1:] == post[order][:-1])
    if by_events:
        same &= seq[order][1:] == seq[order][:-1]
    starts = np.flatnonzero(np.concatenate(([True], ~same)))
    first = order[starts]
    fi, post, seq, mask = fi[first], post[first], seq[first], np.bitwise_or.reduceat(mask[order], starts)
    again = np.lexsort((fi, seq, frontier[fi] // size))
    return [fi[again], post[again], seq[again], mask[again]]
