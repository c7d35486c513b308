"""SUP explored through per-element move tables (synth/sup/explore.py) against the
per-transition exploration (itself checked against libFAUDES and a plain Tajer in
test_supervisor.py): the same states, the same counts, on random rule sets, on lines,
with the code's digits forced into many groups and the visited bitmap into blocks."""

from __future__ import annotations

import numpy as np
import pytest

from randrules import random_rules
from synth.plant.composition import plant
from synth.plant.rules_check import load_rules, parse_rules
from synth.sup import codes
from synth.sup.codes import Layout, Visited
from synth.sup.constraints import CompiledConstraints
from synth.sup.explore import TABLE_BITS, Explorer
from synth.sup.supervisor import supremal_controllable

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))
from gen_line import write_line  # noqa: E402


def _same(rs, **kw) -> int:
    """Both explorations agree; returns SUP's size."""
    p = plant(rs)
    ref = supremal_controllable(p, rs.constraints, per_transition=True)
    sup = supremal_controllable(p, rs.constraints)
    assert sup.explored is not None or ref.empty
    assert np.array_equal(sup.states, ref.states)
    ref_counts = (ref.count_transitions(True), ref.count_transitions(False), ref.forbidden_transitions, ref.forbidden_counts())
    assert (sup.count_transitions(True), sup.count_transitions(False), sup.forbidden_transitions,
            sup.forbidden_counts()) == ref_counts
    assert list(sup.forbidden_counts()) == list(ref.forbidden_counts())  # the constraints' order
    return sup.size


def _edge_rules(seed: int) -> str:
    """A random rule set with edge constraints on every order (``↑O & x = 0``)."""
    text = random_rules(seed)
    orders = sorted({w.split("=")[0].strip() for line in text.splitlines() if line.strip().startswith("orders")
                     for w in line.strip()[len("orders"):].split(",")})
    levels = [f"s{e}0" for e in range(4) if f"s{e}0" in text]
    extra = [f'constraint X{i} "edge {i}": ↑{o} & !{levels[i % len(levels)]} = 0' for i, o in enumerate(orders)]
    return text + "\n".join(extra) + "\n"


@pytest.mark.parametrize("seed", range(60))
def test_random_rule_sets(seed):
    rs = parse_rules(random_rules(seed), f"random{seed}.rules")
    if plant(rs).reads:
        pytest.skip("reads")
    _same(rs)


@pytest.mark.parametrize("seed", range(20))
def test_random_rule_sets_with_edge_constraints(seed):
    _same(parse_rules(_edge_rules(seed), f"edges{seed}.rules"))


def test_random_families_meet_every_case():
    """The random family is not trivial: empty and non-empty SUPs, cut moves, edge cuts."""
    sizes, edge_cuts = [], 0
    for seed in range(20):
        rs = parse_rules(_edge_rules(seed), "e.rules")
        sizes.append(_same(rs))
        cuts = supremal_controllable(plant(rs), rs.constraints).forbidden_counts()
        edge_cuts += sum(n for cid, n in cuts.items() if cid.startswith("X"))
    assert 0 in sizes and max(sizes) > 50 and edge_cuts > 0


@pytest.mark.parametrize("seed", range(12))
def test_many_groups_and_cross_contexts(seed, monkeypatch):
    """Every digit its own group: contexts span groups (read bit by bit), keys add parts."""
    monkeypatch.setattr(codes, "GROUP_BITS", 0)
    monkeypatch.setattr(Visited, "FLAT_BITS", 0)
    monkeypatch.setattr(Visited, "MIN_SHIFT", 3)
    rs = parse_rules(_edge_rules(seed), f"edges{seed}.rules")
    cc = CompiledConstraints(plant(rs), rs.constraints)
    ex = Explorer.of(cc)
    assert ex is not None and len(ex.layout.groups) >= 2
    _same(rs)


def test_line_in_groups_and_blocks(tmp_path, monkeypatch):
    """line_6: two groups of digits, contexts across them, the bitmap in blocks."""
    monkeypatch.setattr(Visited, "FLAT_BITS", 0)
    write_line(6, tmp_path)
    rs = load_rules(tmp_path / "line_6.rules")
    ex = Explorer.of(CompiledConstraints(plant(rs), rs.constraints))
    assert ex is not None and len(ex.layout.groups) == 2 and ex.layout.radices == [9] * 6
    assert any(t.parts and len(t.parts) == 2 for t in ex.tables)
    assert _same(rs) == 20224


def test_line_counts_match_the_closed_form(tmp_path):
    """line_7: SUP = the states where no two neighbours can leave rest (2 safe, 7 unsafe
    local states each): s' = 2(s + u), u' = 7s."""
    write_line(7, tmp_path)
    rs = load_rules(tmp_path / "line_7.rules")
    s, u = 2, 7
    for _ in range(6):
        s, u = 2 * (s + u), 7 * s
    sup = supremal_controllable(plant(rs), rs.constraints)
    assert sup.size == s + u == 100872


def test_an_element_in_too_many_terms_moves_per_transition():
    """An element in more than TABLE_BITS terms with others: no table, the per-transition path."""
    n = TABLE_BITS + 2
    lines = ["element HUB {", "  orders H = 0", "  sensors h = 0", "  ↑H -> ↑h", "  ↓H -> ↓h", "}"]
    for i in range(n):
        lines += [f"element E{i} {{", f"  orders O{i} = 0", "}"]
        lines.append(f'constraint K{i} "hub {i}": h & O{i} = 0')
    rs = parse_rules("\n".join(lines) + "\n", "hub.rules")
    assert Explorer.of(CompiledConstraints(plant(rs), rs.constraints)) is None
    sup = supremal_controllable(plant(rs), rs.constraints)
    assert sup.explored is None and sup.size == 2**n + 3  # HUB at rest: any orders; else none



