"""Seed 000 §6 / seed 002 figure 9, the four cylinders turning pallets clockwise (issue 23,
item 7): the seed's 28 constraints and observers X31..X34 (plants/four_cylinders.filter) in
closed loop with the cell model (plants/four_cylinders*.rules), 1 to 4 pallets. Safe under
any control with 1 and 2 plant events per PLC cycle, unsafe with 3 (the observer misses the
transfer: a 3-cycle trace); the observers are needed; the first PALLET model is unsafe even
with one event per cycle; the Grafcet of grafcets/four_cylinders.g7 turns 1, 2 and 3
pallets (docs/filter.md, "The four cylinders (seed 000 §6)")."""

from __future__ import annotations

import re

import pytest

from conftest import ROOT

FILTER = ROOT / "plants" / "four_cylinders.filter"
GRAFCET = ROOT / "grafcets" / "four_cylinders.g7"
PLANTS = {1: ROOT / "plants" / "four_cylinders.rules", 2: ROOT / "plants" / "four_cylinders_2.rules",
          3: ROOT / "plants" / "four_cylinders_3.rules", 4: ROOT / "plants" / "four_cylinders_4.rules"}


def _lines(out: str) -> list[str]:
    """The report without its first line (paths) and without the measured seconds."""
    return [re.sub(r" in [0-9.]+ s", "", line) for line in out.splitlines()[1:]]


def _trace(out: str, kind: str) -> list[str]:
    """The rows of the shortest trace of ``kind``."""
    lines = out.splitlines()
    start = lines.index(f"shortest trace ({kind}):") + 1
    end = lines.index("", start) if "" in lines[start:] else len(lines)
    return [line.rstrip() for line in lines[start:end]]


def test_the_plants(cli):
    # One pallet cannot duplicate: 17 856 states without control (violations included).
    # Past a collision the model may merge two pallets, so more pallets reach more states.
    counts = {1: (17856, 71424, 48288), 2: (84512, 338048, 230272), 3: (148448, 593792, 404576),
              4: (152544, 610176, 415840)}
    for n, (states, c, u) in counts.items():
        code, out, err = cli("plant", PLANTS[n])
        assert code == 0 and err == ""
        assert out.splitlines()[0] == (f"plant {PLANTS[n]}: {states} states, {c + u} transitions "
                                       f"({c} controllable, {u} uncontrollable)")
    code, out, _ = cli("plant", PLANTS[2])
    assert out.splitlines()[4:] == [
        "  C1         (pusher)             6 states    6 c    4 u",
        "  C2         (pusher)             6 states    6 c    4 u",
        "  C3         (pusher)             6 states    6 c    4 u",
        "  C4         (pusher)             6 states    6 c    4 u",
        "  CELL1      (full_cell)          4 states    0 c    5 u",
        "  CELL2      (full_cell)          4 states    0 c    5 u",
        "  CELL3      (cell)               4 states    0 c    5 u",
        "  CELL4      (cell)               4 states    0 c    5 u"]


SAFE = [  # pallets, events per cycle, explored states, plant states, cycles
    (1, 1, 2160, 1584, 16376), (1, 2, 2160, 1584, 33896),
    (2, 1, 810, 506, 3526), (2, 2, 810, 506, 6294),
    (3, 1, 60, 44, 140), (3, 2, 60, 44, 200),
    (4, 1, 1, 1, 1), (4, 2, 1, 1, 1),
]


@pytest.mark.parametrize("pallets, k, states, plant_states, cycles", SAFE)
def test_safe_under_any_control(cli, pallets, k, states, plant_states, cycles):
    code, out, err = cli("filter", "verify", FILTER, "--plant", PLANTS[pallets], "--any-control",
                         "--events-per-cycle", k)
    assert code == 0, out + err
    assert _lines(out) == [
        *([f"up to {k} plant events between two scans"] if k != 1 else []),
        f"explored {states} states ({plant_states} plant states), {cycles} cycles",
        "safe: no constraint is violated once the outputs are written",
        "outside SUP: 0 explored plant states can reach a violation by uncontrollable events alone",
        "coherent: Y never leaves the care set"]


