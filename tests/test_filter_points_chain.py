"""The chain at a point asks again only the criteria reading a variable that changed since
the last point (``Points.chain``): checked against a fresh ``Points``, whose first chain
asks every criterion, at points changing a few variables at a time, as the witnesses do."""

from __future__ import annotations

import random
import sys

from synth.filter.language import Sense
from synth.filter.language_check import parse_filter
from synth.filter.model import functions
from synth.filter.narrowing import layout
from synth.filter.points import Points
from synth.filter.solve import criteria

from conftest import ROOT


def test_the_chain_at_a_point_is_the_one_computed_afresh():
    sys.path.insert(0, str(ROOT / "bench"))
    from filter_scale import grid_edges_filter

    m = functions(parse_filter(grid_edges_filter(16), "g.filter"))
    e = m.engine
    goods = [e.expr(c.expr) if c.sense is Sense.MAX else ~e.expr(c.expr) for c in criteria(m.filter)]
    p = layout(m, goods)
    kept = Points(p, goods)
    rng = random.Random(7)
    point = {v: rng.random() < 0.5 for v in kept.others}
    seen = set()
    for step in range(40):
        for v in rng.sample(kept.others, 1 + step % 4):  # a few variables flipped, as a witness does
            point[v] = not point[v]
        mine, fresh = kept.chain(point), Points(p, goods).chain(point)
        assert mine == fresh, step
        seen.add(tuple(mine[1]))
    assert len(seen) == 12  # the criteria finding a solution there differ from point to point
