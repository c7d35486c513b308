"""The filter at scale (issue 25): the BDD variable order from the constraint graph, the
incremental "no effect" analysis, flat equations only on request, independent clusters
and ``filter st --split``. Timings live in bench/filter_scale.py and docs/performance.md."""

from __future__ import annotations

import json
import random
import sys
from typing import Any, Sequence

import pytest

from conftest import ROOT
from synth.codegen.filter_st import FilterBlock, filter_block, split_blocks
from synth.codegen.interpreter.machine import load_st
from synth.filter.clusters import clusters, solve_clusters
from synth.filter.language_check import load_filter, parse_filter
from synth.filter.language_reader import filter_expression
from synth.filter.model import bdd_order, variable_order
from synth.filter.solve import criteria, synthesis
from synth.filter.language import Filter, Sense

sys.path.insert(0, str(ROOT / "bench"))
from filter_scale import chain_filter, grid_edges_filter, grid_filter, ring_filter  # noqa: E402

PLANTS = sorted((ROOT / "plants").glob("*.filter"))
# a ring of 3 cylinders, a chain of 3 outputs and one lone output: three clusters
MIXED = ring_filter(3).replace("outputs Q1, Q2, Q3", "outputs Q1, Q2, Q3, o1, o2, o3, L\ninputs e") + (
    chain_filter(3).split("\n", 2)[2].replace("safety K", "safety C") + "safety SL: L & e\n")


def test_each_output_sits_with_its_constraints() -> None:
    f = parse_filter(ring_filter(6), "ring.filter")
    order = bdd_order(f)
    assert sorted(order) == sorted(set(variable_order(f)) | set(order))
    for k in range(1, 7):  # R_Qk, its sensors and Qk^-1 just before Qk; the text order keeps outputs last
        assert order.index(f"Q{k}") - order.index(f"R_Q{k}") <= 7
    assert variable_order(f)[-6:] == [f"Q{k}" for k in range(1, 7)]
    chain = bdd_order(parse_filter(chain_filter(5), "chain.filter"))
    assert chain == [n for k in range(1, 6) for n in (f"R_o{k}", f"o{k}^-1", f"o{k}")]


def _naive_effects(f):
    """The quadratic definition: every narrowing criterion re-solved without it."""
    s = synthesis(f)
    m = s.functions
    e, outs = m.engine, m.outputs
    steps = [(c, e.expr(c.expr)) for c in criteria(f)]

    def narrowed(a, c, u):
        best = e.exists(outs, a & u) if c.sense is Sense.MAX else e.forall(outs, ~a | u)
        return a & u.equiv(best)

    states = [m.assumed & ~m.forbidden]
    for c, u in steps:
        states.append(narrowed(states[-1], c, u))
    out = []
    for i in range(len(steps)):
        without = states[i]
        for c, u in steps[i + 1:]:
            without = narrowed(without, c, u)
        out.append((states[i + 1] != states[i], states[i + 1] != states[i] and without != states[-1]))
    return out, s


@pytest.mark.parametrize("text", [ring_filter(3), chain_filter(6), grid_filter(8), MIXED] +
                         [p.read_text() for p in PLANTS], ids=["ring3", "chain6", "grid8", "mixed"] + [p.stem for p in PLANTS])
def test_incremental_effects_are_the_quadratic_ones(text: str) -> None:
    want, s = _naive_effects(parse_filter(text, "x.filter"))
    assert [(a.narrows, a.effect) for a in s.applied] == want


def test_flat_only_on_request_and_limited(cli, tmp_path, monkeypatch) -> None:
    path = tmp_path / "ring.filter"
    path.write_text(ring_filter(4))
    s = synthesis(load_filter(str(path)))
    assert s.flat_omitted == ("Q4",)  # wider than the probe (64 cubes): not written
    assert set(s.chained) == {"Q1", "Q2", "Q3", "Q4"}
    code, out, err = cli("filter", "solve", path, "--json")
    data = json.loads(out)
    assert code == 0 and list(data["equations"]) == ["Q1", "Q2", "Q3"] and data["flat_omitted"] == ["Q4"]
    assert data["clusters"] == [["Q1", "Q2", "Q3", "Q4"]] and data["variable_order"][:2] == ["R_Q1", "b1"]
    code, out, err = cli("filter", "solve", path, "--flat")
    flat = synthesis(load_filter(str(path)), flat=True)
    assert code == 0 and out.splitlines() == [f"equation {o} = {t}" for o, t in flat.equations.items()]
    assert "note: BDD variable order: R_Q1, b1" in err
    import synth.filter.solve as solve

    monkeypatch.setattr(solve, "FLAT_LIMIT", 10)
    code, out, err = cli("filter", "solve", path, "--flat")
    assert (code, out) == (2, "")
    assert err == (f"stopped: {path}: the flat equation of Q1 needs more than 10 terms; the chained equations "
                   "(solve without --flat) are the filter\n")


def _composed(text: str):
    """Each cluster's chained equations, substituted in the whole filter's manager."""
    f = parse_filter(text, "x.filter")
    whole = synthesis(f)
    e = whole.functions.engine
    done: dict = {}
    for s in solve_clusters(f):
        for o, t in s.chained.items():
            done[o] = e.let(done, e.expr(filter_expression(t, o)))
    return f, whole, done


