"""`synth filter verify --engine symbolic` (issue 23, build 2): the closed loop under any
control on BDDs gives the explicit engine's report exactly (counts, cycles, findings,
shortest traces) on the bundled filters; what it refuses; ``--engine auto``; rings of
cylinders (bench/verify_scale.py): both engines equal on small ones, the explicit one
without arrays over a grid of 24^6 states (issue 37)."""

from __future__ import annotations

import dataclasses
import json
import re
import sys

import pytest

from conftest import ROOT
from schemas import assert_valid
from synth.engines import EngineChoice
from synth.filter.loop.verify import verify
from synth.filter.cycle import Algorithm, Mode
from synth.filter.from_rules import skeleton
from synth.filter.language_check import load_filter, parse_filter
from synth.filter.loop.symbolic.verify import verify_symbolic
from synth.filter.loop.verification import FindingKind
from synth.plant.composition import load_plant

DATA = ROOT / "tests" / "data" / "filter"
FOUR = ROOT / "plants" / "four_cylinders.filter"
FOUR_RULES = ROOT / "plants" / "four_cylinders.rules"
sys.path.insert(0, str(ROOT / "bench"))
from verify_scale import ring_filter, ring_rules  # noqa: E402


def _same(f, rules: str, **kw) -> None:
    """Both engines, the same verification (but the seconds and the engine's name)."""
    a = verify(f, rules, any_control=True, **kw)
    b = verify_symbolic(f, load_plant(rules), **kw)
    assert b.engine is EngineChoice.SYMBOLIC and a.engine is EngineChoice.EXPLICIT
    assert dataclasses.replace(a, seconds=0) == dataclasses.replace(b, seconds=0, engine=a.engine)


@pytest.mark.parametrize("name, rules, kw", [
    ("two_no_edge.filter", "two.rules", {}),
    ("two_no_edge.filter", "two.rules", {"atomic": True}),
    ("two_no_edge.filter", "two.rules", {"mode": Mode.BLOCKING, "events_per_cycle": 2}),
    ("two_no_edge.filter", "two.rules", {"require_sup": True, "strict": True}),
    ("two_assume.filter", "two.rules", {}),
    ("two_assume.filter", "two.rules", {"mode": Mode.BLOCKING}),
    ("two_assume.filter", "two.rules", {"events_per_cycle": 0}),
    ("three_cycle.filter", "three.rules", {}),
    ("three_cycle.filter", "three.rules", {"algorithm": Algorithm.LOOP}),  # falls back
])
def test_same_verification_as_the_explicit_engine(name, rules, kw):
    _same(load_filter(DATA / name), str(DATA / rules), **kw)


def test_same_verification_on_tri(tmp_path):
    out = tmp_path / "F.filter"
    f = skeleton(ROOT / "plants" / "tri.rules", out).filter
    _same(f, str(ROOT / "plants" / "tri.rules"))  # 12996 states, a transient finding


def _report(out: str) -> list[str]:
    return [re.sub(r" in [0-9.]+ s", "", line) for line in out.splitlines()]


@pytest.mark.nightly  # 4 s: the explicit engine
@pytest.mark.parametrize("args", [
    ("--events-per-cycle", "2"),
    ("--algorithm", "loop"),
])
def test_four_cylinders_same_text(cli, args):
    _, explicit, _ = cli("filter", "verify", FOUR, "--plant", FOUR_RULES, "--any-control", *args, "--engine",
                         "explicit")
    code, symbolic, err = cli("filter", "verify", FOUR, "--plant", FOUR_RULES, "--any-control", *args, "--engine",
                              "symbolic")
    assert (code, err) == (0, "")
    assert _report(symbolic) == _report(explicit)
    assert "explored 2160 states (1584 plant states), " + (
        "33896 cycles" if args[0] == "--events-per-cycle" else "16376 cycles") in _report(symbolic)


SAFE = [  # tests/test_four_cylinders.py: pallets, events per cycle, states, plant states, cycles
    (1, 1, 2160, 1584, 16376), (1, 2, 2160, 1584, 33896), (2, 2, 810, 506, 6294), (3, 1, 60, 44, 140),
    (4, 2, 1, 1, 1)]


