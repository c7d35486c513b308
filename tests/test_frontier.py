"""The explicit engine's frontier path (synth/validation/frontier.py) against the machine's
path state by state, its differential oracle: the same SYNC (nodes, edges, order,
conflicts, SYNC state count) and the same reports (text and JSON) byte for byte, on the
bundled Grafcets, the bench families at small sizes and random models; and the features
the frontier path leaves to the machine, named."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from synth.errors import InputError, SynthError
from synth.grafcet.language_check import load_grafcet
from synth.grafcet.machine import GrafcetMachine
from synth.output.result import validation_json, validation_text
from synth.plant.composition import plant
from synth.plant.rules_check import load_rules
from synth.validation import validate as validate_mod
from synth.validation.validate import explore
from synth.validation.frontier import Unsupported, explore_frontier, reason
from synth.validation.result import load_model
from synth.validation.sync import WATCHED_WIDE, WIDE, Exploration, synchronous_product

from conftest import ROOT
from test_symbolic import CASES, _random_case

sys.path.insert(0, str(ROOT / "bench"))
from gen_branches import write_branches  # noqa: E402
from gen_line import write_line  # noqa: E402
from gen_par import write_par  # noqa: E402
from gen_steep import write_steep  # noqa: E402

G = ROOT / "grafcets"
P = ROOT / "plants"


def _frontier_only(p, constraints, machine, how=Exploration()):
    return explore_frontier(p, constraints, machine, how)


def _machine_only(p, constraints, machine, how=Exploration()):
    return synchronous_product(p, constraints, machine, how)


def _both(monkeypatch, g7: Path, rules: Path, homes=(), expert: bool = False) -> tuple:
    """The validation by each path: identical SYNC, text and JSON; returns (frontier, machine)."""
    out = []
    for path in (_frontier_only, _machine_only):
        monkeypatch.setattr(validate_mod, "explore", path)
        out.append(validate_mod.validate(g7, rules, homes=homes, expert=expert))
    a, b = out
    sa, sb = a.sync, b.sync
    assert (sa.nodes, sa.edges, sa.initial, sa.conflicts, sa.sync_states) == (
        sb.nodes, sb.edges, sb.initial, sb.conflicts, sb.sync_states)
    assert [(sa.successors(i), sa.predecessors(i)) for i in range(len(sa.nodes))] == [
        (sb.successors(i), sb.predecessors(i)) for i in range(len(sb.nodes))]
    assert [x.tolist() for x in sa.edge_arrays()] == [x.tolist() for x in sb.edge_arrays()]
    assert validation_text(a) == validation_text(b)
    assert json.dumps(validation_json(a), ensure_ascii=False) == json.dumps(validation_json(b), ensure_ascii=False)
    assert a.stats == b.stats and a.passed == b.passed
    return a, b


def _reason(g7: Path, rules: Path) -> str | None:
    _, p, g = load_model(g7, rules)
    return reason(p, GrafcetMachine(g))


SUPPORTED = [c for c in CASES if _reason(c[0], c[1]) is None]


class TestFrontierOracle:
    def test_most_bundled_cases_run_the_frontier(self):
        assert len(SUPPORTED) >= 11, [c[0].name for c in CASES if c not in SUPPORTED]

    @pytest.mark.parametrize("g7,rules,homes", SUPPORTED, ids=lambda x: x.name if isinstance(x, Path) else str(x))
    @pytest.mark.parametrize("expert", [False, True])
    def test_bundled_cases(self, monkeypatch, g7, rules, homes, expert):
        _both(monkeypatch, g7, rules, homes, expert)

    def test_four_cylinders(self, monkeypatch):
        a, _ = _both(monkeypatch, G / "four_cylinders.g7", P / "four_cylinders.rules")
        assert a.sync.sync_states > 100

    def test_conflicts_noted_by_the_machine_inside_the_frontier(self, monkeypatch):
        a, _ = _both(monkeypatch, ROOT / "tests" / "data" / "or_conflict.g7", P / "tri.rules")
        assert a.sync.conflicts

    @pytest.mark.parametrize("family", ["par", "line", "steep", "branches", "branches_3x1"])
    def test_bench_families(self, monkeypatch, tmp_path, family):
        if family == "branches":
            base, full, missing = write_branches(2, 2, tmp_path)
        elif family == "branches_3x1":  # the middle branch interlocked on both sides
            base, full, missing = write_branches(3, 1, tmp_path)
        else:
            base, full, missing = {"par": write_par, "line": write_line, "steep": write_steep}[family](3, tmp_path)
        a, _ = _both(monkeypatch, full, base)
        assert a.sync.sync_states > 20 and a.passed is not family.startswith("branches")  # the interlocks block the branches
        if family == "branches_3x1":  # several refusals in one settled state
            assert any(len({p.event for p in n.proh}) > 1 for n in a.sync.nodes)
        a, _ = _both(monkeypatch, missing, base)
        assert not a.passed and a.analysis.blocking

    @pytest.mark.parametrize("seed", range(40))
    def test_random_cases(self, monkeypatch, tmp_path, seed):
        _random_case(seed, tmp_path)
        g7, rules = tmp_path / "g.g7", tmp_path / "r.rules"
        try:
            why = _reason(g7, rules)
        except SynthError:
            return  # a model the loader refuses: no SYNC to compare
        assert why is None  # timers, conditional actions, edges, step variables: all on the rows
        homes = ("X0",) if seed % 2 else ()
        try:
            _both(monkeypatch, g7, rules, homes)
        except Unsupported:  # the frontier left it to the machine: a transient cycle
            with pytest.raises(InputError):
                _machine_only(*_loaded(g7, rules))
        except InputError as err:  # met before the frontier starts (the initial situation): the same error
            with pytest.raises(InputError) as theirs:
                _machine_only(*_loaded(g7, rules))
            assert str(theirs.value) == str(err)

    def test_a_long_transient_chain_is_left_to_the_machine(self, monkeypatch, tmp_path):
        """Past the rows' rounds (ROUNDS = 32), the machine finishes the evolution."""
        steps = "\n".join(f"  step {i}" for i in range(1, 41))
        chain = "\n".join(f"  transition {i} -> {i + 1} when 1" for i in range(1, 40))
        (tmp_path / "chain.g7").write_text(
            f"grafcet G {{\n  initial step 0\n{steps}\n  transition 0 -> 1 when ↑start\n{chain}\n"
            "  transition 40 -> 0 when !start\n}\n")
        write_par(1, tmp_path)
        a, _ = _both(monkeypatch, tmp_path / "chain.g7", tmp_path / "par_1.rules")
        assert any(n.situation.steps == ("40",) for n in a.sync.nodes)


