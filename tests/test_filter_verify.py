"""`synth filter verify`: the closed loop of docs/filter.md — the done-when of issue 11
(from-rules on plants/tri.rules, then verify --any-control), a filter with a constraint
dropped and its exact shortest trace, edge constraints, ordered vs atomic writes,
fallback and care-set findings, a Grafcet as the request source, and the vectorised
exploration against a plain breadth-first oracle written here."""

from __future__ import annotations

import dataclasses
import json
from collections import deque
from itertools import product

import pytest

from conftest import ROOT
from schemas import assert_valid
from synth.errors import InputError
from synth.filter.loop.verify import verify
from synth.filter.cycle import Algorithm, FilterCycle, Mode
from synth.filter.from_rules import skeleton
from synth.filter.language_check import load_filter, parse_filter
from synth.logic.events import Event
from synth.output.filter_text import trace_text
from synth.plant.composition import plant
from synth.plant.rules_check import load_rules
from synth.sup.constraints import CompiledConstraints

DATA = ROOT / "tests" / "data" / "filter"
TRI = ROOT / "plants" / "tri.rules"


@pytest.fixture(scope="module")
def tri_filter(tmp_path_factory):
    out = tmp_path_factory.mktemp("tri") / "F.filter"
    out.write_text(skeleton(TRI, out).text)
    return out


def _rows(finding):
    return [(r.event, r.state, r.requests, r.orders, r.note) for r in finding.trace]


def test_done_when_tri_any_control(cli, tri_filter):
    """Issue 11: from-rules plants/tri.rules, then verify --any-control: no state violating a
    constraint once the outputs are written. The transient states (a sensor rises under an
    order the filter removes at the next cycle, e.g. cp11 under AVANCER2) are counted."""
    v = verify(load_filter(tri_filter), str(TRI), any_control=True)
    assert (v.safe, v.coherent, v.complete) == (True, True, True)
    assert (v.states, v.plant_states, v.cycles, v.outside_sup) == (12996, 12996, 2357952, 3816)
    assert set(v.findings) == {"transient"}
    t = v.findings["transient"]
    assert (t.count, t.constraints) == (4392, ("C2_5",))
    assert _rows(t) == [
        ("initial", "{v10,v20,v30,v40}", (), (), ""),
        ("-", "{v10,v20,v30,v40,TAPIS,AVANCER2}", ("TAPIS", "AVANCER2"), ("TAPIS", "AVANCER2"), ""),
        ("↑cp11", "{v10,v20,v30,v40,cp11,TAPIS,AVANCER2}", (), (), "before the PLC writes"),
    ]
    code, out, err = cli("filter", "verify", tri_filter, "--plant", TRI, "--any-control")
    assert code == 0
    assert "safe: no constraint is violated once the outputs are written" in out
    assert out.splitlines()[1].startswith("explored 12996 states (12996 plant states), 2357952 cycles in ")
    assert not dataclasses.replace(v, strict=True).safe  # --strict: the transients count


def test_dropped_constraint_is_found(cli, tri_filter, tmp_path):
    """The skeleton without C2_6 (AVANCER3 & AVANCER1): one cycle from the initial state."""
    unsafe = tmp_path / "unsafe.filter"
    text = skeleton(TRI, unsafe).text
    unsafe.write_text("".join(line for line in text.splitlines(True) if "C2_6" not in line))
    code, out, _ = cli("filter", "verify", unsafe, "--plant", TRI, "--any-control", "--json")
    data = json.loads(out)
    assert_valid("filter_verify", data)
    assert (code, data["safe"], data["coherent"]) == (1, False, True)
    found = data["findings"]["violation"]
    assert (found["constraints"], found["count"]) == (["C2_6"], 1152)
    assert [(r["event"], r["state"], r["requests"], r["orders"], r["note"], r["plc_ran"]) for r in found["trace"]] == [
        ("initial", "{v10,v20,v30,v40}", [], [], "", True),
        ("-", "{v10,v20,v30,v40,AVANCER1,AVANCER3}", ["AVANCER1", "AVANCER3"], ["AVANCER1", "AVANCER3"], "", True),
    ]