@pytest.mark.parametrize("pallets, k, states, plant_states, cycles", SAFE)
def test_four_cylinders_pinned_counts(cli, pallets, k, states, plant_states, cycles):
    rules = FOUR_RULES if pallets == 1 else ROOT / "plants" / f"four_cylinders_{pallets}.rules"
    code, out, err = cli("filter", "verify", FOUR, "--plant", rules, "--any-control", "--events-per-cycle", k,
                         "--engine", "symbolic")
    assert (code, err) == (0, "")
    assert _report(out)[1:] == [
        *([f"up to {k} plant events between two scans"] if k != 1 else []),
        f"explored {states} states ({plant_states} plant states), {cycles} cycles",
        "safe: no constraint is violated once the outputs are written",
        "outside SUP: 0 explored plant states can reach a violation by uncontrollable events alone",
        "coherent: Y never leaves the care set"]


@pytest.mark.nightly  # 4 s (the explicit engine: 15 s)
def test_four_cylinders_three_events_unsafe_with_the_explicit_trace(cli):
    code, out, _ = cli("filter", "verify", FOUR, "--plant", FOUR_RULES, "--any-control", "--events-per-cycle", "3",
                       "--engine", "symbolic")
    assert code == 1
    lines = _report(out)
    assert lines[1:4] == ["up to 3 plant events between two scans", "explored 21660 states (6912 plant states), 767224 cycles",
                          "unsafe: a plant state violates a constraint once the outputs are written "
                          "(1608 plant states): K2"]
    start = lines.index("shortest trace (a plant state violates a constraint once the outputs are written):")
    assert lines[start + 1:start + 5] == [
        "0  initial        {b1,b2,b3,b4,i1}",
        "1  -              {b1,b2,b3,b4,i1,Q1}  requests: Q1  orders: Q1",
        "2  ↓b1, ↑t2, ↓i1  {b2,b3,b4,t2,Q1,Q2}  requests: Q2  orders: Q1, Q2   requests violate CSs1_6",
        "3  ↓b2            {b3,b4,t2,Q1,Q2}     requests: Q2  orders: Q1, Q2   requests violate CSs1_6"]


def test_unsafe_text_and_json_identical(cli):
    args = ("filter", "verify", DATA / "two_assume.filter", "--plant", DATA / "two.rules", "--any-control")
    e_code, e_out, _ = cli(*args, "--engine", "explicit")
    s_code, s_out, _ = cli(*args, "--engine", "symbolic")
    assert e_code == s_code == 1 and _report(s_out) == _report(e_out)
    assert "shortest trace (an output event breaks an edge constraint):" in s_out
    _, e_json, _ = cli(*args, "--engine", "explicit", "--json")
    _, s_json, _ = cli(*args, "--engine", "symbolic", "--json")
    e, s = json.loads(e_json), json.loads(s_json)
    assert_valid("filter_verify", s)
    assert (e.pop("engine"), s.pop("engine")) == ("explicit", "symbolic")
    e.pop("seconds"), s.pop("seconds")
    assert e == s


def test_what_the_symbolic_engine_refuses(cli):
    base = ("filter", "verify", DATA / "two_no_edge.filter", "--plant", DATA / "two.rules")
    code, _, err = cli(*base, "--grafcet", DATA / "two.g7", "--engine", "symbolic")
    assert code == 2 and "supports --any-control only" in err and "--engine explicit" in err
    code, _, err = cli(*base, "--any-control", "--progress", "A", "--engine", "symbolic")
    assert code == 2 and "(--progress need --engine explicit)" in err
    code, _, err = cli("filter", "verify", ROOT / "plants" / "tri.filter", "--plant", ROOT / "plants" / "tri.rules",
                       "--any-control", "--engine", "symbolic")  # the explicit engine's checks, the same message
    assert code == 2 and "the filter's input C0, C1" in err and "is not an input of the plant" in err
    code, out, _ = cli(*base, "--grafcet", DATA / "two.g7", "--json")  # auto: explicit there
    assert json.loads(out)["engine"] == "explicit"
    code, out, _ = cli(*base, "--any-control", "--json")  # auto: a small plant stays explicit
    assert json.loads(out)["engine"] == "explicit"


