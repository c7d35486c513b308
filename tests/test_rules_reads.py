"""Elements that read other elements' variables (`reads`): guards on them, the product
evaluating each move's guard in the global state, SUP on such plants, the errors, and
the symbolic engine's refusal. docs/rules.md, "Reading other elements"."""

from __future__ import annotations

import json
from collections import deque
from pathlib import Path

import numpy as np

from conftest import ROOT
from synth.logic.events import Event
from synth.logic.expr import evaluate
from synth.plant.composition import Plant, plant
from synth.plant.rules import RuleSet
from synth.plant.rules_check import load_rules, parse_rules
from synth.sup.supervisor import supremal_controllable

# Two stations: cylinder C1 pushes the pallet of cell 1 into cell 2.
TRANSFER = """use "lib/single_acting.rules"
element C1 = single_acting(AVANCER=A1, v0=b1, v1=h1)
element CELLS {
    reads h1
    sensors p1 = 1, p2 = 0
    ↑h1 [p1] -> ↑p2
    ↑h1 [p2] -> ↓p1
}
"""

# A chain where reading restricts the reachable states: t can only follow s, s only go.
CHAIN = """free go = 0
element E {
    reads go
    sensor s = 0
    ↑go -> ↑s
}
element F {
    reads s
    sensor t = 0
    ↑s -> ↑t
}
"""


def _succ(p: Plant, state: str) -> list[tuple[str, str]]:
    return [(str(t.event), p.label(n)) for t, n in p.successors(p.parse_state(state))]


def test_transfer_counts():
    # C1: 6 local states, 6 controllable and 4 uncontrollable moves; CELLS: {p1}, {p1,p2},
    # {p2}. C1 moves freely, so each of the 3 x 6 grid states is reachable: 18. Transitions:
    # C1's 10 local moves in each of the 3 pallet states (30), ↑p2 and ↓p1 each in the 2
    # states of C1 where h1 holds (4), instead of 6 each without the guard.
    p = plant(parse_rules(TRANSFER, "transfer.rules"))
    assert p.reads and p.shape == (6, 3)
    assert (p.state_count, p.count_transitions(), p.count_transitions(True), p.count_transitions(False)) == (18, 34, 18, 16)
    cells = p.element("CELLS")
    assert cells.reads == ("h1",) and (cells.size, cells.count()) == (3, 2)


def test_transfer_successors_exact():
    p = plant(parse_rules(TRANSFER, "transfer.rules"))
    assert _succ(p, "b1,p1") == [("↑A1", "{b1,p1,A1}")]
    assert _succ(p, "h1,p1,A1") == [("↓A1", "{h1,p1}"), ("↑p2", "{h1,p1,p2,A1}")]
    # h1 = 0: the pallet in transit does not leave cell 1
    assert _succ(p, "b1,p1,p2") == [("↑A1", "{b1,p1,p2,A1}")]
    assert _succ(p, "h1,p1,p2") == [("↑A1", "{h1,p1,p2,A1}"), ("↓h1", "{p1,p2}"), ("↓p1", "{h1,p2}")]


def test_drifts_to_reads_the_guards_in_the_plant():
    # CELLS' own automaton keeps ↑p2 from {p1} (some value of h1 allows it); in the plant it
    # needs C1 out, so with A1 = 0 and C1 at rest it never comes by uncontrollable moves alone
    p = plant(parse_rules(TRANSFER, "transfer.rules"))
    cells = p.element("CELLS")
    assert cells.produces(0, Event.rise("p2"))
    assert not p.drifts_to(p.parse_state("b1,p1"), Event.rise("p2"))
    assert p.drifts_to(p.parse_state("b1,p1,A1"), Event.rise("p2"))  # ↓b1 ↑h1 ↑p2
    assert p.drifts_to(p.parse_state("b1,p1,A1"), Event.fall("p1"))
    assert p.drifts_to(p.parse_state("h1,p1"), Event.rise("p2"))  # while h1, before ↓h1