def test_require_sup(cli, tmp_path):
    """--require-sup: a node from which uncontrollable events alone reach a violation fails.
    On two.rules, {s} is reached before any write, and from {} the plant can make ↑s."""
    out = tmp_path / "two.filter"
    out.write_text(skeleton(DATA / "two.rules", out).text)
    v = verify(load_filter(out), str(DATA / "two.rules"), any_control=True, require_sup=True)
    assert (v.safe, v.outside_sup) == (False, 1)
    found = v.findings["outside_sup"]
    assert (found.constraints, found.count) == (("K",), 1)
    assert trace_text(found.trace).splitlines() == [
        "0  initial  {}   outside SUP: uncontrollable events can lead to K"]
    code, text, _ = cli("filter", "verify", out, "--plant", DATA / "two.rules", "--any-control", "--require-sup",
                        "--json")
    data = json.loads(text)
    assert_valid("filter_verify", data)
    assert code == 1 and data["findings"]["outside_sup"]["count"] == 1


def test_edge_constraint_and_trace_text():
    v = verify(load_filter(DATA / "two_no_edge.filter"), str(DATA / "two.rules"), any_control=True)
    assert not v.safe and set(v.findings) == {"edge", "transient"}
    edge = v.findings["edge"]
    assert (edge.constraints, edge.count) == (("E",), 2)
    assert trace_text(edge.trace).splitlines() == [
        "0  initial  {}",
        "1  ↑s       {s,A}  requests: A  orders: A",
        "2  -        {s,B}  requests: B  orders: B   output event forbidden",
    ]


def test_ordered_and_atomic_writes(tmp_path):
    """docs/filter.md: from {s,B} with the request A, the filter writes A=1, B=0. Falls first
    passes through {s}, which violates K: a transient of the ordered write, absent when the
    outputs are written at once."""
    out = tmp_path / "two.filter"
    out.write_text(skeleton(DATA / "two.rules", out).text)
    f = load_filter(out)
    ordered = verify(f, str(DATA / "two.rules"), any_control=True)
    atomic = verify(f, str(DATA / "two.rules"), any_control=True, atomic=True)
    assert ordered.safe and atomic.safe and ordered.coherent
    assert (ordered.states, ordered.findings["transient"].count) == (7, 2)
    assert (atomic.states, atomic.findings["transient"].count) == (7, 1)
    assert not verify(f, str(DATA / "two.rules"), any_control=True, strict=True).safe


def test_fallback_and_care_set(cli):
    v = verify(load_filter(DATA / "three_cycle.filter"), str(DATA / "three.rules"), any_control=True,
               algorithm=Algorithm.LOOP)
    assert (v.safe, v.coherent, v.states) == (True, False, 4)
    assert _rows(v.findings["fallback"]) == [
        ("initial", "{}", (), (), ""), ("-", "{}", ("o1", "o3"), (), "requests violate K2; fallback")]
    assert verify(load_filter(DATA / "three_cycle.filter"), str(DATA / "three.rules"), any_control=True).coherent
    v = verify(load_filter(DATA / "two_assume.filter"), str(DATA / "two.rules"), any_control=True)
    assert not v.coherent and v.findings["outside_care"].count == 4
    assert _rows(v.findings["outside_care"])[-1][0] == "↑s"
    code, out, _ = cli("filter", "verify", DATA / "three_cycle.filter", "--plant", DATA / "three.rules",
                       "--any-control", "--algorithm", "loop")
    assert code == 1 and "incoherent: the loop falls back (4 plant states)" in out


