"""`synth filter verify` on the PLC cycle (issue 23, items 3 and 4): several plant events
between two scans (--events-per-cycle, the docs/filter.md example read from the doc),
observers computed from their equation (`observer P := EXPR`) on two cylinders, --progress
(holds, unreachable, a fair cycle avoiding the goal) and the crash paths (exit 2)."""

from __future__ import annotations

import json
import re

import pytest

from conftest import ROOT
from schemas import assert_valid
from synth.errors import InputError
from synth.filter.loop.verify import verify
from synth.filter.cycle import FilterCycle
from synth.filter.language_check import load_filter, parse_filter
from synth.filter.run import run_trace
from synth.output.filter_text import trace_text

SINGLE_ACTING = """model single_acting {
    order   Q = 0
    sensors b = 1, h = 0
    incoherent b & h
    ↑Q [b]        -> ↓b
    ↑Q [!b & !h]  -> ↑h
    ↓Q [h]        -> ↓h
    ↓Q [!b & !h]  -> ↑b
    ↑Q: ↓b < ↑h
    ↓Q: ↓h < ↑b
}
"""
CYLINDER = SINGLE_ACTING + "element V = single_acting(Q=Q, b=v0, h=v1)\n"
CYLINDER_FILTER = """inputs v0, v1
outputs Q
safety FROM_REST "push only from rest": ↑Q & !v0
safety TO_END "do not stop before the end": ↓Q & !v1
"""
CYCLING = """inputs v0, v1
outputs Q
grafcet G {
  initial step 0
  step 1: Q
  transition 0 -> 1 when v0
  transition 1 -> 0 when v1
}
"""
TWO = SINGLE_ACTING + """element V1 = single_acting(Q=Q1, b=b1, h=h1)
element V2 = single_acting(Q=Q2, b=b2, h=h2)
constraint APART "never both away from rest": !b1 & !b2 = 0
"""
TWO_FILTER = """# b1 is not wired to the PLC: the observer P1 remembers that cylinder 1 was ordered out.
inputs h1, b2, h2
outputs Q1, Q2
observer P1 := Q1^-1 | P1^-1
safety OUT1 "extend 1 only while 2 rests": ↑Q1 & !b2
safety END1 "do not stop 1 before its end": ↓Q1 & !h1
safety END2 "do not stop 2 before its end": ↓Q2 & !h2
safety OUT2 "never extend 2 once 1 moved": ↑Q2 & P1
safety BOTH: Q1 & Q2 keep Q2
"""


def _doc_blocks() -> tuple[str, str]:
    """The jog example of docs/filter.md: its rules and filter blocks."""
    text = (ROOT / "docs" / "filter.md").read_text(encoding="utf-8")
    section = text[text.index("**`--events-per-cycle K`**"):text.index("**Observers computed by verify.**")]
    rules = re.search(r"```rules\n(.*?)```", section, re.S)
    flt = re.search(r"```filter\n(.*?)```", section, re.S)
    assert rules and flt
    return rules.group(1), flt.group(1)


@pytest.fixture()
def files(tmp_path):
    def write(name: str, text: str) -> str:
        (tmp_path / name).write_text(text, encoding="utf-8")
        return str(tmp_path / name)

    return write


@pytest.fixture()
def jog(files):
    rules, flt = _doc_blocks()
    return files("jog.filter", flt), files("jog.rules", rules)


def _rows(trace):
    return [(r.event, r.state, r.requests, r.orders, r.note) for r in trace]


# ---------------------------------------------------------------- --events-per-cycle


def test_doc_example_k1_safe_k2_unsafe(cli, jog):
    f, rules = jog
    one = verify(load_filter(f), rules, any_control=True)
    assert (one.safe, one.states, one.cycles, one.events_per_cycle, set(one.findings)) == (True, 3, 8, 1, set())
    zero = verify(load_filter(f), rules, any_control=True, events_per_cycle=0)
    assert (zero.safe, zero.states, zero.cycles) == (True, 2, 4)
    two = verify(load_filter(f), rules, any_control=True, events_per_cycle=2)
    assert (two.safe, two.states, two.cycles) == (False, 4, 13)
    found = two.findings["violation"]
    assert (found.constraints, found.count) == (("END",), 1)
    assert trace_text(found.trace).splitlines() == [
        "0  initial   {v0}",
        "1  -         {v0,Q}  requests: Q  orders: Q",
        "2  ↓v0, ↑v1  {v1}    requests: -  orders: -",
    ]
    assert _rows(two.findings["transient"].trace)[-1] == ("↓v0, ↑v1", "{v1,Q}", (), (), "before the PLC writes")
    doc = (ROOT / "docs" / "filter.md").read_text(encoding="utf-8")
    assert "\n".join(["unsafe: a plant state violates a constraint once the outputs are written (1 plant states): END",
                      *trace_text(found.trace).splitlines()]) in doc
    code, out, _ = cli("filter", "verify", f, "--plant", rules, "--any-control", "--events-per-cycle", "2")
    assert code == 1 and out.splitlines()[1] == "up to 2 plant events between two scans"
    code, out, _ = cli("filter", "verify", f, "--plant", rules, "--any-control", "--events-per-cycle", "2", "--json")
    data = json.loads(out)
    assert_valid("filter_verify", data)
    assert (code, data["events_per_cycle"], data["findings"]["violation"]["trace"][2]["event"]) == (1, 2, "↓v0, ↑v1")
    code, out, _ = cli("filter", "verify", f, "--plant", rules, "--any-control")
    assert code == 0 and "plant events between two scans" not in out