def test_visited_codes_come_back_sorted_from_flat_and_blocked_bitmaps(monkeypatch):
    rng = np.random.default_rng(7)
    for flat in (True, False):
        monkeypatch.setattr(Visited, "FLAT_BITS", 1 << 27 if flat else 0)
        v = Visited(10**7)
        codes = np.unique(rng.integers(0, 10**7, 50_000))
        v.add(codes[::2])
        v.add(codes[1::2])
        assert np.array_equal(v.codes(), codes) and (v.blocks == 1) == flat


def test_layout_codes_and_visited_blocks():
    lay = Layout([np.array([False, True, True]), np.array([True, False, True, True])], (4, 1))
    assert lay.size == 6 and lay.code((0, 0)) is None and lay.code((2, 3)) == 5
    assert lay.plant_codes(np.arange(6)).tolist() == [4, 6, 7, 8, 10, 11]
    for size in (1 << 20, 1 << 40, 1 << 62):  # one block; a table of blocks; the blocks met searched
        v = Visited(size)
        codes = np.array([3, 9, 1 << 19, (1 << 19) + 8191, size - 1], dtype=np.int64)
        v.add(codes[:2])
        v.add(codes[2:])
        assert v.test(np.array([3, 4, 9, 1 << 19, (1 << 19) + 8191, (1 << 19) + 8192, size - 2, size - 1])).tolist() == \
            [True, False, True, True, True, False, False, True]
        assert v.blocks == (1 if size == 1 << 20 else 3) and v.codes().tolist() == codes.tolist()
        assert (v.table is None) == (size == 1 << 62)


# ---------------------------------------------------------------------------------- grids on disk
def _grids_of(rules):
    rs = load_rules(rules)
    cc = CompiledConstraints(plant(rs), rs.constraints)  # a new plant: the in-memory cache misses
    assert cc.reach_grids is not None
    return cc


def test_reach_grids_kept_on_disk(tmp_path, monkeypatch):
    from synth.plant.composition import _plants
    from synth.sup import stored

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.delenv(stored.OFF, raising=False)
    first = _grids_of(_plants("tri_boxes.rules"))
    (file,) = (tmp_path / "synth" / "grids").iterdir()
    calls = []
    monkeypatch.setattr("synth.sup.constraints.backward_closures", lambda *a, **k: calls.append(a) or [])
    again = _grids_of(_plants("tri_boxes.rules"))  # read back: no closure computed
    assert calls == [] and all(np.array_equal(a, b) for a, b in zip(first.reach_grids, again.reach_grids))
    assert not again.reach_grids[0].flags.writeable and file.suffix == ".bin"


@pytest.mark.parametrize("damage", ["truncated", "flipped", "header"])
def test_damaged_grid_files_are_ignored_and_written_again(damage, tmp_path, monkeypatch):
    from synth.plant.composition import _plants
    from synth.sup import stored

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.delenv(stored.OFF, raising=False)
    first = _grids_of(_plants("tri_boxes.rules"))
    (file,) = (tmp_path / "synth" / "grids").iterdir()
    data = bytearray(file.read_bytes())
    if damage == "truncated":
        data = data[:-10]
    elif damage == "flipped":
        data[-1] ^= 0xFF
    else:
        data[:11] = b"synth-grid2"
    file.write_bytes(bytes(data))
    again = _grids_of(_plants("tri_boxes.rules"))
    assert all(np.array_equal(a, b) for a, b in zip(first.reach_grids, again.reach_grids))
    assert file.read_bytes() != bytes(data)  # written whole again
    assert [f.name for f in file.parent.iterdir()] == [file.name]  # no temporary file left


def test_grid_keys_follow_the_content_and_the_cache_can_be_off(tmp_path, monkeypatch):
    from synth.plant.composition import _plants
    from synth.sup import stored

    rs = load_rules(_plants("tri_boxes.rules"))
    p = plant(rs)
    terms = [t.factors for t in CompiledConstraints(p, rs.constraints).level_terms]
    k = stored.key(p, terms)
    assert k == stored.key(plant(rs), terms)
    (a, vec), *rest = terms[0]
    changed = ((a, ~vec), *rest)
    assert stored.key(p, [changed, *terms[1:]]) != k
    assert stored.key(p, terms[:-1]) != k
    other = load_rules(_plants("four_cylinders.rules"))
    assert stored.key(plant(other), terms) != k
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.setenv(stored.OFF, "1")
    assert stored.folder() is None
    _grids_of(_plants("tri_boxes.rules"))
    assert not (tmp_path / "synth").exists()


@pytest.mark.parametrize("constraint", ["not v10 & not v11 & AVANCER1 = 0", "AVANCER1 & RECULER1 = 0", "v11 = 0"])
def test_a_plant_of_fewer_than_eight_codes(constraint):
    """One cylinder whose constraint leaves fewer than 8 codes: the visited bitmap still holds
    a byte (it once had none: an internal error)."""
    text = ("element V1 {\n    orders AVANCER1 = 0, RECULER1 = 0\n    sensors v10 = 1, v11 = 0\n"
            "    incoherent v10 & v11\n    ↑AVANCER1 [v10] -> ↓v10\n}\n"
            f'constraint C1 "x": {constraint}\n')
    assert _same(parse_rules(text, "small.rules")) > 0