def test_grafcet_requests(cli, tmp_path):
    """The Grafcet asks for B while s; the filter keeps A on while s (E): 2 of 8 cycles corrected."""
    out = tmp_path / "two.filter"
    out.write_text(skeleton(DATA / "two.rules", out).text)
    v = verify(load_filter(out), str(DATA / "two.rules"), str(DATA / "two.g7"))
    assert (v.safe, v.coherent, v.states, v.cycles, v.corrected, v.max_distance) == (True, True, 4, 8, 2, 1)
    code, text, _ = cli("filter", "verify", out, "--plant", DATA / "two.rules", "--grafcet", DATA / "two.g7")
    assert code == 0 and "transparency: 2 of 8 cycles correct the requests, largest Hamming distance 1" in text
    code, text, _ = cli("filter", "verify", out, "--plant", DATA / "two.rules", "--grafcet", DATA / "two.g7", "--json")
    data = json.loads(text)
    assert_valid("filter_verify", data)
    assert (data["corrected"], data["max_distance"], data["findings"]["transient"]["trace"][0]["situation"]) == (
        2, 1, "{X0}")
    code, text, _ = cli("filter", "verify", tmp_path / "no.filter", "--plant", DATA / "two.rules", "--any-control")
    assert code == 2


def test_grafcet_on_tri(tri_filter):
    v = verify(load_filter(tri_filter), str(TRI), str(ROOT / "grafcets" / "tri.g7"))
    assert (v.safe, v.coherent, v.states, v.cycles, v.corrected) == (True, True, 90, 370, 0)


def test_bad_input_and_limit(cli, tmp_path):
    f = tmp_path / "x.filter"
    f.write_text("inputs s, zz\noutputs A\nsafety K: s & A\n")
    with pytest.raises(InputError, match="the filter's input zz is not an input of the plant"):
        verify(load_filter(f), str(DATA / "two.rules"), any_control=True)
    f.write_text("inputs s\noutputs A, B\nobserver X1\nsafety K: s & A & X1\n")
    code, _, err = cli("filter", "verify", f, "--plant", DATA / "two.rules", "--any-control")
    assert code == 2 and f"{f}:3:10: error: observer X1 has no value in verify" in err
    with pytest.raises(SystemExit):
        cli("filter", "verify", f, "--plant", DATA / "two.rules")
    code, _, err = cli("filter", "verify", DATA / "two_no_edge.filter", "--plant", DATA / "two.rules",
                       "--any-control", "--algorithm", "loop")
    assert code == 2 and "K is a combined constraint without priority" in err
    code, out, err = cli("filter", "verify", DATA / "three_cycle.filter", "--plant", DATA / "three.rules",
                         "--any-control", "--max-states", "2")
    assert code == 2 and "STOPPED at the state limit" in out
    code, out, _ = cli("filter", "verify", DATA / "three_cycle.filter", "--plant", DATA / "three.rules",
                       "--any-control", "--max-states", "4")  # exactly the reachable states: complete
    assert code == 0 and out.splitlines()[1].startswith("explored 4 states (4 plant states), 16 cycles in ")
    assert err.splitlines()[-1].startswith("stopped: the exploration reached --max-states 2")


# ---------------------------------------------------------------- the oracle