def test_the_loop_algorithm_is_safe_too(cli):
    code, out, _ = cli("filter", "verify", FILTER, "--plant", PLANTS[1], "--any-control", "--algorithm", "loop")
    assert code == 0
    assert _lines(out)[0] == "explored 2160 states (1584 plant states), 16376 cycles"
    assert _lines(out)[-1] == "coherent: the loop never falls back"


def test_three_events_per_cycle_the_observer_misses_the_transfer(cli):
    # The write of Q1, then ↓b1, ↑t2, ↓i1 before the next scan: the PLC never sees i1 with
    # Q1^-1, X32 stays 0, and Q2 may extend while the pallet travels towards cell 2.
    code, out, _ = cli("filter", "verify", FILTER, "--plant", PLANTS[1], "--any-control", "--events-per-cycle", "3")
    assert code == 1
    assert _lines(out)[:6] == [
        "up to 3 plant events between two scans",
        "explored 21660 states (6912 plant states), 767224 cycles",
        "unsafe: a plant state violates a constraint once the outputs are written (1608 plant states): K2",
        "transient: 1872 plant states violate a constraint between the plant's event and the end of the write (K2)",
        "outside SUP: 3168 explored plant states can reach a violation by uncontrollable events alone",
        "incoherent: Y is outside the care set of the algebraic filter (1008 plant states)"]
    assert _trace(out, "a plant state violates a constraint once the outputs are written") == [
        "0  initial        {b1,b2,b3,b4,i1}",
        "1  -              {b1,b2,b3,b4,i1,Q1}  requests: Q1  orders: Q1",
        "2  ↓b1, ↑t2, ↓i1  {b2,b3,b4,t2,Q1,Q2}  requests: Q2  orders: Q1, Q2   requests violate CSs1_6",
        "3  ↓b2            {b3,b4,t2,Q1,Q2}     requests: Q2  orders: Q1, Q2   requests violate CSs1_6"]


def test_without_the_observers_one_event_per_cycle_is_unsafe(cli, tmp_path):
    # Drop CSsk_4 (↑Qk & X3k): the pallet leaves i1 and cylinder 2 extends into its way.
    text = FILTER.read_text()
    f = tmp_path / "no_observer.filter"
    f.write_text("\n".join(line for line in text.splitlines() if not re.match(r"safety CSs\d_4 ", line)) + "\n")
    assert f.read_text().count("safety") == text.count("safety") - 4
    code, out, _ = cli("filter", "verify", f, "--plant", PLANTS[1], "--any-control", "--max-states", "300")
    assert code == 1
    assert _trace(out, "a plant state violates a constraint once the outputs are written") == [
        "0  initial  {b1,b2,b3,b4,i1}",
        "1  -        {b1,b2,b3,b4,i1,Q1}  requests: Q1  orders: Q1",
        "2  ↓b1      {b2,b3,b4,i1,Q1}     requests: -  orders: Q1   requests violate CSs1_6",
        "3  ↑t2      {b2,b3,b4,i1,t2,Q1}  requests: -  orders: Q1   requests violate CSs1_6",
        "4  ↓i1      {b2,b3,b4,t2,Q1,Q2}  requests: Q2  orders: Q1, Q2   requests violate CSs1_6",
        "5  ↓b2      {b3,b4,t2,Q1,Q2}     requests: Q2  orders: Q1, Q2   requests violate CSs1_6"]