def test_events_per_cycle_with_a_grafcet(files):
    """The Grafcet reacts to each event of the cycle in turn: with K = 2 the cylinder leaves
    and reaches its end in one cycle, the Grafcet goes back to step 0 in the same cycle."""
    f, rules, g = files("c.filter", CYLINDER_FILTER), files("c.rules", CYLINDER), files("c.g7", CYCLING)
    counts = [(v.safe, v.states, v.cycles, v.corrected) for v in
              (verify(load_filter(f), rules, g, events_per_cycle=k) for k in (0, 1, 2, 3))]
    assert counts == [(True, 2, 2, 0), (True, 5, 9, 0), (True, 5, 11, 0), (True, 5, 11, 0)]


# ---------------------------------------------------------------- observers


def test_observer_syntax_and_errors():
    f = parse_filter("inputs i4\noutputs Q4\nobserver P := i4 & Q4^-1 | P^-1 & !(!Q4^-1)\nsafety S: ↑Q4 & P",
                     "x.filter")
    (p,) = f.observers
    assert (p.name, p.definition.text()) == ("P", "i4 & Q4^-1 | P^-1 & !!Q4^-1")
    assert FilterCycle(f).reads == ("i4", "R_Q4")  # computed: not read
    for line, message in (("observer P := i4 & ↑Q4", "x.filter:3:21: error: observer P cannot read the output 'Q4' at t"),
                          ("observer P := P & i4", "x.filter:3:15: error: observer P cannot read the observer 'P' at t"),
                          ("observer P := zz", "x.filter:3:15: error: unknown variable 'zz' in the definition of observer P")):
        with pytest.raises(InputError) as err:
            parse_filter(f"inputs i4\noutputs Q4\n{line}\nsafety S: ↑Q4 & P", "x.filter")
        assert err.value.render().splitlines()[0] == message


def test_observer_in_run(files):
    """`run` computes the observer: P = i & Q^-1 | P^-1 (Q^-1: the previous output)."""
    f = files("o.filter", "inputs i\noutputs Q\nobserver P := i & Q^-1 | P^-1\nsafety S: Q & P\n")
    csv = files("t.csv", "i,R_Q\n1,1\n1,1\n0,1\n")
    r = run_trace(load_filter(f), csv)
    assert [c.outputs for c in r.results] == [(True,), (False,), (False,)]


def test_observer_two_cylinders(cli, files):
    rules = files("two.rules", TWO)
    good = verify(load_filter(files("two.filter", TWO_FILTER)), rules, any_control=True)
    assert (good.safe, good.coherent, good.states, good.plant_states, good.cycles) == (True, True, 13, 11, 38)
    weak = files("weak.filter", TWO_FILTER.replace("observer P1 := Q1^-1 | P1^-1", "observer P1 := Q1^-1"))
    v = verify(load_filter(weak), rules, any_control=True)
    assert (v.safe, v.states, v.cycles) == (False, 21, 86)
    found = v.findings["violation"]
    assert (found.constraints, found.count) == (("APART",), 8)
    assert trace_text(found.trace).splitlines() == [
        "0  initial  {b1,b2}",
        "1  -        {b1,b2,Q1}  requests: Q1  orders: Q1",
        "2  ↓b1      {b2,Q1}     requests: Q1  orders: Q1",
        "3  ↑h1      {h1,b2}     requests: -  orders: -",
        "4  ↓h1      {b2,Q2}     requests: Q2  orders: Q2",
        "5  ↓b2      {Q2}        requests: Q2  orders: Q2",
    ]
    code, _, err = cli("filter", "verify", weak, "--plant", rules, "--any-control")
    assert (code, err) == (1, "")


# ---------------------------------------------------------------- --progress


def test_progress_holds_with_a_grafcet(cli, files):
    f, rules, g = files("c.filter", CYLINDER_FILTER), files("c.rules", CYLINDER), files("c.g7", CYCLING)
    for goal in ("v1", "↑v0", "↓v1", "v1 | !v0"):
        v = verify(load_filter(f), rules, g, progress=goal)
        assert v.progress is not None and (v.progress.holds, v.progress.unreachable, v.progress.avoiding) == (
            True, 0, 0), goal
    code, out, _ = cli("filter", "verify", f, "--plant", rules, "--grafcet", g, "--progress", "v1", "--json")
    data = json.loads(out)
    assert_valid("filter_verify", data)
    assert (code, data["progress"]) == (0, {"goal": "v1", "holds": True, "failure": None, "unreachable": 0,
                                            "avoiding": 0, "trace": []})
    code, out, _ = cli("filter", "verify", f, "--plant", rules, "--grafcet", g, "--progress", "v1")
    assert code == 0 and out.splitlines()[-1] == (
        "progress v1: holds: GOAL stays reachable from every state and no fair cycle avoids it")