def _oracle(f, rules: str, atomic: bool = False, mode: Mode = Mode.SUPERVISOR):
    """The closed loop one state, one event, one request vector at a time."""
    rs = load_rules(rules)
    p = plant(rs)
    cc = CompiledConstraints(p, rs.constraints)
    cyc = FilterCycle(f, mode=mode)
    used = [cyc.remembered.index(n) for n in cyc.used]

    def key(local, memory):
        return local, tuple(memory.previous[i] for i in used), memory.blocked

    start = (p.initial, cyc.initial())
    seen = {key(*start)}
    queue = deque([start])
    found = {"violation": set(), "edge": set(), "transient": set(), "incoherent": set()}
    cycles = 0
    extra = ("Ack",) if mode is Mode.BLOCKING else ()
    while queue:
        local, memory = queue.popleft()
        for post in [local] + [dst for t, dst in p.successors(local) if not t.controllable]:
            if post != local and cc.violated(post) and not cc.violated(local):
                found["transient"].add(post)
            val = p.valuation(post)
            outcomes = set()
            for bits in product((False, True), repeat=len(f.outputs) + len(extra)):
                values = {n: val[n] for n in f.inputs}
                values.update(zip((*f.requests, *extra), bits))
                r, after = cyc.step(memory, values)
                cur, middle, edge = post, False, False
                for rising in (False, True):
                    for o in p.outputs:
                        if r.outputs[f.outputs.index(o)] == rising and p.valuation(cur)[o] != rising:
                            ev = Event.edge(o, rising)
                            edge |= bool(cc.forbidding(ev, post if atomic else cur))
                            cur = next(d for t, d in p.successors(cur) if t.event == ev)
                            middle |= not atomic and bool(cc.violated(cur))
                if cc.violated(cur):
                    found["violation"].add(cur)
                elif middle and not cc.violated(post):
                    found["transient"].add(post)
                if edge:
                    found["edge"].add(post)
                if r.fallback or r.outside_care:
                    found["incoherent"].add(post)
                outcomes.add((cur, key(cur, after), r.fallback, r.outside_care))
                k = key(cur, after)
                if k not in seen:
                    seen.add(k)
                    queue.append((cur, after))
            cycles += len({(k, fb, oc) for _, k, fb, oc in outcomes})
    return len(seen), cycles, {k: len(v) for k, v in found.items()}


@pytest.mark.parametrize("name, rules, atomic, mode", [
    ("two_no_edge.filter", "two.rules", False, Mode.SUPERVISOR),
    ("two_no_edge.filter", "two.rules", True, Mode.SUPERVISOR),
    ("two_assume.filter", "two.rules", False, Mode.SUPERVISOR),
    ("two_assume.filter", "two.rules", False, Mode.BLOCKING),
    ("three_cycle.filter", "three.rules", False, Mode.SUPERVISOR),
])
def test_against_the_oracle(name, rules, atomic, mode):
    f = load_filter(DATA / name)
    v = verify(f, str(DATA / rules), any_control=True, atomic=atomic, mode=mode)
    states, cycles, found = _oracle(f, str(DATA / rules), atomic, mode)
    count = {k: v.findings[k].count if k in v.findings else 0 for k in ("violation", "edge", "transient")}
    incoherent = v.findings.get("outside_care") or v.findings.get("fallback")
    count["incoherent"] = incoherent.count if incoherent else 0
    assert (v.states, v.cycles, count) == (states, cycles, found)


def test_blocking_mode_latch_in_the_state(tri_filter):
    f = parse_filter("use \"%s\"\nsafety K: s & !A & !B\nsafety E: ↓A & s\n" % (DATA / "two.rules").as_posix(),
                     "b.filter")
    plain = verify(f, str(DATA / "two.rules"), any_control=True)
    blocking = verify(f, str(DATA / "two.rules"), any_control=True, mode=Mode.BLOCKING)
    assert blocking.safe and blocking.states > plain.states


def test_held_orders(tmp_path):
    """`hold TAPIS = 1` (tri_annex.rules): the request of a held order is its held value; a
    filter that switches it off meets a plant with no event ↓TAPIS (refused)."""
    annex = ROOT / "plants" / "tri_annex.rules"
    out = tmp_path / "annex.filter"
    out.write_text(skeleton(annex, out).text)
    v = verify(load_filter(out), str(annex), any_control=True)
    assert (v.safe, v.coherent, v.states, v.cycles) == (True, True, 2199, 174035)
    held = tmp_path / "held.filter"
    held.write_text(f'use "{annex.as_posix()}"\nsafety H "stop the conveyor on a small box": TAPIS & cp11\n')
    v = verify(load_filter(held), str(annex), any_control=True)
    assert not v.safe and v.findings["refused"].count == 5184
    assert _rows(v.findings["refused"]) == [
        ("initial", "{v10,v20,v30,v40,TAPIS}", (), (), ""),
        ("↑cp11", "{v10,v20,v30,v40,cp11,TAPIS}", ("TAPIS",), (), "requests violate H; output change refused")]