@pytest.mark.nightly  # 4 s: a model the square no longer uses (pytest -m nightly)
def test_the_pallet_model_moving_after_the_stroke_is_unsafe(cli):
    # four_cylinders_pallet.rules: the pallet reaches cell 2 only after h1, once Q1 may have
    # dropped (X32 then resets): cylinder 2 extends while the pallet is still arriving.
    code, out, _ = cli("filter", "verify", FILTER, "--plant", ROOT / "plants" / "four_cylinders_pallet.rules",
                       "--any-control")
    assert code == 1
    assert _lines(out)[:2] == [
        "explored 12524 states (7128 plant states), 116116 cycles",
        "unsafe: a plant state violates a constraint once the outputs are written (1728 plant states): K2"]
    assert _trace(out, "a plant state violates a constraint once the outputs are written") == [
        "0  initial  {b1,b2,b3,b4,i1}",
        "1  -        {b1,b2,b3,b4,i1,Q1}     requests: Q1  orders: Q1",
        "2  ↓b1      {b2,b3,b4,i1,Q1}        requests: -  orders: Q1   requests violate CSs1_6",
        "3  ↑h1      {b2,b3,b4,h1,i1}        requests: -  orders: -",
        "4  ↑i2      {b2,b3,b4,h1,i1,i2,Q2}  requests: Q2  orders: Q2",
        "5  ↓b2      {b3,b4,h1,i1,i2,Q2}     requests: -  orders: Q2   requests violate CSs2_6"]


GRAFCET_RUNS = [  # pallets, events per cycle, states, plant states, cycles, corrected, distance
    (1, 1, 361, 301, 1201, 556, 1), (1, 2, 361, 301, 3009, 1376, 1),
    (2, 1, 313, 229, 897, 753, 2), (2, 2, 321, 229, 1937, 1603, 2),
    (3, 1, 41, 33, 81, 81, 3), (3, 2, 41, 33, 113, 113, 3),
]


@pytest.mark.parametrize("pallets, k, states, plant_states, cycles, corrected, distance", GRAFCET_RUNS)
def test_the_grafcet_turns_the_pallets(cli, pallets, k, states, plant_states, cycles, corrected, distance):
    code, out, err = cli("filter", "verify", FILTER, "--plant", PLANTS[pallets], "--grafcet", GRAFCET,
                         "--progress", "↑i2", "--events-per-cycle", k)
    assert code == 0, out + err
    assert _lines(out) == [
        *([f"up to {k} plant events between two scans"] if k != 1 else []),
        f"explored {states} states ({plant_states} plant states), {cycles} cycles",
        "safe: no constraint is violated once the outputs are written",
        "outside SUP: 0 explored plant states can reach a violation by uncontrollable events alone",
        "coherent: Y never leaves the care set",
        f"transparency: {corrected} of {cycles} cycles correct the requests, largest Hamming distance {distance}",
        "progress ↑i2: holds: GOAL stays reachable from every state and no fair cycle avoids it"]


def test_four_pallets_never_move(cli):
    code, out, _ = cli("filter", "verify", FILTER, "--plant", PLANTS[4], "--grafcet", GRAFCET, "--progress", "↑i2")
    assert code == 1
    assert _lines(out)[4:] == [
        "transparency: 1 of 1 cycles correct the requests, largest Hamming distance 4",
        "progress ↑i2: fails: GOAL cannot be reached from 1 states",
        "",
        "shortest trace (progress):",
        "0  initial  {b1,b2,b3,b4,i1,i2,i3,i4}  {X101, X201, X301, X401}   GOAL cannot be reached from here"]


def test_the_grafcet_with_three_events_per_cycle(cli):
    code, out, _ = cli("filter", "verify", FILTER, "--plant", PLANTS[1], "--grafcet", GRAFCET,
                       "--events-per-cycle", "3")
    assert code == 1
    assert _lines(out)[1:3] == [
        "explored 881 states (593 plant states), 17009 cycles",
        "unsafe: a plant state violates a constraint once the outputs are written (32 plant states): K2"]
    assert _trace(out, "a plant state violates a constraint once the outputs are written") == [
        "0  initial        {b1,b2,b3,b4,i1}        {X101, X200, X300, X400}",
        "1  -              {b1,b2,b3,b4,i1,Q1}     {X101, X200, X300, X400}  requests: Q1  orders: Q1",
        "2  ↓b1, ↑t2, ↓i1  {b2,b3,b4,t2,Q1}        {X101, X200, X300, X400}  requests: Q1  orders: Q1",
        "3  ↑i2            {b2,b3,b4,i2,t2,Q1,Q2}  {X101, X201, X300, X400}  requests: Q1, Q2  orders: Q1, Q2",
        "4  ↓b2            {b3,b4,i2,t2,Q1,Q2}     {X101, X201, X300, X400}  requests: Q1, Q2  orders: Q1, Q2"]


