"""`synth filter verify --control PROG.st` (issue 23, item 3, "what runs is what was proven"):
the requests of each scan computed by a cyclic ST PROGRAM run by synth's interpreter. The ST
that `synth st` generates for the box sorting gives the Grafcet's verdict and counts, state for
state (its evolution's bookkeeping is VAR_TEMP, the power-up scan is not a cycle); the
seed's toggling controller on one cylinder, safe and unsafe with the exact counterexample; a
TON in the loop (it elapses as a cycle's event, fairly); the bad inputs (exit 2, located)."""

from __future__ import annotations

import functools
import json

import pytest

from conftest import ROOT
from schemas import assert_valid
from test_filter_verify_cycle import SINGLE_ACTING
from synth.codegen.interpreter.machine import load_st
from synth.errors import InputError
from synth.filter.loop.verify import verify
from synth.filter.loop.control_st import StSource, split_control
from synth.filter.cycle import Algorithm, Mode
from synth.filter.loop.explorer import Explorer
from synth.filter.from_rules import skeleton
from synth.filter.language_check import load_filter
from synth.filter.loop.product import Product
from synth.grafcet.language_check import load_grafcet
from synth.output.filter_text import trace_text
from synth.plant.composition import load_plant
from synth.plant.rules_check import load_rules

DATA = ROOT / "tests" / "data" / "filter"
TRI = ROOT / "plants" / "tri.rules"
TOGGLE = DATA / "toggle.st"
CYLINDER = SINGLE_ACTING + """element V1 = single_acting(Q=Q1, b=v10, h=v11)
constraint REST "push only from rest": ↑Q1 & !v10 = 0
constraint END "do not stop before the end": ↓Q1 & !v11 = 0
"""
FILTER = """inputs v10, v11
outputs Q1
safety FROM_REST "push only from rest": ↑Q1 & !v10
safety TO_END "do not stop before the end": ↓Q1 & !v11
"""
DOC = (ROOT / "docs" / "filter.md").read_text(encoding="utf-8")
HALF = "inputs v10, v11\noutputs Q1\nsafety FROM_REST \"push only from rest\": ↑Q1 & !v10\n"


@functools.lru_cache(maxsize=None)
def _parsed(text: str, file: str):
    """load_st, once per text (blark parses the box sorting's program in seconds)."""
    return load_st(text, file)


def _st(option) -> StSource:
    return StSource(str(option), _parsed)


def _grafcet(path, rules):
    """The Grafcet of ``path`` checked against the plant of ``rules`` (as verify loads it)."""
    rs = load_rules(rules)
    return load_grafcet(path, inputs=rs.inputs, outputs=rs.outputs)


def _rows(trace):
    return [(r.event, r.state, r.situation, r.requests, r.orders, r.note) for r in trace]


@pytest.fixture()
def cyl(tmp_path):
    for name, text in (("c.rules", CYLINDER), ("c.filter", FILTER), ("half.filter", HALF)):
        (tmp_path / name).write_text(text, encoding="utf-8")
    return tmp_path


@pytest.fixture(scope="module")
def tri(tmp_path_factory):
    """The skeleton filter of tri.rules and the ST that `synth st` generates from tri.g7."""
    from synth.cli.main import main

    d = tmp_path_factory.mktemp("tri")
    (d / "F.filter").write_text(skeleton(TRI, d / "F.filter").text)
    assert main(["st", str(ROOT / "grafcets" / "tri.g7"), "--plant", str(TRI), "-o", str(d / "tri.st")]) == 0
    return d


# ---------------------------------------------------------------- the generated ST against its Grafcet


def test_generated_st_has_the_grafcets_verdict(tri):
    f = load_filter(tri / "F.filter")
    g = verify(f, str(TRI), str(ROOT / "grafcets" / "tri.g7"))
    c = verify(f, str(TRI), control=_st(tri / "tri.st"))
    assert (g.safe, g.coherent, g.complete, set(g.findings)) == (c.safe, c.coherent, c.complete, set(c.findings)) \
        == (True, True, True, set())
    assert (g.states, g.plant_states, g.cycles, g.corrected) == (90, 90, 370, 0)
    assert (c.states, c.plant_states, c.cycles, c.corrected) == (90, 90, 370, 0)
    assert c.source == f"PROGRAM tri of {tri / 'tri.st'}"
    assert "the same **90 states and 370 cycles**" in " ".join(DOC.split())
    # K = 2: the Grafcet reacts to each event, the program scans once after both
    g2 = verify(f, str(TRI), str(ROOT / "grafcets" / "tri.g7"), events_per_cycle=2)
    c2 = verify(f, str(TRI), control=_st(tri / "tri.st"), events_per_cycle=2)
    assert [(v.safe, v.coherent, v.states, v.plant_states, set(v.findings)) for v in (g2, c2)] == [
        (True, True, 154, 131, {"transient"}), (True, True, 372, 317, {"transient"})]


