"""The keep/force spelling comparison when the chain up to the last relief grows wider than
``regions`` (``synth.filter.reliefs.REGION_SIZE``: nodes of its local relation at a criterion):
the points are taken where the criteria narrow ``S_0``, nothing is compared on every input.
Checked against the comparison on every input (``limit=None``) on small filters."""

from __future__ import annotations

import sys

from synth.filter.language_check import parse_filter
from synth.filter.reliefs import spelling_warnings

from conftest import ROOT


def _families() -> list[str]:
    sys.path.insert(0, str(ROOT / "bench"))
    from filter_scale import chain_filter, grid_edges_filter, grid_filter, ring_filter

    return [ring_filter(4), chain_filter(6), grid_filter(8), grid_edges_filter(16),
            (ROOT / "plants/four_cylinders.filter").read_text(encoding="utf-8")]


def _outputs(message: str) -> list[str]:
    return message.split("it drives ")[1].split(" differently")[0].split(", ")


def test_past_the_region_size_every_warning_is_a_witness_of_the_comparison_on_every_input():
    """Each relief warned is one the comparison on every input warns, its witness naming
    some of the outputs that comparison names; each relief that comparison warns is warned
    or listed as not compared."""
    counts = []
    for n, text in enumerate(_families()):
        f = parse_filter(text, f"f{n}.filter")
        coarse = spelling_warnings(f, regions=-1)
        exact = {w.message.split("'")[0]: _outputs(w.message) for w in spelling_warnings(f, limit=None).warnings}
        warned = [w.message.split("'")[0] for w in coarse.warnings]
        skipped = [s.id for s in coarse.skipped]
        for w in coarse.warnings:
            name = w.message.split("'")[0]
            assert " when " in w.message, w.message  # nothing compared on every input
            assert set(_outputs(w.message)) <= set(exact[name]), w.message
        assert not set(warned) & set(skipped)
        assert set(exact) <= set(warned) | set(skipped), n
        counts.append((len(warned), skipped))
    assert counts == [(3, ["K4"]), (4, ["K1"]), (7, []), (21, ["V4_2"]), (2, ["CSc3", "CSc4"])]


def test_the_first_witness_on_grid_edges():
    f = parse_filter(_families()[3], "g.filter")
    first = spelling_warnings(f, regions=-1).warnings[0].message
    assert first == ("H1_1's relief `keep o1_1` written `force o1_2=0` gives another algebraic filter "
                     "(it drives o1_2 differently when only R_o1_1, R_o1_2, o1_2^-1 are 1)")


def test_under_the_region_size_the_reliefs_are_compared_on_every_input_as_before():
    """grid_edges 8 × 2: 8 reliefs shown at the sparse points, the 14 others compared on
    every input (the chain to its last relief stays far under REGION_SIZE)."""
    found = spelling_warnings(parse_filter(_families()[3], "g.filter"))
    assert [" when " in w.message for w in found.warnings].count(False) == 14
    assert len(found.warnings) == 22 and not found.skipped


def test_the_region_size_is_read_on_the_chain():
    """grid_edges 8 × 2: the chain's widest local relation up to its last relief is 406 nodes
    (at that relief's own criterion, the 22nd); a limit of 406 runs it to there, 405 stops
    it and takes the regions on ``S_0``."""
    import dataclasses

    from synth.filter.reliefs import _other
    from synth.filter.spelling_chain import SpellingChain

    f = parse_filter(_families()[3], "g.filter")
    swapped = [(s, dataclasses.replace(s, keep=o.keep, force=o.force))
               for s in f.combined if s.has_priority for o in (_other(s),) if o is not None]
    coarse = []
    for size in (406, 405):
        chain = SpellingChain(f, swapped)
        chain.sparse_points(range(len(swapped)), size)
        coarse.append((chain.coarse, len(chain.states)))
    assert coarse == [(False, 23), (True, 22)]