def test_the_doc_shows_the_three_event_trace():
    doc = (ROOT / "docs" / "filter.md").read_text(encoding="utf-8")
    section = doc[doc.index("## The four cylinders (seed 000 §6)"):doc.index("## Not yet")]
    assert "\n".join([
        "0  initial        {b1,b2,b3,b4,i1}",
        "1  -              {b1,b2,b3,b4,i1,Q1}  requests: Q1  orders: Q1",
        "2  ↓b1, ↑t2, ↓i1  {b2,b3,b4,t2,Q1,Q2}  requests: Q2  orders: Q1, Q2   requests violate CSs1_6",
        "3  ↓b2            {b3,b4,t2,Q1,Q2}     requests: Q2  orders: Q1, Q2   requests violate CSs1_6"]) in section
    assert "observer X31 := Q4^-1 & (i4 | X31^-1)" in (ROOT / "plants" / "four_cylinders.filter").read_text()


TOGGLE = ROOT / "plants" / "four_cylinders_toggle.st"
TOGGLE_RUNS = [  # pallets, states, plant states, cycles, corrected
    (1, 2304, 1280, 8320, 7856), (2, 1080, 480, 2980, 2760), (3, 80, 40, 152, 128),
]


@pytest.mark.parametrize("pallets, states, plant_states, cycles, corrected", TOGGLE_RUNS)
def test_the_seeds_toggling_controller_turns_1_2_3_pallets(cli, pallets, states, plant_states, cycles, corrected):
    """Seed 000 §6: the filter as the controller (request every order, release it at the next
    cycle) turns the pallets: safe, and a transfer into cell 2 stays reachable with no fair
    cycle avoiding it."""
    pytest.importorskip("blark")
    code, out, err = cli("filter", "verify", FILTER, "--plant", PLANTS[pallets], "--control", TOGGLE, "--progress", "↑i2")
    assert code == 0, out + err
    assert _lines(out)[1:] == [
        "safe: no constraint is violated once the outputs are written",
        "outside SUP: 0 explored plant states can reach a violation by uncontrollable events alone",
        "coherent: Y never leaves the care set",
        f"transparency: {corrected} of {cycles} cycles correct the requests, largest Hamming distance 4",
        "progress ↑i2: holds: GOAL stays reachable from every state and no fair cycle avoids it"]
    assert _lines(out)[0] == f"explored {states} states ({plant_states} plant states), {cycles} cycles"


@pytest.mark.parametrize("pallets", [1, 2, 3])
def test_every_transfer_stays_reachable_under_the_toggle(pallets):
    """Seed 000 §6, "every transfer stays reachable": with the toggling controller, each of
    the four transfers (↑i1 … ↑i4) is reachable from every state and no fair cycle avoids it
    (one exploration of the loop, the four goals checked on it)."""
    pytest.importorskip("blark")
    from synth.codegen.interpreter.machine import load_st
    from synth.filter.loop.verify import goal_of, progress_of
    from synth.filter.loop.control_st import StSource
    from synth.filter.cycle import Algorithm, Mode
    from synth.filter.loop.explorer import Explorer
    from synth.filter.language_check import load_filter
    from synth.filter.loop.product import Product
    from synth.plant.composition import load_plant

    pr = Product(load_filter(FILTER), load_plant(PLANTS[pallets]), None, Algorithm.ALGEBRAIC, Mode.SUPERVISOR, False,
                 StSource(str(TOGGLE), load_st))
    ex = Explorer(pr, 100_000, edges=True)
    ex.run()
    assert ex.complete and ex.states == {1: 2304, 2: 1080, 3: 80}[pallets]
    verdicts = {g: progress_of(ex, goal_of(g, pr)) for g in ("↑i1", "↑i2", "↑i3", "↑i4")}
    assert {g: (p.holds, p.unreachable, p.avoiding) for g, p in verdicts.items()} == {
        g: (True, 0, 0) for g in ("↑i1", "↑i2", "↑i3", "↑i4")}