def test_chain_reachable_states_and_successors():
    p = plant(parse_rules(CHAIN, "chain.rules"))
    labels = [p.label(p.local(int(c))) for c in np.nonzero(p.reachable.ravel())[0]]
    assert labels == ["{}", "{s}", "{s,t}", "{go}", "{go,s}", "{go,s,t}"]  # {t}, {go,t}: t without s
    assert (p.size, p.state_count, p.count_transitions()) == (8, 6, 9)
    assert _succ(p, "") == [("↑go", "{go}")]
    assert _succ(p, "go") == [("↓go", "{}"), ("↑s", "{go,s}")]
    assert _succ(p, "s") == [("↑go", "{go,s}"), ("↑t", "{s,t}")]
    # the preimage follows the guards: only {go} leads into {go,s} by ↑s
    target = np.zeros(p.shape, dtype=bool)
    target[p.parse_state("go,s")] = True
    before = p.preimage(target, controllable=False)
    assert sorted(p.label(p.local(int(c))) for c in np.nonzero(before.ravel())[0]) == ["{go}", "{s}"]
    # global copies: go's 8 moves on the grid, ↑s where go (2), ↑t where s (2); 9 among reachable states
    copies = {str(t.event): (src.tolist(), dst.tolist()) for t, src, dst in p.transition_arrays()}
    assert copies == {"↑go": ([0, 1, 2, 3], [4, 5, 6, 7]), "↓go": ([4, 5, 6, 7], [0, 1, 2, 3]),
                      "↑s": ([4, 5], [6, 7]), "↑t": ([2, 6], [3, 7])}
    assert sum(src.size for _, src, _ in p.transition_arrays(p.reachable)) == 9
    from synth.filter.invariants import _reachable  # the filter's own exploration agrees

    assert (_reachable(p) == p.reachable.ravel()).all()


def test_model_with_reads_renamed():
    text = TRANSFER.replace("element CELLS {", "model cells {").replace("reads h1", "reads h") \
        .replace("↑h1", "↑h") + "element CELLS = cells(h=h1)\n"
    p = plant(parse_rules(text, "transfer.rules"))
    assert p.element("CELLS").reads == ("h1",) and p.count_transitions(False) == 16


def _errors(cli, tmp_path: Path, text: str) -> list[str]:
    f = tmp_path / "bad.rules"
    f.write_text(text)
    code, out, err = cli("plant", f)
    assert code == 2 and "Traceback" not in err
    return err.replace(str(f), "bad.rules").splitlines()


def test_foreign_name_not_declared(cli, tmp_path):
    lines = _errors(cli, tmp_path, TRANSFER.replace("↑h1 [p1]", "↑h1 [p1 & !b1]"))
    assert lines[:6] == [
        "bad.rules:6:16: error: guard of element CELLS uses 'b1', which belongs to element C1",
        "  6 |     ↑h1 [p1 & !b1] -> ↑p2",
        "    |                ^~",
        "  = did you mean p1 or h1?",
        "  = note: an element's guards may only use its own variables and those it `reads`: h1, p1, p2",
        "  = note: to read C1's variable, declare `reads b1` in element CELLS",
    ]


def test_cause_of_an_unread_variable(cli, tmp_path):
    lines = _errors(cli, tmp_path, TRANSFER.replace("reads h1", "reads b1"))
    assert lines[0] == "bad.rules:6:6: error: rule of element CELLS uses 'h1', which belongs to element C1"
    assert "  = note: to read C1's variable, declare `reads h1` in element CELLS" in lines


def test_reads_errors(cli, tmp_path):
    assert _errors(cli, tmp_path, TRANSFER.replace("reads h1", "reads h1, hh1"))[:4] == [
        "bad.rules:4:15: error: element CELLS reads unknown variable 'hh1'",
        "  4 |     reads h1, hh1",
        "    |               ^~~",
        "  = did you mean h1?",
    ]
    assert _errors(cli, tmp_path, TRANSFER.replace("reads h1", "reads h1, p1"))[0] == \
        "bad.rules:4:15: error: element CELLS reads 'p1', but it is its own variable: no `reads` needed"
    assert _errors(cli, tmp_path, TRANSFER.replace("reads h1", "reads h1, h1"))[0] == \
        "bad.rules:4:15: error: element CELLS reads 'h1' twice"
    # incoherences stay on the element's own variables
    lines = _errors(cli, tmp_path, TRANSFER.replace("reads h1", "reads h1\n    incoherent p1 & h1"))
    assert lines[0] == "bad.rules:5:21: error: incoherence of element CELLS uses 'h1', which belongs to element C1"


