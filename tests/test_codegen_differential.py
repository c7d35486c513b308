"""The proof by execution: generated ST run by the interpreter equals ``synth run``, cycle by cycle.

Bundled Grafcets are explored exhaustively (every input event and the next timer, to a
bounded depth); 200 random Grafcets (``tests/randgrafcet.py``) likewise; deliberately broken
generators (one emitted operator flipped) must be caught.
"""

from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pytest

from synth.codegen import grafcet_st
from synth.codegen.check import differential_check
from synth.grafcet.language_check import load_grafcet, parse_grafcet

from randgrafcet import check_seed, random_grafcet

from conftest import ROOT

BUNDLED = [p for p in sorted(ROOT.glob("grafcets/*.g7")) + sorted(ROOT.glob("tests/data/**/*.g7"))
           if "codegen" not in p.parts]
DEPTH = {"tri.g7": 3, "tri_missing_order.g7": 3, "tri_boxes.g7": 3}  # 11 inputs: 1 335 sequences at depth 3
RANDOM_SEEDS = range(1, 120, 3)  # 1 000 more nightly (40, every third seed: the suite stays under 6 min on 2 cores)


@pytest.mark.slow  # about 60 s: blark parses each program (about 1 ms per character)
@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: str(p.relative_to(ROOT)))
def test_bundled_grafcets_exhaustively(path: Path):
    """Also the test that blark parses the program of every bundled Grafcet: the interpreter
    parses with blark and raises an InputError on any text blark rejects."""
    g = load_grafcet(path)
    program = grafcet_st.generate_program(g, version="test")
    assert program.text.count("\nPROGRAM ") == 1 and program.text.rstrip().endswith("END_PROGRAM")
    report = differential_check(g, depth=DEPTH.get(path.name, 4), program=program)
    assert report.ok, report.text()
    assert report.sequences >= 1


def test_box_sorting_with_the_plants_initial_inputs():
    from synth.plant.rules_check import load_rules

    rs = load_rules(ROOT / "plants/tri.rules")
    g = load_grafcet(ROOT / "grafcets/tri.g7", inputs=rs.inputs, outputs=rs.outputs)
    initial = {v.name: v.initial for v in rs.variables if v.is_input}
    report = differential_check(g, initial, depth=2)
    assert report.ok, report.text()
    assert (report.sequences, report.cycles) == (121, 133)


def test_a_never_stabilising_grafcet_sets_the_unstable_flag():
    g = parse_grafcet("grafcet G { initial step 0 step 1 transition 0 -> 1 when a transition 1 -> 0 when a }",
                      "loop.g7")
    report = differential_check(g, depth=2)
    assert report.ok, report.text()
    assert (report.sequences, report.cycles) == (1, 2)  # initial, then ↑a: both sides never stable


def _random_programs(seeds: range) -> list[tuple[int, int, int, str]]:
    workers = min(2, os.cpu_count() or 1)
    with ProcessPoolExecutor(max_workers=workers) as pool:
        results = list(pool.map(check_seed, seeds, chunksize=4))
    assert [text for _, _, _, text in results if text] == []
    assert len(results) == len(seeds)
    return results


@pytest.mark.slow  # about 35 s on 2 cores: 80 programs for blark to parse
def test_random_grafcets():
    results = _random_programs(RANDOM_SEEDS)
    assert sum(cycles for _, _, cycles, _ in results) > 1500


@pytest.mark.nightly  # about 6 min on 2 cores: pytest -m nightly
def test_random_grafcets_nightly():
    """The same differential on 1 000 more random Grafcets (seeds 120 to 1 119)."""
    results = _random_programs(range(120, 1120))
    assert sum(cycles for _, _, cycles, _ in results) > 25000


def test_random_grafcets_cover_every_construct():
    """The programs the suite runs cover each construct (the thresholds: two thirds of what these 40 seeds give)."""
    texts = [random_grafcet(seed) for seed in RANDOM_SEEDS]
    gs = [parse_grafcet(t, f"random{i}.g7") for i, t in enumerate(texts)]
    assert sum(any(len(t.targets) > 1 for t in g.transitions) for g in gs) >= 3  # AND divergences
    assert sum(any(len(t.sources) > 1 for t in g.transitions) for g in gs) >= 2  # AND convergences
    assert sum(len({t.sources for t in g.transitions}) < len(g.transitions) for g in gs) >= 7  # OR divergences
    assert sum(bool(g.timers) for g in gs) >= 18
    assert sum("↑" in t or "↓" in t for t in texts) >= 24
    assert sum(" on ↑" in t or " on ↓" in t for t in texts) >= 11  # stored actions on events
    assert sum(" on deactivation" in t for t in texts) >= 4
    assert sum(" if " in t for t in texts) >= 9  # conditional actions
    assert sum(len(g.grafcets) > 1 for g in gs) >= 11  # step variables across partial grafcets


def _flip(monkeypatch, old: str, new: str) -> None:
    """Break the generator: the first emitted line containing ``old`` gets ``new`` instead."""
    emit = grafcet_st._Writer.emit
    done = []

    def broken(self, line: str = "", indent: int = 0) -> None:
        if old in line and not done:
            done.append(line)
            line = line.replace(old, new, 1)
        emit(self, line, indent)

    monkeypatch.setattr(grafcet_st._Writer, "emit", broken)


@pytest.mark.parametrize("file, old, new, first", [
    # the rising edge: x AND NOT Prev_x becomes x OR NOT Prev_x
    ("grafcets/edges.g7", " AND NOT _Prev_", " OR NOT _Prev_",
     "initially: active steps of synth run {X0}, of the ST program {X1}"),
    # rule 5 broken: activate, then deactivate (a step deactivated and activated at once is left)
    ("tests/data/codegen/rule5.g7", "X0 := (X0 AND NOT _Fire[1]) OR _Fire[2];", "X0 := (X0 OR _Fire[2]) AND NOT _Fire[1];",
     "after ↑a: active steps of synth run {X0, X1}, of the ST program {X1}"),
    # continuous actions only from stable situations: transient step 1 of G1 would emit T
    ("grafcets/transient.g7", "T := NOT Unstable AND X1", "T := NOT Unstable OR X1",
     "initially: outputs of synth run {}, of the ST program {T}"),
])
def test_a_broken_generator_is_caught(monkeypatch, file, old, new, first):
    _flip(monkeypatch, old, new)
    report = differential_check(load_grafcet(ROOT / file), depth=3)
    assert not report.ok
    assert report.mismatches[0].text() == first



@pytest.mark.parametrize("preset, first", [
    ("3s", None),
    ("2990ms", "after ↑a, ↓a, 2999 ms before 3s/X1: active steps of synth run {X1}, of the ST program {X0}"),
    ("3010ms", "after ↑a, ↓a, 3s/X1: active steps of synth run {X0}, of the ST program {X1}"),
])
def test_a_timer_preset_off_by_10_ms_is_seen(preset, first):
    """The proof plays a cycle 1 ms before each preset and one at it: a program whose 3 s timer
    was changed by 10 ms either way differs from synth run."""
    pytest.importorskip("blark")
    text = "grafcet G {{ initial step 0 step 1: A transition 0 -> 1 when ↑a transition 1 -> 0 when {}/X1 }}"
    g = parse_grafcet(text.format("3s"), "g.g7")
    program = grafcet_st.generate_program(parse_grafcet(text.format(preset), "g.g7"), version="check")
    report = differential_check(g, {"a": False}, depth=3, program=program)
    assert [m.text() for m in report.mismatches][:1] == ([first] if first else [])