def test_max_states_on_the_symbolic_engine(cli):
    # the symbolic engine stops after the first level that passes N nodes (not at N exactly)
    code, out, err = cli("filter", "verify", FOUR, "--plant", FOUR_RULES, "--any-control", "--engine", "symbolic",
                         "--max-states", "100")
    assert code == 2 and "STOPPED at the state limit" in out
    assert re.match(r"explored (\d+) states", out.splitlines()[1])
    assert int(re.match(r"explored (\d+) states", out.splitlines()[1]).group(1)) > 100
    assert "--max-states 100" in err


def test_the_explicit_engine_holds_a_ring_of_6(tmp_path):
    # 6 cylinders, one pallet: a plant grid of 24^6 states; the explicit engine holds no
    # array over it (synth/filter/loop/columns.py) and explores until its state limit
    (tmp_path / "ring6.rules").write_text(ring_rules(6))
    f = parse_filter(ring_filter(6), str(tmp_path / "ring6.filter"))
    v = verify(f, str(tmp_path / "ring6.rules"), any_control=True, max_states=300)
    assert v.engine is EngineChoice.EXPLICIT and not v.complete and v.states == 300


@pytest.mark.parametrize("n, k", [(3, 1), (3, 2), (4, 1)])
def test_both_engines_agree_on_small_rings(tmp_path, n, k):
    # the differential of issue 37: the explicit engine (columns over state codes) and the
    # symbolic one (observers placed by their reads) on the bench's rings
    (tmp_path / "ring.rules").write_text(ring_rules(n))
    _same(parse_filter(ring_filter(n), str(tmp_path / "ring.filter")), str(tmp_path / "ring.rules"),
          events_per_cycle=k)


@pytest.mark.nightly  # 70 s
def test_the_explicit_engine_explores_a_ring_of_6(tmp_path):
    (tmp_path / "ring6.rules").write_text(ring_rules(6))
    f = parse_filter(ring_filter(6), str(tmp_path / "ring6.filter"))
    v = verify(f, str(tmp_path / "ring6.rules"), any_control=True)
    assert v.engine is EngineChoice.EXPLICIT
    assert (v.safe, v.coherent, v.complete, v.states, v.plant_states, v.cycles, v.outside_sup) == (
        True, True, True, 116640, 85536, 2277120, 0)


@pytest.mark.nightly  # 3 s (10 s on a loaded machine)
def test_auto_takes_the_symbolic_engine_on_a_ring_of_6(tmp_path):
    # the symbolic one (chosen by auto) explores the 116640 nodes of the closed loop
    (tmp_path / "ring6.rules").write_text(ring_rules(6))
    f = parse_filter(ring_filter(6), str(tmp_path / "ring6.filter"))
    rules = str(tmp_path / "ring6.rules")
    v = verify(f, rules, any_control=True, engine=EngineChoice.AUTO)
    assert v.engine is EngineChoice.SYMBOLIC
    assert (v.safe, v.coherent, v.complete, v.states, v.plant_states, v.cycles, v.outside_sup) == (
        True, True, True, 116640, 85536, 2277120, 0)


def test_the_ring_generator_gives_the_four_cylinders(tmp_path):
    # bench/verify_scale.py's ring of 4 is plants/four_cylinders.rules / .filter (the same counts)
    (tmp_path / "ring4.rules").write_text(ring_rules(4))
    v = verify_symbolic(parse_filter(ring_filter(4), str(tmp_path / "ring4.filter")),
                        load_plant(tmp_path / "ring4.rules"))
    assert (v.safe, v.states, v.plant_states, v.cycles) == (True, 2160, 1584, 16376)


# ---------------------------------------------------------------- the walk back (no explicit engine)

@pytest.mark.parametrize("name, rules, kw", [
    ("two_no_edge.filter", "two.rules", {"require_sup": True}),
    ("two_assume.filter", "two.rules", {"mode": Mode.BLOCKING}),
    ("three_cycle.filter", "three.rules", {"algorithm": Algorithm.LOOP}),
])
def test_walk_back_traces_are_shortest(name, rules, kw):
    # trace_budget=0: the explicit engine may not render the traces; the walk back gives
    # traces of the same length, the same constraints, the same finding noted last (the
    # requests, hence "requests violate ...", may be another shortest trace's)
    f = load_filter(DATA / name)
    shown = verify_symbolic(f, load_plant(DATA / rules), **kw)
    walked = verify_symbolic(f, load_plant(DATA / rules), trace_budget=0, **kw)
    assert list(walked.findings) == list(shown.findings) and walked.findings
    for k, a in shown.findings.items():
        b = walked.findings[k]
        last = (b.trace[-1].note.split("; ")[-1], b.trace[-1].ran)
        assert (b.count, b.constraints, len(b.trace), b.trace[0], last) == (
            a.count, a.constraints, len(a.trace), a.trace[0], (a.trace[-1].note.split("; ")[-1], a.trace[-1].ran))