@pytest.mark.parametrize("text", [MIXED, ring_filter(4), grid_filter(16)] + [p.read_text() for p in PLANTS],
                         ids=["mixed", "ring4", "grid16"] + [p.stem for p in PLANTS])
def test_clusters_compose_to_the_whole_filter(text: str) -> None:
    f, whole, composed = _composed(text)
    assert sorted(o for g in clusters(f) for o in g) == sorted(f.outputs)
    e = whole.functions.engine
    for o in whole.outputs:  # equal on the whole filter's care set
        assert (~composed[o].equiv(whole.output(o)) & whole.care) == e.false, o


def assert_split_runs_as_whole(f: Filter, blocks: Sequence[FilterBlock], parts: Sequence[Any], seed: int) -> None:
    """Drive each split block (``parts``: a running instance per block, with ``cycle`` and
    ``[output]``) on its own inputs and the whole filter's block on all of them, 300 random
    cycles: the outputs agree at every cycle (the ring's assumptions are on past outputs:
    the runs stay in the care set)."""
    whole_block = filter_block(f)
    whole = load_st(whole_block.text, "whole.st").instance(whole_block.name)
    rnd = random.Random(seed)
    for n in range(300):
        values = {x: rnd.random() < 0.5 for x in whole_block.inputs}
        whole.cycle(values)
        for b, fb in zip(blocks, parts):
            fb.cycle({x: values[x] for x in b.inputs})
        got = {o: fb[o] for b, fb in zip(blocks, parts) for o in b.outputs}
        assert got == {o: whole[o] for o in f.outputs}, f"cycle {n}"


def test_mixed_has_three_clusters_and_split_blocks_run_as_the_whole(cli, tmp_path) -> None:
    f = parse_filter(MIXED, "mixed.filter")
    assert clusters(f) == (("Q1", "Q2", "Q3"), ("o1", "o2", "o3"), ("L",))
    blocks = split_blocks(f)
    assert [b.name for b in blocks] == ["FB_mixed_1_Filter", "FB_mixed_2_Filter", "FB_mixed_3_Filter"]
    assert blocks[2].inputs == ("R_L", "e")
    assert_split_runs_as_whole(f, blocks, [load_st(b.text, f"{b.name}.st").instance(b.name) for b in blocks], 3)
    path = tmp_path / "mixed.filter"
    path.write_text(MIXED)
    code, out, _ = cli("filter", "st", path, "--split")
    assert code == 0 and out.count("END_FUNCTION_BLOCK") == 3
    code, out, _ = cli("filter", "st", path, "--split", "--algorithm", "loop")
    assert code == 0 and out.count("END_FUNCTION_BLOCK") == 3 and "FB_mixed_3_Filter" in out


def test_grid_edges_equations_are_the_brute_force_narrowing() -> None:
    """The grid_edges family (edges on the end sensors, priorities both ways) at 2 stations × 3
    cylinders: the printed chained equations, evaluated in order, give at 2 000 seeded random
    points of the truth table the one output vector that the chain of narrowings leaves when
    run by enumeration of the 64 output vectors (each criterion keeps the vectors that satisfy
    it where some do)."""
    import numpy as np

    from synth.logic.expr import Edge, evaluate, names
    from synth.logic.past import pre_name

    f = parse_filter(grid_edges_filter(6, stations=2), "ge.filter")
    s = synthesis(f)
    assert s.functional and s.consistent and list(s.chained) != []
    steps = criteria(f)
    read: set[str] = set()
    for e in [k.expr for k in f.safeties] + [c.expr for c in steps]:
        for v in names(e):
            read |= {v.name, pre_name(v.name)} if isinstance(v, Edge) else {v.name}
    ys = sorted(read - set(f.outputs))
    points, vectors = 2000, 2 ** len(f.outputs)
    rng = np.random.default_rng(37)
    rows = {y: np.repeat(rng.random(points) < 0.5, vectors) for y in ys}
    for k, o in enumerate(f.outputs):
        rows[o] = np.tile((np.arange(vectors) >> k) & 1 == 1, points)

    def value(e, at: dict, n: int):
        def edge(x: Edge):
            now, before = at[x.name], at[pre_name(x.name)]
            return ~before & now if x.rising else before & ~now
        return np.broadcast_to(np.asarray(evaluate(e, at.__getitem__, edge)), (n,))

    alive = np.ones((points, vectors), dtype=bool)
    for k in f.safeties:
        alive &= ~value(k.expr, rows, points * vectors).reshape(points, vectors)
    for c in steps:
        good = value(c.expr, rows, points * vectors).reshape(points, vectors)
        good = good if c.sense is Sense.MAX else ~good
        kept = alive & good
        alive = np.where(kept.any(axis=1, keepdims=True), kept, alive)
    assert (alive.sum(axis=1) == 1).all()  # functional at every point
    chosen = alive.argmax(axis=1)
    at = {y: rows[y][::vectors] for y in ys}
    for o, text in s.chained.items():
        at[o] = value(filter_expression(text, "eq"), at, points)
        k = f.outputs.index(o)
        assert (at[o] == ((chosen >> k) & 1 == 1)).all(), o
