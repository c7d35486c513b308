"""The parts of `synth filter verify` after the split of closed_loop (issue 20): the
product's grids come from sup.Supervisor and agree with the per-state closed forms of
CompiledConstraints; the finding kinds print as before; the filter computes and the
output layer prints (from-rules writes nothing, check and run are one call each)."""

from __future__ import annotations

import json
import sys

import numpy as np

from conftest import ROOT
from synth.filter.coherence import check
from synth.filter.cycle import Algorithm, Mode
from synth.filter.from_rules import Classification, skeleton
from synth.filter.language_check import load_filter
from synth.filter.loop.product import Product
from synth.filter.run import run_trace
from synth.filter.loop.verification import FindingKind
from synth.logic.events import Event
from synth.output.filter_text import FINDINGS, check_text, run_json, skeleton_text, verification_json
from synth.plant.composition import load_plant, plant
from synth.plant.rules_check import load_rules
from synth.sup.constraints import CompiledConstraints

sys.path.insert(0, str(ROOT / "bench"))
from verify_scale import ring_rules  # noqa: E402

DATA = ROOT / "tests" / "data" / "filter"
TRI = ROOT / "plants" / "tri.rules"


def _product(rules, tmp_path, grafcet=None):
    sk = skeleton(rules, tmp_path / "F.filter")
    return Product(sk.filter, load_plant(rules), grafcet, Algorithm.ALGEBRAIC, Mode.SUPERVISOR, False)