def _loaded(g7: Path, rules: Path) -> tuple:
    rs, p, g = load_model(g7, rules)
    return p, rs.constraints, GrafcetMachine(g)


@pytest.mark.parametrize("actions,feature", [
    ("n := 1 on activation", "internal variables"),
])
def test_features_left_to_the_machine_are_named(tmp_path, actions, feature):
    declare = "internal n : 0..1\n" if ":=" in actions else ""
    (tmp_path / "g.g7").write_text(f"{declare}grafcet G {{ initial step 0 step 1: {actions}\n"
                                   "  transition 0 -> 1 when ↑start  transition 1 -> 0 when ↓start }\n")
    write_par(1, tmp_path)
    g7, rules = tmp_path / "g.g7", tmp_path / "par_1.rules"
    why = _reason(g7, rules)
    assert why is not None and why.startswith(feature)
    with pytest.raises(Unsupported, match=feature):
        explore_frontier(*_loaded(g7, rules))
    a, b = explore(*_loaded(g7, rules)), synchronous_product(*_loaded(g7, rules))
    assert (a.nodes, a.edges, a.sync_states) == (b.nodes, b.edges, b.sync_states) and len(a.nodes) > 1


def test_sfc_semantics_left_to_the_machine():
    rs = load_rules(P / "tri.rules")
    p = plant(rs)
    g = load_grafcet(G / "tri.g7", inputs=p.inputs, outputs=p.outputs, semantics="sfc")
    assert reason(p, GrafcetMachine(g)) == "--semantics sfc (one evolution per scan)"