def test_walk_back_edge_trace():
    # another shortest trace than the explicit engine's (↑s first, then the drop of A), a real one
    v = verify_symbolic(load_filter(DATA / "two_assume.filter"), load_plant(DATA / "two.rules"), trace_budget=0)
    assert [(r.event, r.state, r.requests, r.orders, r.note) for r in v.findings[FindingKind.EDGE].trace] == [
        ("initial", "{}", (), (), ""),
        ("-", "{A}", ("A",), ("A",), ""),
        ("↑s", "{s}", (), (), "requests violate K, E; output event forbidden")]


@pytest.mark.nightly  # 4 s
def test_walk_back_four_cylinders_three_events():
    v = verify_symbolic(load_filter(FOUR), load_plant(FOUR_RULES), events_per_cycle=3, trace_budget=0)
    rows = [(r.event, r.state, r.orders) for r in v.findings[FindingKind.VIOLATION].trace]
    assert rows == [("initial", "{b1,b2,b3,b4,i1}", ()), ("-", "{b1,b2,b3,b4,i1,Q1}", ("Q1",)),
                    ("↓b1, ↑t2, ↓i1", "{b2,b3,b4,t2,Q1,Q2}", ("Q1", "Q2")),
                    ("↓b2, ↑h2", "{b3,b4,h2,t2,Q1}", ("Q1",))]  # t2 & !b2: K2
    assert v.findings[FindingKind.VIOLATION].constraints == ("K2",)


@pytest.fixture
def held(tmp_path):
    # tri_annex.rules holds TAPIS = 1 (requested at 1; a filter dropping it is refused) and
    # the held.filter declares no other order (passed through: O = R, any R)
    annex = ROOT / "plants" / "tri_annex.rules"
    held = tmp_path / "held.filter"
    held.write_text(f'use "{annex.as_posix()}"\nsafety H "stop the conveyor on a small box": TAPIS & cp11\n')
    return held, annex


def test_held_and_passed_through_orders(held):  # 1 s (the explicit engine on tri_annex)
    _same(load_filter(held[0]), str(held[1]))


def test_held_order_refused_walk_back(held):
    held, annex = held
    walked = verify_symbolic(load_filter(held), load_plant(annex), trace_budget=0)
    assert walked.findings[FindingKind.REFUSED].count == 5184
    assert [(r.event, r.state, r.requests, r.orders, r.note) for r in walked.findings[FindingKind.REFUSED].trace] == [
        ("initial", "{v10,v20,v30,v40,TAPIS}", (), (), ""),
        ("↑cp11", "{v10,v20,v30,v40,cp11,TAPIS}", ("TAPIS",), (), "requests violate H; output change refused")]


def test_box_sorting_with_boxes_as_workpieces(cli, tmp_path):
    # plants/tri_boxes.rules: elements reading each other (the boxes read the cylinders);
    # the skeleton's counts are the explicit engine's (tests/test_tri_boxes.py, nightly there)
    boxes = ROOT / "plants" / "tri_boxes.rules"
    f = tmp_path / "F.filter"
    f.write_text(skeleton(boxes, f).text)
    code, out, _ = cli("filter", "verify", f, "--plant", boxes, "--any-control", "--engine", "symbolic")
    assert code == 0
    assert _report(out)[1:6] == [
        "explored 46692 states (46692 plant states), 9511968 cycles",
        "safe: no constraint is violated once the outputs are written",
        "transient: 5904 plant states violate a constraint between the plant's event and the end of the write (C2_5)",
        "outside SUP: 7932 explored plant states can reach a violation by uncontrollable events alone",
        "coherent: Y never leaves the care set"]