def test_columns_agree_with_the_supervisor_state_by_state(tmp_path):
    """illegal, outside SUP and the forbidden edges of every state, computed by the
    product's columns for the codes asked (all of them at once, and one by one), equal the
    Supervisor's grids and CompiledConstraints' answers for that one state."""
    from synth.sup.supervisor import Supervisor

    seen = set()
    ring = tmp_path / "ring3.rules"  # cells that read the cylinders
    ring.write_text(ring_rules(3))
    for rules in (DATA / "two.rules", TRI, ring):
        pr = _product(rules, tmp_path)
        rs = load_rules(rules)
        cc = CompiledConstraints(plant(rs), rs.constraints)
        sup = Supervisor(pr.plant, rs.constraints)
        codes = np.arange(pr.size, dtype=np.int64)
        illegal, outside = pr.illegal[codes], pr.outside_sup[codes]
        assert (illegal == sup.illegal.ravel()).all() and (outside == sup.removed.ravel()).all(), rules
        assert set(pr.forbid) == set(sup.forbid), rules
        for ev, col in pr.forbid.items():
            assert (col[codes] == sup.forbid[ev].ravel()).all(), (rules, ev)
        seen |= {"edge"} if pr.forbid else set()
        seen |= {"weakly"} if (outside & ~illegal).any() else set()
        seen |= {"reads"} if pr.plant.reads and (outside & ~illegal).any() else set()  # the forward search
        for code in codes.tolist()[:: max(1, pr.size // 300)]:
            local = pr.plant.local(code)
            assert bool(pr.illegal[code]) == bool(cc.violated(local)), (rules, code)
            assert pr.violated(code) == tuple(cc.violated(local)), (rules, code)
            assert pr.columns.threatened(code) == tuple(cc.threatened(local)), (rules, code)
            for ev in pr.forbid:
                assert pr.columns.forbidding(ev, code) == tuple(cc.forbidding(ev, local)), (rules, code, ev)
        # every event's successor column equals the plant's transitions
        dense: dict[str, np.ndarray] = {}
        for t, src, dst in pr.plant.transition_arrays():
            dense.setdefault(t.event, np.full(pr.size, -1, dtype=np.int64))[src] = dst
        moves = dict(pr.moves(codes))
        assert list(moves) == list(pr.uncontrollable) == [e for e in dense if e not in pr.toggle], rules
        for ev, col in pr.toggle.items():
            assert (col[codes] == dense.get(ev, -1)).all(), (rules, ev)
        for ev, succ in moves.items():
            assert (succ == dense[ev]).all(), (rules, ev)
    assert seen == {"edge", "weakly", "reads"}  # not vacuous
    # every order has both edges in the toggle table (-1 where the plant has no such move)
    assert all(Event.edge(z, r) in pr.toggle for z in pr.orders for r in (False, True))


def test_outside_sup_asked_level_by_level_equals_asked_at_once(tmp_path):
    """The searches of outside SUP stop at the states decided by the searches before: asked
    in shuffled pieces (as the levels ask), every answer equals the one asked at once."""
    ring = tmp_path / "ring3.rules"  # cells that read the cylinders: the forward search, not the closed form
    ring.write_text(ring_rules(3))
    whole = _product(ring, tmp_path)
    codes = np.arange(whole.size, dtype=np.int64)
    expected = whole.outside_sup[codes]
    assert (expected & ~whole.illegal[codes]).any() and whole.plant.reads  # weakly outside states: not vacuous
    pieces = _product(ring, tmp_path)
    order = np.random.default_rng(5).permutation(codes)
    for chunk in np.array_split(order, 40):
        assert (pieces.outside_sup[chunk] == expected[chunk]).all()
    assert pieces.outside_sup[int(order[0])] == expected[order[0]]  # one code, decided before


def test_moves_by_element_tables_equal_moves_event_by_event(tmp_path, monkeypatch):
    """An element's uncontrollable events side by side in one table (guards read from the
    other elements) give the successors of looking each event's sources up alone."""
    from synth.filter.loop import columns

    ring = tmp_path / "ring3.rules"
    ring.write_text(ring_rules(3))
    tabled = _product(ring, tmp_path)
    monkeypatch.setattr(columns, "TABLE_ENTRIES", 0)
    alone = _product(ring, tmp_path)
    kinds = [sum(isinstance(t, columns.Table) for t in pr.columns.tables) for pr in (tabled, alone)]
    assert kinds[0] >= 6 and kinds[1] == 0 and any(t.guard is not None for t in tabled.columns.tables
                                                   if isinstance(t, columns.Table))
    codes = np.random.default_rng(2).permutation(tabled.size)[:5000]
    got, want = list(tabled.moves(codes)), list(alone.moves(codes))
    assert [e for e, _ in got] == [e for e, _ in want] == list(tabled.uncontrollable)
    for (e, a), (_, b) in zip(got, want):
        assert (a == b).all() and (a >= 0).any(), e


def test_classes_found_a_few_at_a_time_give_the_same_verification(tmp_path, monkeypatch):
    """The outcomes of a level's new classes, found by batches of any size, number the
    classes, outcomes and memories alike: the same counts, findings and traces."""
    from synth.filter.loop import explorer
    from synth.filter.loop.verify import verify

    cases = ((ROOT / "plants" / "four_cylinders.filter", ROOT / "plants" / "four_cylinders.rules"),
             (DATA / "two_no_edge.filter", DATA / "two.rules"))

    def run() -> list[dict]:
        return [{k: x for k, x in verification_json(verify(load_filter(f), str(r), any_control=True)).items()
                 if k != "seconds"} for f, r in cases]

    whole = run()
    monkeypatch.setattr(explorer, "CLASS_BATCH", 3)
    assert run() == whole
    assert whole[0]["states"] == 2160 and whole[1]["findings"]  # many classes; traces through the outcomes


def test_distinct_lanes_equal_first_lanes_row_by_row():
    from synth.filter.loop.outcomes import distinct_lanes, first_lanes

    rng = np.random.default_rng(11)
    for count, m in ((1, 3), (8, 5), (64, 12), (100, 7), (32, 63)):
        rows = [[int(x) for x in rng.integers(0, 4, size=m)] if r % 3 == 0 else
                [int.from_bytes(rng.bytes((count + 7) // 8), "little") & ((1 << count) - 1) for _ in range(m)]
                for r in range(30)]
        got = distinct_lanes(rows, count)
        assert [lanes for lanes, _ in got] == [first_lanes(r, count) for r in rows], (count, m)
        for r, (lanes, keys) in zip(rows, got):
            want = None if m >= 63 else [sum(((x >> j) & 1) << i for i, x in enumerate(r)) for j in lanes]
            assert keys == want, (count, m)


def test_finding_kinds_print_as_before():
    assert [str(k) for k in FindingKind] == ["violation", "edge", "refused", "fallback", "outside_care",
                                             "transient", "outside_sup"]
    assert set(FINDINGS) == set(FindingKind)


def test_verification_json_keys_are_plain_strings(tmp_path):
    from synth.filter.loop.verify import verify

    out = tmp_path / "F.filter"
    sk = skeleton(DATA / "two.rules", out)
    v = verify(sk.filter, str(DATA / "two.rules"), any_control=True, require_sup=True)
    data = json.loads(json.dumps(verification_json(v)))
    assert list(data["findings"]) == [str(k) for k in v.findings] and v.findings


def test_from_rules_classification_and_text(tmp_path):
    out = tmp_path / "F.filter"
    sk = skeleton(TRI, out)
    assert not out.exists()  # the filter computes; the CLI writes
    assert {c.kind for c in sk.constraints} == {Classification.SIMPLE, Classification.COMBINED}
    assert skeleton_text(sk).splitlines()[:3] == ["C2_1: CSc (no priority) on AVANCER1, RECULER1",
                                                  "C2_2: CSc (no priority) on AVANCER2, RECULER2",
                                                  "C2_3: CSs on AVANCER3"]


def test_check_and_run_are_one_call_each(cli):
    tri = ROOT / "plants" / "tri.filter"
    c = check(load_filter(tri))
    code, text, _ = cli("filter", "check", tri)
    assert (code, text) == (0 if c.holds else 1, check_text(c))
    loop_c = ROOT / "plants" / "loop_c.filter"
    r = run_trace(load_filter(loop_c), str(DATA / "loop_c.csv"), Algorithm.LOOP)
    code, text, _ = cli("filter", "run", loop_c, "--trace", DATA / "loop_c.csv", "--algorithm", "loop", "--json")
    assert code == (0 if r.coherent else 1)
    assert json.loads(text) == json.loads(json.dumps(run_json(str(loop_c), r)))