def test_the_programs_states_are_the_grafcets_states(tri):
    """docs/filter.md: keyed by (plant state, filter memory, Blocked, active steps), the 90
    states of the program are the Grafcet's 90, one for one: the program keeps nothing else
    from a scan to the next (its evolution's bookkeeping is VAR_TEMP, its inputs are given
    at every scan), and its fresh instance (the PLC before the power-up scan) is the
    traces' first row, not a state."""
    f = load_filter(tri / "F.filter")
    pr = Product(f, load_plant(TRI), None, Algorithm.ALGEBRAIC, Mode.SUPERVISOR, False, _st(tri / "tri.st"))
    ex = Explorer(pr, 10_000)
    ex.run()
    gr = Product(f, load_plant(TRI), _grafcet(ROOT / "grafcets" / "tri.g7", TRI), Algorithm.ALGEBRAIC, Mode.SUPERVISOR, False)
    eg = Explorer(gr, 10_000)
    eg.run()

    def program(k):
        mem, blocked, snap = ex.aux_list[k // ex.size]
        return k % ex.size, mem, blocked, frozenset(n[1:] for n, x in snap.instance.values.items()
                                                    if n.startswith("X") and x is True)

    def grafcet(k):
        mem, blocked, sit = eg.aux_list[k // eg.size]
        return k % eg.size, mem, blocked, frozenset(sit.steps)

    states = [program(k) for k in ex.order if k != ex.prelude]
    assert (ex.states, len(states), len(set(states))) == (90, 90, 90)
    assert set(states) == {grafcet(k) for k in eg.order}
    assert ex.trace(ex.order[1])[1].event == "power-up"
    assert not ex.reentered and ex.aux_list[ex.prelude // ex.size][2].text() == "{X0, X100, X200, X300, _FirstCycle}"


def test_cli_json_names_the_program(cli, tri):
    code, out, err = cli("filter", "verify", tri / "F.filter", "--plant", TRI, "--control", tri / "tri.st", "--json")
    data = json.loads(out)
    assert_valid("filter_verify", data)
    assert (code, data["control"], data["states"], data["cycles"], data["safe"]) == (
        0, {"kind": "st", "file": str(tri / "tri.st"), "program": "tri"}, 90, 370, True)
    code, out, _ = cli("filter", "verify", tri / "F.filter", "--plant", TRI, "--grafcet", ROOT / "grafcets" / "tri.g7",
                       "--json")
    data = json.loads(out)
    assert_valid("filter_verify", data)
    assert data["control"] == {"kind": "grafcet", "file": str(ROOT / "grafcets" / "tri.g7")}


# ---------------------------------------------------------------- the seed's toggling controller


def test_toggle_is_made_safe_by_the_filter(cli, cyl):
    """Q1 := NOT Q1_prev: request, then release at the next cycle. The filter holds the order
    until the end of the stroke and keeps it off away from rest."""
    v = verify(load_filter(cyl / "c.filter"), str(cyl / "c.rules"), control=_st(TOGGLE))
    assert (v.safe, v.coherent, v.complete, set(v.findings)) == (True, True, True, set())
    assert (v.states, v.plant_states, v.cycles, v.corrected, v.max_distance) == (10, 6, 18, 6, 1)
    code, out, _ = cli("filter", "verify", cyl / "c.filter", "--plant", cyl / "c.rules", "--control",
                       f"{TOGGLE}:toggle", "--json")
    data = json.loads(out)
    assert_valid("filter_verify", data)
    assert (code, data["control"], data["corrected"]) == (0, {"kind": "st", "file": str(TOGGLE),
                                                              "program": "Toggle"}, 6)


def test_toggle_without_the_end_constraint_is_unsafe(cli, cyl):
    v = verify(load_filter(cyl / "half.filter"), str(cyl / "c.rules"), control=_st(TOGGLE))
    assert (v.safe, v.states, v.plant_states, v.cycles, v.corrected, set(v.findings)) == (False, 4, 3, 7, 1, {"edge"})
    edge = v.findings["edge"]
    assert (edge.constraints, edge.count) == (("END",), 2)
    assert _rows(edge.trace) == [
        ("initial", "{v10}", "{}", (), (), ""),
        ("power-up", "{v10,Q1}", "{Q1_prev}", ("Q1",), ("Q1",), ""),
        ("-", "{v10}", "{}", (), (), "output event forbidden"),
    ]
    assert trace_text(edge.trace) in DOC
    code, out, _ = cli("filter", "verify", cyl / "half.filter", "--plant", cyl / "c.rules", "--control", TOGGLE)
    assert code == 1
    assert out.splitlines()[0] == (f"closed loop: {cyl / 'half.filter'} on {cyl / 'c.rules'}, requests from PROGRAM "
                                   f"Toggle of {TOGGLE} (algebraic, supervisor, ordered outputs)")
    assert out.endswith("shortest trace (an output event breaks an edge constraint):\n"
                        "0  initial   {v10}     {}\n"
                        "1  power-up  {v10,Q1}  {Q1_prev}  requests: Q1  orders: Q1\n"
                        "2  -         {v10}     {}         requests: -  orders: -   output event forbidden\n")


def test_a_ton_elapses_as_an_event_and_fairly(cyl):
    """The clock does not advance; the running TON may elapse instead of a plant event, and
    --progress counts it among the events that cannot be postponed forever."""
    v = verify(load_filter(cyl / "c.filter"), str(cyl / "c.rules"), control=_st(DATA / "timed.st"), progress="↑v11")
    assert (v.safe, v.states, v.plant_states, v.cycles, v.corrected) == (True, 6, 5, 12, 0)
    assert v.progress is not None and v.progress.holds
    pr = Product(load_filter(cyl / "c.filter"), load_plant(cyl / "c.rules"), None, Algorithm.ALGEBRAIC, Mode.SUPERVISOR,
                 False, _st(DATA / "timed.st"))
    ex = Explorer(pr, 100)
    ex.run()
    end = next(k for k in ex.order if pr.val["v11"][k % ex.size])
    assert trace_text(ex.trace(end)).splitlines() == [
        "0  initial            {v10}     {}",
        "1  power-up           {v10}     {rest running}  requests: -  orders: -",
        "2  timer rest (T#2s)  {v10,Q1}  {rest elapsed}  requests: Q1  orders: Q1",
        "3  ↓v10               {Q1}      {}              requests: Q1  orders: Q1",
        "4  ↑v11               {v11}     {}              requests: -  orders: -",
    ]
    assert "\n".join(trace_text(ex.trace(end)).splitlines()[:3]) in DOC


# ---------------------------------------------------------------- bad input, budget


def test_split_control():
    assert split_control("a/b.st:Main") == ("a/b.st", "Main")
    assert split_control("a/b.st") == ("a/b.st", None)
    assert split_control("a:/b.st") == ("a:/b.st", None)


@pytest.mark.parametrize("text, option, expected", [
    (None, "{d}/none.st", "--control:1:1: error: cannot read '{d}/none.st': No such file or directory"),
    ("PROGRAM P\nVAR_OUTPUT Q1 : BOOL; END_VAR\nQ1 := ;\nEND_PROGRAM\n", "{d}/x.st",
     "{d}/x.st:3:7: error: not valid IEC 61131-3 Structured Text (blark)"),
    ("FUNCTION_BLOCK P\nVAR_OUTPUT Q1 : BOOL; END_VAR\nQ1 := TRUE;\nEND_FUNCTION_BLOCK\n", "{d}/x.st",
     "--control:1:1: error: {d}/x.st has no PROGRAM: --control runs a cyclic PROGRAM (its POUs: P)"),
    ("PROGRAM A\nVAR_OUTPUT Q1 : BOOL; END_VAR\nEND_PROGRAM\nPROGRAM B\nVAR_OUTPUT Q1 : BOOL; END_VAR\nEND_PROGRAM\n",
     "{d}/x.st", "--control:1:1: error: {d}/x.st has 2 PROGRAMs (A, B): name one, --control {d}/x.st:NAME"),
    ("PROGRAM Main\nVAR_OUTPUT Q1 : BOOL; END_VAR\nEND_PROGRAM\n", "{d}/x.st:Mian",
     "--control:1:{col}: error: no PROGRAM Mian in {d}/x.st (its PROGRAMs: Main)"),
    ("PROGRAM P\nVAR_OUTPUT Q2 : BOOL; END_VAR\nVAR Q1 : BOOL; END_VAR\nEND_PROGRAM\n", "{d}/x.st",
     "--control:1:1: error: PROGRAM P of {d}/x.st has Q1 in VAR, not in VAR_OUTPUT, and no VAR_OUTPUT Q1: the "
     "request of the output Q1 of {d}/c.filter"),
    ("PROGRAM P\nVAR_INPUT v10 : INT; END_VAR\nVAR_OUTPUT Q1 : BOOL; END_VAR\nEND_PROGRAM\n", "{d}/x.st",
     "--control:1:1: error: VAR_INPUT v10 of PROGRAM P is INT: a plant's signal is a BOOL"),
    ("PROGRAM P\nVAR_OUTPUT Q1 : BOOL; END_VAR\nVAR n : INT; END_VAR\nIF n THEN Q1 := TRUE; END_IF;\nEND_PROGRAM\n",
     "{d}/x.st", "--control:1:1: error: PROGRAM P of {d}/x.st fails in a scan: BOOL expected, got 0"),
    ("PROGRAM P\nVAR_OUTPUT Q1 : BOOL; END_VAR\nWHILE TRUE DO Q1 := NOT Q1; END_WHILE;\nEND_PROGRAM\n",
     "{d}/x.st", "{d}/x.st:3:1: error: loop did not terminate after 100000 iterations"),
])
def test_bad_control_is_located_exit_2(cli, cyl, text, option, expected):
    if text is not None:
        (cyl / "x.st").write_text(text, encoding="utf-8")
    option = option.format(d=cyl)
    expected = expected.format(d=cyl, col=len(option) - 3)
    code, out, err = cli("filter", "verify", cyl / "c.filter", "--plant", cyl / "c.rules", "--control", option)
    assert (code, out) == (2, "")
    assert err.splitlines()[0] == expected and "Traceback" not in err
    if expected.startswith("--control:"):
        assert err.splitlines()[1] == f"  1 | {option}"


def test_the_state_budget_stops_a_counter(cli, cyl):
    """A program that counts its scans has no finite state space: --max-states stops it (exit 2)."""
    (cyl / "n.st").write_text("PROGRAM Count\nVAR_OUTPUT Q1 : BOOL; END_VAR\nVAR n : DINT; END_VAR\n"
                              "n := n + 1;\nEND_PROGRAM\n", encoding="utf-8")
    code, out, err = cli("filter", "verify", cyl / "c.filter", "--plant", cyl / "c.rules", "--control", cyl / "n.st",
                         "--max-states", "20")
    assert code == 2 and out.splitlines()[1].startswith("explored 20 states (1 plant states), ")
    assert out.splitlines()[1].endswith("-- STOPPED at the state limit")
    assert err.splitlines()[-1].startswith("stopped: the exploration reached --max-states 20")


def test_observers_read_the_programs_variables(cyl):
    (cyl / "o.filter").write_text(FILTER + "observer Q1_prev\nsafety HOLD: ↓Q1 & Q1_prev\n", encoding="utf-8")
    v = verify(load_filter(cyl / "o.filter"), str(cyl / "c.rules"), control=_st(TOGGLE))
    assert (v.safe, v.states, v.cycles, v.corrected) == (True, 10, 18, 6)
    (cyl / "p.filter").write_text(FILTER + "observer P\nsafety HOLD: ↓Q1 & P\n", encoding="utf-8")
    with pytest.raises(InputError, match="observer P has no value in verify: define it .* or make it a BOOL variable "
                                         "of PROGRAM Toggle"):
        verify(load_filter(cyl / "p.filter"), str(cyl / "c.rules"), control=_st(TOGGLE))


def test_one_request_source(cyl):
    with pytest.raises(InputError, match="verify needs a request source: --grafcet G.g7, --control PROG.st or "
                                         "--any-control"):
        verify(load_filter(cyl / "c.filter"), str(cyl / "c.rules"), any_control=True, control=_st(TOGGLE))