def test_symbolic_refuses_and_auto_is_explicit(cli, tmp_path):
    f = tmp_path / "transfer.rules"
    f.write_text(TRANSFER + "constraint K: p1 & p2 & !h1 = 0\n")
    code, out, err = cli("sup", f, "--engine", "symbolic")
    assert code == 2 and out == ""
    assert err == (f"{f}:4:11: error: the symbolic engine does not support elements that read other elements' "
                   "variables (`reads` in CELLS)\n"
                   "  4 |     reads h1\n"
                   "    |           ^~\n"
                   "  = note: use --engine explicit\n")
    code, out, err = cli("sup", f, "--json")
    data = json.loads(out)
    assert code == 0 and "symbolic" not in data
    assert (data["plant"]["states"], data["states"]) == (18, 12)  # {p1}: 5 C1 states (not (0,h)), {p1,p2}: (1,h), {p2}: 6


FOUR = ROOT / "plants" / "four_cylinders_pallet.rules"


def test_four_cylinders_plant_by_hand(cli):
    # Each cylinder: 6 local states, 6 controllable and 4 uncontrollable moves. The pallet:
    # {p1} -> {p1,p2} -> {p2} -> ... -> {p4,p1} -> {p1}, 8 states, 8 moves, move k needing
    # h of its cylinder (2 of its 6 states). The cylinders move freely, so every one of
    # the 6^4 x 8 = 10368 grid states is reachable. Controllable: 4 x 6 x (6^3 x 8) = 41472;
    # uncontrollable: 4 x 4 x 1728 (cylinders) + 8 x 2 x 6^3 (pallet) = 27648 + 3456 = 31104.
    p = plant(load_rules(FOUR))
    assert p.shape == (6, 6, 6, 6, 8)
    assert (p.state_count, p.count_transitions(True), p.count_transitions(False)) == (10368, 41472, 31104)
    code, out, err = cli("plant", FOUR)
    assert code == 0 and err == ""
    assert out.splitlines()[0] == (f"plant {FOUR}: 10368 states, 72576 transitions (41472 controllable, "
                                   "31104 uncontrollable)")
    assert out.splitlines()[-1] == "  PALLET                          8 states    0 c    8 u"


def _brute_sup(p: Plant, rs: RuleSet) -> tuple[int, int, int]:
    """SUP by plain enumeration over p.successors (constraints: E* forbid ↑Qk when !bk,
    K* are levels): states, controllable and uncontrollable transitions."""
    succ: dict[tuple[int, ...], list] = {}
    queue = deque([p.initial])
    succ[p.initial] = []
    while queue:
        s = queue.popleft()
        succ[s] = list(p.successors(s))
        for _, n in succ[s]:
            if n not in succ:
                succ[n] = []
                queue.append(n)
    assert len(succ) == 10368
    levels = [c.forbidden for c in rs.constraints if c.id.startswith("K")]
    bad = {s for s in succ if any(evaluate(x, p.valuation(s).__getitem__) for x in levels)}
    grow = True
    while grow:
        more = {s for s in succ if s not in bad and any(not t.controllable and n in bad for t, n in succ[s])}
        bad |= more
        grow = bool(more)

    def allowed(s: tuple[int, ...], t, n: tuple[int, ...]) -> bool:
        name = str(t.event)
        return n not in bad and not (name.startswith("↑Q") and not p.valuation(s)["b" + name[2:]])

    seen = {p.initial}
    queue = deque([p.initial])
    counts = [0, 0]
    while queue:
        s = queue.popleft()
        for t, n in succ[s]:
            if allowed(s, t, n):
                counts[0 if t.controllable else 1] += 1
                if n not in seen:
                    seen.add(n)
                    queue.append(n)
    return len(seen), counts[0], counts[1]


def test_four_cylinders_sup(cli):
    rs = load_rules(FOUR)
    p = plant(rs)
    sup = supremal_controllable(p, rs.constraints)
    # illegal by hand: a pallet in transit into cell k+1 (4 pallet states) with C(k+1) not
    # retracted (4 of its 6 states), the other three cylinders free: 4 x 4 x 6^3 = 3456
    assert sup.summary() == {
        "states": 3168, "transitions": 14352, "controllable": 6528, "uncontrollable": 7824,
        "forbidden_transitions": 6144, "illegal": 3456, "defended": 2016, "weakly_defended": 1728,
        "unreachable_removed": 0,
    }
    assert _brute_sup(p, rs) == (3168, 6528, 7824)
    code, out, err = cli("sup", FOUR)
    assert code == 0
    assert out.splitlines()[1:3] == [
        "SUP: 3168 states, 14352 transitions (6528 controllable, 7824 uncontrollable)",
        "removed: 3456 illegal, 2016 defended, 1728 weakly defended, 0 unreachable",
    ]
