"""SUP's questions about one state (:class:`~synth.sup.constraints.CompiledConstraints`:
kept, threatened, forbidding, move, moves), read from bit masks per element and local
state, against the terms' factors read one by one (the former writing)."""

from __future__ import annotations

import random

from synth.plant.composition import plant
from synth.plant.rules_check import load_rules, parse_rules
from synth.sup.constraints import CompiledConstraints

from conftest import ROOT
from randrules import random_rules


def _ids(pairs, local):
    ids = []
    for term, factors in pairs:
        if term.constraint not in ids and all(vec[local[a]] for a, vec in factors):
            ids.append(term.constraint)
    return ids


def _plain_move(cc, t, local):
    target = list(local)
    target[t.axis] = t.dst
    why = _ids(((e, e.factors) for e in cc.edge_terms.get(t.event, ())), local) if t.controllable else []
    why += [c for c in _ids(zip(cc.level_terms, cc.level_reach), tuple(target)) if c not in why]
    return not why, why


def _rule_sets():
    yield "tri", load_rules(ROOT / "plants" / "tri.rules")
    yield "tri_annex", load_rules(ROOT / "plants" / "tri_annex.rules")
    for seed in range(40):
        yield f"random{seed}", parse_rules(random_rules(seed), f"random{seed}.rules")


def test_masks_answer_as_the_factors():
    asked = refused = forbidden = 0
    for name, rs in _rule_sets():
        p = plant(rs)
        if p.reads:  # the exact grids answer there, unchanged
            continue
        cc = CompiledConstraints(p, rs.constraints)
        rng = random.Random(name)
        for _ in range(min(p.size, 300)):
            local = p.local(rng.randrange(p.size))
            threatened = _ids(zip(cc.level_terms, cc.level_reach), local)
            assert cc.threatened(local) == threatened, name
            assert cc.kept(local) == (not threatened), name
            for event, terms in cc.edge_terms.items():
                assert cc.forbidding(event, local) == _ids(((e, e.factors) for e in terms), local), name
            ts = [t for t in p.transitions if t.src == local[t.axis]]
            rng.shuffle(ts)
            expected = [_plain_move(cc, t, local) for t in ts]
            assert cc.verdicts(ts, local) == expected, name
            assert [cc.move(t, local) for t in ts] == expected, name
            asked += len(ts)
            refused += sum(not ok for ok, _ in expected)
            forbidden += sum(bool(cc.forbidding(t.event, local)) for t in ts if t.controllable)
    assert asked > 10_000 and refused > 1_000 and forbidden > 100, (asked, refused, forbidden)