def test_progress_starved_by_the_filter(cli, files, jog):
    """The jog filter drops the order as the cylinder leaves: the Grafcet never reaches v1."""
    f, _ = jog
    rules, g = files("c.rules", CYLINDER), files("c.g7", CYCLING)
    v = verify(load_filter(f), rules, g, progress="v1")
    assert v.safe and v.progress is not None
    assert (v.progress.holds, str(v.progress.failure), v.progress.unreachable, v.progress.avoiding) == (
        False, "unreachable", 3, 2)
    assert trace_text(v.progress.trace).splitlines() == ["0  initial  {v0}  {X1}   GOAL cannot be reached from here"]
    code, out, _ = cli("filter", "verify", f, "--plant", rules, "--grafcet", g, "--progress", "v1")
    assert code == 1 and out.splitlines()[-4:] == [
        "progress v1: fails: GOAL cannot be reached from 3 states", "", "shortest trace (progress):",
        "0  initial  {v0}  {X1}   GOAL cannot be reached from here"]
    # the observer of the two cylinders is sticky: once cylinder 1 moved, cylinder 2 never can
    two = verify(load_filter(files("two.filter", TWO_FILTER)), files("two.rules", TWO), any_control=True,
                 progress="h2")
    assert two.progress is not None and (str(two.progress.failure), two.progress.unreachable) == ("unreachable", 7)
    assert trace_text(two.progress.trace).splitlines() == [
        "0  initial  {b1,b2}",
        "1  -        {b1,b2,Q1}  requests: Q1  orders: Q1   GOAL cannot be reached from here"]


def test_progress_fair_cycle_avoids_the_goal(cli, files):
    """Any control may never order the cylinder: at rest without the order the plant has no
    event enabled, so staying there is fair. The Grafcet's waiting is not: ↓v0 is enabled."""
    f, rules = files("c.filter", CYLINDER_FILTER), files("c.rules", CYLINDER)
    v = verify(load_filter(f), rules, any_control=True, progress="v1")
    assert v.progress is not None
    assert (str(v.progress.failure), v.progress.unreachable, v.progress.avoiding) == ("avoided", 0, 1)
    assert trace_text(v.progress.trace).splitlines() == [
        "0  initial  {v0}",
        "1  -        {v0}  requests: -  orders: -   back to the state of cycle 0: a fair cycle avoids GOAL"]
    code, out, _ = cli("filter", "verify", f, "--plant", rules, "--any-control", "--progress", "↑Q", "--json")
    data = json.loads(out)
    assert_valid("filter_verify", data)
    assert (code, data["progress"]["failure"], data["progress"]["avoiding"]) == (1, "avoided", 2)
    two = verify(load_filter(files("two.filter", TWO_FILTER)), files("two.rules", TWO), any_control=True,
                 events_per_cycle=2, progress="h1")
    assert two.progress is not None and (str(two.progress.failure), two.progress.avoiding) == ("avoided", 7)


# ---------------------------------------------------------------- crash paths


def test_crash_paths_exit_2(cli, files, jog):
    f, rules = jog
    cases = [
        (["--max-states", "0"], "error: --max-states is a number of states, 1 or more, not 0"),
        (["--events-per-cycle", "-1"], "error: --events-per-cycle is a number of plant events, 0 or more, not -1"),
        (["--progress", "zz"], "--progress:1:1: error: unknown variable 'zz' in --progress: GOAL names the plant's "
                               "variables"),
        (["--progress", "v1 &"], "--progress:1:5: error: syntax error"),
        (["--progress", "↑v1 & v0"], "--progress:1:2: error: --progress: an edge is a whole goal (↑x or ↓x), not part "
                                     "of an expression"),
    ]
    for extra, message in cases:
        code, out, err = cli("filter", "verify", f, "--plant", rules, "--any-control", *extra)
        assert (code, out) == (2, ""), extra
        assert err.splitlines()[0].startswith(message), (extra, err)
    code, out, err = cli("filter", "verify", f, "--plant", rules, "--any-control", "--progress", "v1",
                         "--max-states", "2")
    assert code == 2 and out.splitlines()[-1] == (
        "progress v1: not checked (the exploration stopped at the state limit)")
    assert err.splitlines()[-1].endswith("(progress needs every state: not checked)")
    code, out, _ = cli("filter", "verify", f, "--plant", rules, "--any-control", "--progress", "v1",
                       "--max-states", "2", "--json")
    data = json.loads(out)
    assert_valid("filter_verify", data)
    assert (code, data["complete"], data["progress"]) == (2, False, None)
