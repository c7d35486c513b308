"""Covers compiled for lanes (synth/logic/lanes.py) against the plain reading: OR over
cubes of the AND of literals, literal by literal."""

from __future__ import annotations

import random

from synth.logic.lanes import compiled, lane_mask


def plain(cover, v, full):
    out = 0
    for cube in cover:
        m = full
        for n, value in cube:
            m &= v[n] if value else full ^ v[n]
        out |= m
    return out


def test_compiled_covers_are_the_plain_reading_on_random_covers_and_lanes():
    rng = random.Random(7)
    names = [f"x{i}" for i in range(9)] + ["R_o", "o^-1", "a'b"]  # names as filters spell them
    for _ in range(300):  # lanes where a cube dies early (uniform values), and mixed ones
        covers = [tuple(tuple((n, rng.random() < 0.5) for n in rng.sample(names, rng.randint(0, 6)))
                        for _ in range(rng.randint(0, 7))) for _ in range(rng.randint(0, 4))]
        count = rng.choice([1, 2, 8, 64, 200])
        full = (1 << count) - 1
        v = {n: rng.choice([0, full, rng.getrandbits(count)]) for n in names}
        late = set(rng.sample(names, rng.randint(0, 4)))
        expected = tuple(plain(c, v, full) for c in covers)
        assert compiled(covers)(v, full) == compiled(covers, late)(v, full) == expected, covers


def test_a_long_cube_is_exact():
    names = [f"y{i}" for i in range(150)]
    cube = tuple((n, i % 3 != 0) for i, n in enumerate(names))
    full = (1 << 40) - 1
    rng = random.Random(1)
    # every literal true on every lane but three, random: the cube is their AND
    v = {n: full if value else 0 for n, value in cube}
    for n in ("y1", "y74", "y149"):
        v[n] = rng.getrandbits(40)
    expected = v["y1"] & v["y74"] & v["y149"]
    assert expected and compiled([(cube,)])(v, full) == (plain((cube,), v, full),) == (expected,)
    assert compiled([(cube, (("y0", True),))])(v, full) == (expected,)


def test_the_empty_cover_is_false_and_the_empty_cube_true():
    assert compiled([(), ((),)])({}, 0b111) == (0, 0b111)
    assert compiled([])({}, 0b111) == ()


def test_lane_masks_give_each_free_name_its_bit_of_the_lane_number():
    for count in (1, 2, 4, 8, 16):
        for i in range(count.bit_length() - 1):
            m = lane_mask(i, count)
            assert [(m >> j) & 1 for j in range(count)] == [(j >> i) & 1 for j in range(count)]
    assert lane_mask(2, 8) == 0b11110000
