"""The "no effect" races run in the chain's frame (docs/filter.md, "The race in the chain's
frame"): the verdicts of the races run alone from their dropped part, with steps skipped
where the message across the criterion's bag is the chain's."""

from __future__ import annotations

import random
import sys

import pytest

from conftest import ROOT

sys.path.insert(0, str(ROOT / "bench"))
from filter_scale import chain_filter, grid_filter, ring_filter  # noqa: E402
from synth.filter import narrowing, points
from synth.filter.language_check import parse_filter
from synth.filter.solve import synthesis

FRAMED = narrowing._Race.framed


def _verdicts(text: str, monkeypatch: pytest.MonkeyPatch, framed: bool) -> tuple[list[bool], int]:
    skipped = []

    def counted(race: narrowing._Race, *args: object) -> None:
        if framed:
            FRAMED(race, *args)  # type: ignore[arg-type]
        skipped.append(race.skipped)

    monkeypatch.setattr(narrowing._Race, "framed", counted)
    s = synthesis(parse_filter(text, "race.filter"))
    return [a.effect for a in s.applied], sum(skipped)


@pytest.mark.parametrize("text", [grid_filter(16), ring_filter(4), chain_filter(12)], ids=["grid16", "ring4", "chain12"])
def test_framed_races_give_the_verdicts_of_the_races_alone(text: str, monkeypatch: pytest.MonkeyPatch) -> None:
    alone, none = _verdicts(text, monkeypatch, framed=False)
    framed, skipped = _verdicts(text, monkeypatch, framed=True)
    assert framed == alone and none == 0
    if text == grid_filter(16):  # the grid's two priorities without effect: steps far from their output skipped
        assert alone.count(False) == 2 and skipped > 0, skipped


def test_framed_races_on_random_filters(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = random.Random(25)
    for _ in range(25):
        n = rng.randint(3, 5)
        outs = [f"o{k}" for k in range(n)]
        lines = ["inputs a, b, c", "outputs " + ", ".join(outs)]
        for k in range(n):
            lines.append(f"safety S{k}: ↑o{k} & !{rng.choice('abc')}")
            j = rng.randrange(n)
            if j != k:
                lines.append(f"safety K{k}: o{k} & o{j}   keep o{rng.choice((k, j))}")
        text = "\n".join(lines) + "\n"
        assert _verdicts(text, monkeypatch, framed=True)[0] == _verdicts(text, monkeypatch, framed=False)[0], text


def test_random_points_leave_fewer_symbolic_races_and_change_no_verdict(monkeypatch: pytest.MonkeyPatch) -> None:
    """The rounds of random points (``POINT_ROUNDS``) only show effects the symbolic race
    would find: the verdicts are the same without them, and on the grid of 16 outputs they
    leave 6 races of 19 to the symbolic race (the two without effect among them)."""
    framed: list[int] = []

    def counted(race: narrowing._Race, *args: object) -> None:
        framed.append(race.i)
        FRAMED(race, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(narrowing._Race, "framed", counted)
    runs = {}
    for rounds in (0, points.POINT_ROUNDS):
        monkeypatch.setattr(points, "POINT_ROUNDS", rounds)
        framed.clear()
        s = synthesis(parse_filter(grid_filter(16), "grid16.filter"))
        runs[rounds] = ([a.effect for a in s.applied], len(framed))
    (without, symbolic_without), (with_points, symbolic_with) = runs[0], runs[points.POINT_ROUNDS]
    assert with_points == without and without.count(False) == 2
    assert (symbolic_without, symbolic_with) == (19, 6)