def test_a_transient_cycle_is_the_machines_error(tmp_path):
    (tmp_path / "cycle.g7").write_text("grafcet G { initial step 0 step 1 step 2\n"
                                       "  transition 0 -> 1 when ↑start  transition 1 -> 2 when start\n"
                                       "  transition 2 -> 1 when start }\n")
    write_par(1, tmp_path)
    args = _loaded(tmp_path / "cycle.g7", tmp_path / "par_1.rules")
    with pytest.raises(Unsupported):
        explore_frontier(*args)
    with pytest.raises(InputError) as mine:
        explore(*args)
    with pytest.raises(InputError) as theirs:
        synchronous_product(*args)
    assert str(mine.value) == str(theirs.value)


def test_a_narrow_sync_stays_on_the_machines_path(tmp_path):
    """Below WIDE states waiting, the frontier path is never imported (a subprocess: the
    test process has imported it already)."""
    import subprocess

    write_line(3, tmp_path)
    code = ("import sys; from synth.validation.result import load_model; "
            "from synth.validation.validate import validate_loaded; "
            f"v = validate_loaded(*load_model({str(tmp_path / 'line_3.g7')!r}, {str(tmp_path / 'line_3.rules')!r})); "
            "print(v.sync.sync_states, 'synth.validation.frontier' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env={**__import__("os").environ, "PYTHONPATH": str(ROOT)}).stdout.split()
    assert int(out[0]) > 0 and out[1] == "False" and WIDE == 20


def test_a_wide_sync_goes_to_the_frontier(tmp_path, monkeypatch):
    write_par(4, tmp_path)  # more than 32 states wait early
    import synth.validation.frontier as frontier

    ran = []
    real = frontier.explore_frontier
    monkeypatch.setattr(frontier, "explore_frontier", lambda *a, **kw: ran.append(1) or real(*a, **kw))
    args = _loaded(tmp_path / "par_4.g7", tmp_path / "par_4.rules")
    a, b = explore(*args), synchronous_product(*args)
    assert ran == [1] and (a.nodes, a.edges, a.sync_states) == (b.nodes, b.edges, b.sync_states)


def test_where_the_frontier_takes_over(tmp_path, monkeypatch):
    """An explicit run leaves the machine's path once more than WIDE (20) states wait; the
    run ``auto`` watches once more than WATCHED_WIDE (32) wait, so the counts it judges stay
    those its shares were measured on; the same SYNC either way."""
    write_par(4, tmp_path)
    import synth.validation.frontier as frontier

    taken = []
    real = frontier.explore_frontier
    monkeypatch.setattr(frontier, "explore_frontier", lambda *a, **kw: taken.append(kw["partial"]) or real(*a, **kw))
    args = _loaded(tmp_path / "par_4.g7", tmp_path / "par_4.rules")
    watched: list[tuple[int, int]] = []
    plain, seen, full = explore(*args), explore(*args, Exploration(watch=lambda *counts: watched.append(counts))), synchronous_product(*args)
    assert (WIDE, WATCHED_WIDE) == (20, 32) and len(taken) == 2
    waiting = [len(partial.nodes) - partial.next for partial in taken]
    assert waiting[0] > WIDE and waiting[1] > WATCHED_WIDE and taken[0].next < taken[1].next
    machine_calls = watched[:taken[1].next]  # one call per state expanded on the machine's path
    assert all(w <= WATCHED_WIDE for _, w in machine_calls[:-1]) and machine_calls[-1][1] == waiting[1]
    for sync in (plain, seen):
        assert (sync.nodes, sync.edges, sync.conflicts, sync.sync_states) == (full.nodes, full.edges, full.conflicts,
                                                                              full.sync_states)


@pytest.mark.parametrize("case", ["par", "branches_3x1", "steep_missing", "tri", "or_conflict"])
def test_rows_keyed_by_their_bytes(monkeypatch, tmp_path, case):
    """Rows of more than ROW_BITS columns (situations, the orders wanted and set, refusals)
    are keyed by their packed bytes instead of one integer: forced on every row here, the
    same SYNC and reports as the machine's path."""
    import synth.validation.frontier as frontier
    import synth.validation.regions as regions_module

    monkeypatch.setattr(frontier, "ROW_BITS", 0)
    monkeypatch.setattr(regions_module, "ROW_BITS", 0)
    if case == "par":
        base, g7, _ = write_par(3, tmp_path)
    elif case == "branches_3x1":
        base, g7, _ = write_branches(3, 1, tmp_path)
    elif case == "steep_missing":
        base, _, g7 = write_steep(3, tmp_path)
    elif case == "tri":
        base, g7 = P / "tri.rules", G / "tri.g7"
    else:
        base, g7 = P / "tri.rules", ROOT / "tests" / "data" / "or_conflict.g7"
    a, _ = _both(monkeypatch, g7, base)
    assert a.sync.sync_states > 5


def test_nodes_and_edges_made_in_bulk_are_the_constructors():
    from synth.logic.events import Event
    from synth.validation.sync import Edge, Node, Prohibition, many_edges, many_nodes

    up, down = Event.rise("a"), Event.fall("b")
    edges = many_edges([0, 3], [up, down], [1, 2])
    assert edges == [Edge(0, up, 1), Edge(3, down, 2)] and [hash(e) for e in edges] == [hash(Edge(0, up, 1)),
                                                                                        hash(Edge(3, down, 2))]
    assert repr(edges[1]) == repr(Edge(3, down, 2))
    sit = load_model(G / "tri.g7", P / "tri.rules")[2]
    machine = GrafcetMachine(sit)
    s0 = machine.initial({n: False for n in machine.inputs})
    proh = (Prohibition(up, ("C1",)),)
    nodes = many_nodes([s0, s0], [(0, 1), (1, 0)], [frozenset({"A"}), frozenset()], [("A",), ()], [proh, ()])
    assert nodes == [Node(s0, (0, 1), frozenset({"A"}), ("A",), proh), Node(s0, (1, 0), frozenset(), (), ())]
    with pytest.raises(AttributeError):
        nodes[0].plant = (1, 1)  # frozen as the constructor's


def test_max_states_is_the_same_limit(tmp_path):
    write_par(3, tmp_path)
    args = _loaded(tmp_path / "par_3.g7", tmp_path / "par_3.rules")
    from synth.errors import LimitExceeded

    with pytest.raises(LimitExceeded) as mine:
        explore_frontier(*args, Exploration(max_states=40))
    with pytest.raises(LimitExceeded) as theirs:
        synchronous_product(*args, Exploration(max_states=40))
    assert str(mine.value) == str(theirs.value) == "more than 40 aggregated states; raise --max-states or simplify the model"
    assert len(explore_frontier(*args, Exploration(max_states=1000)).nodes) > 40


@pytest.mark.parametrize("wide", [1, 4])
@pytest.mark.parametrize("case", ["par", "steep_missing", "branches", "four_cylinders", "or_conflict", "timers"])
def test_the_frontier_goes_on_from_the_machines_path(tmp_path, monkeypatch, wide, case):
    """validate.explore: the machine's path until more than ``wide`` states wait, then the
    frontier from there (its nodes, edges, conflicts, regions and SYNC states taken over)."""
    if case == "par":
        base, g7, _ = write_par(3, tmp_path)
    elif case == "steep_missing":
        base, _, g7 = write_steep(3, tmp_path)
    elif case == "branches":
        base, g7, _ = write_branches(2, 2, tmp_path)
    elif case == "four_cylinders":
        base, g7 = P / "four_cylinders.rules", G / "four_cylinders.g7"
    elif case == "or_conflict":  # 6 nodes: never 4 waiting
        base, g7, wide = P / "tri.rules", ROOT / "tests" / "data" / "or_conflict.g7", 1
    else:
        base, g7 = P / "tri.rules", G / "tri.g7"
    monkeypatch.setattr(validate_mod, "WIDE", wide)
    import synth.validation.frontier as frontier

    resumed = []
    real = frontier.explore_frontier
    monkeypatch.setattr(frontier, "explore_frontier", lambda *a, **kw: resumed.append(kw["partial"].next) or real(*a, **kw))
    a, b = explore(*_loaded(g7, base)), synchronous_product(*_loaded(g7, base))
    assert resumed and resumed[0] > 0
    assert (a.nodes, a.edges, a.initial, a.conflicts, a.sync_states) == (b.nodes, b.edges, b.initial, b.conflicts, b.sync_states)
    assert [(a.successors(i), a.predecessors(i)) for i in range(len(a.nodes))] == [
        (b.successors(i), b.predecessors(i)) for i in range(len(b.nodes))]


def _wide(tmp_path: Path, idle: int, missing: bool = False) -> tuple[Path, Path]:
    """par_3 and ``idle`` more double-acting cylinders the Grafcet never orders, declared
    before par_3's second one (past 2^62 states, C1 and C2 lie in different words): a plant
    of 2 × 12^(3 + idle) states whose SYNC stays par_3's."""
    base, full, miss = write_par(3, tmp_path)
    extra = "".join(f"element D{i} = double_acting(AVANCER=AD{i}, RECULER=RD{i}, v0=d{i}_0, v1=d{i}_1)\n"
                    for i in range(idle))
    rules = tmp_path / f"wide_{idle}.rules"
    text = base.read_text(encoding="utf-8")
    at = text.index("element C2 ")
    rules.write_text(text[:at] + extra + text[at:], encoding="utf-8")
    return (miss if missing else full), rules


class TestWidePlants:
    """Plants of 2^40 states and more: codes numbered as met (one word up to 2^62, then two)."""

    @pytest.mark.parametrize("idle,missing,words", [(9, False, 1), (9, True, 1), (15, False, 2), (15, True, 2)])
    def test_the_frontier_runs_them_as_the_machine(self, monkeypatch, tmp_path, idle, missing, words):
        g7, rules = _wide(tmp_path, idle, missing)
        _, p, _ = load_model(g7, rules)
        assert p.size >= 1 << (40 if words == 1 else 64) and _reason(g7, rules) is None
        from synth.validation.regions import PlantCodes
        from synth.sup.constraints import CompiledConstraints

        args = _loaded(g7, rules)
        pc = PlantCodes(p, CompiledConstraints(p, args[1]))
        assert pc.layout is not None and pc.layout.count == words and pc.P == 1 << 32
        assert len({int(pc.layout.word[p.owner[f"a{i}_0"]]) for i in (1, 2, 3)}) == words
        a, _ = _both(monkeypatch, g7, rules)
        assert a.sync.sync_states > 20 and a.passed is not missing

    def test_the_frontier_goes_on_from_the_machine_on_a_wide_plant(self, monkeypatch, tmp_path):
        g7, rules = _wide(tmp_path, 15, missing=True)
        monkeypatch.setattr(validate_mod, "WIDE", 4)
        a, b = explore(*_loaded(g7, rules)), synchronous_product(*_loaded(g7, rules))
        assert (a.nodes, a.edges, a.initial, a.conflicts, a.sync_states) == (
            b.nodes, b.edges, b.initial, b.conflicts, b.sync_states)

    def test_two_states_under_one_key_are_left_to_the_machine(self, monkeypatch, tmp_path):
        import numpy as np
        from synth.validation import words

        g7, rules = _wide(tmp_path, 15)
        monkeypatch.setattr(words.Interned, "_key", lambda self, w: np.zeros(len(w), dtype=np.int64))
        with pytest.raises(Unsupported, match="two plant states under one key"):
            explore_frontier(*_loaded(g7, rules))
        monkeypatch.setattr(validate_mod, "WIDE", 4)
        a, b = explore(*_loaded(g7, rules)), synchronous_product(*_loaded(g7, rules))
        assert (a.nodes, a.edges, a.sync_states) == (b.nodes, b.edges, b.sync_states) and len(a.nodes) > 20


STORED = """inputs start, a1_0, a1_1, a2_0, a2_1
outputs A1, R1, A2, R2
grafcet G {{
  initial step 0
  step 1: set A1 on activation, set A2 on activation
  step 2: reset A1 on activation, set R1 on activation
  step 3: reset A2 on activation, set R2 on activation
  step 4: {r1}set A1 on deactivation, reset A1 on deactivation{reset}
  step 5{step5}
  transition 0 -> 1 when start & a1_0 & a2_0
  transition 1 -> 2, 3 when a1_1 & a2_1{wait}
  transition 2, 3 -> 4 when a1_0 & a2_0
  transition 4 -> 5 when 1
  transition 5 -> 0 when !start
}}
"""


@pytest.mark.parametrize("variant", ["plain", "timer", "missing", "event"])
def test_stored_actions_on_activation_and_deactivation(monkeypatch, tmp_path, variant):
    """Sets and resets on activation, on deactivation and on an event run on the rows (a set
    and a reset of one output in one phase: the reset wins; without step 4's reset of R2,
    the next cycle advances and retracts C2 at once; ``event``: R1 reset on ↓start in step
    5, which start may have fallen before: the next cycle may find R1 still set), against
    the machine's path."""
    write_par(2, tmp_path)
    text = STORED.format(wait=" & 2s/X1" if variant == "timer" else "",  # the timers' columns, then the stored outputs'
                         reset="" if variant == "missing" else ", reset R2 on deactivation",
                         r1="" if variant == "event" else "reset R1 on deactivation, ",
                         step5=": reset R1 on ↓start" if variant == "event" else "")
    (tmp_path / "s.g7").write_text(text, encoding="utf-8")
    g7, rules = tmp_path / "s.g7", tmp_path / "par_2.rules"
    assert _reason(g7, rules) is None
    a, _ = _both(monkeypatch, g7, rules)
    assert any(n.situation.stored for n in a.sync.nodes) and a.sync.sync_states > 20
    assert a.passed is (variant in ("plain", "timer"))
    if variant == "event":
        assert any(n.situation.steps == ("5",) and "R1" in n.situation.stored for n in a.sync.nodes)
        assert {"R1" in n.situation.stored for n in a.sync.nodes if n.situation.steps == ("0",)} == {True, False}


def test_random_grafcets_with_stored_actions(tmp_path):
    """The code generator's random Grafcets (stored actions on activation, deactivation and
    events, timers, edges, step variables) on free inputs and single-acting cylinders: the
    same SYNC by both paths, or the same transient cycle."""
    from randgrafcet import random_grafcet

    lib = (P / "lib" / "single_acting.rules").read_text(encoding="utf-8")
    (tmp_path / "r.rules").write_text(lib + "free a = 0\nfree b = 0\nfree c = 0\n" + "".join(
        f"element V{o} = single_acting(AVANCER={o}, v0={o.lower()}0, v1={o.lower()}1)\n" for o in "PQRMN"),
        encoding="utf-8")
    compared = stored = 0
    for seed in range(24):
        (tmp_path / "g.g7").write_text(random_grafcet(seed), encoding="utf-8")
        args = _loaded(tmp_path / "g.g7", tmp_path / "r.rules")
        assert reason(args[0], args[2]) is None
        try:
            b = synchronous_product(*args)
        except InputError as theirs:  # a transient cycle: left to the machine, or met in the initial situation
            with pytest.raises((Unsupported, InputError)) as mine:
                explore_frontier(*_loaded(tmp_path / "g.g7", tmp_path / "r.rules"))
            assert mine.type is Unsupported or str(mine.value) == str(theirs)
            continue
        a = explore_frontier(*_loaded(tmp_path / "g.g7", tmp_path / "r.rules"))
        assert (a.nodes, a.edges, a.initial, a.conflicts, a.sync_states) == (
            b.nodes, b.edges, b.initial, b.conflicts, b.sync_states), seed
        compared += 1
        stored += any(n.situation.stored for n in a.nodes)
    assert compared >= 16 and stored >= 4


def test_occurrences_against_a_plain_reading():
    """keys.occurrences: each distinct key's first position in order of occurrence, and for
    each position the rank of its key among them (what a dictionary filled in order gives)."""
    from synth.validation.keys import occurrences

    rng = np.random.default_rng(37)
    for size in (0, 1, 2, 17, 300):
        keys = rng.integers(0, max(1, size // 3), size)
        first, at = occurrences(keys)
        seen: dict[int, int] = {}
        for i, k in enumerate(keys.tolist()):
            seen.setdefault(k, i)
        assert first.tolist() == list(seen.values())
        rank = {k: r for r, k in enumerate(seen)}
        assert at.tolist() == [rank[k] for k in keys.tolist()]
