"""The equations of every bundled filter, pinned as they were before the filter's scale work
(issue 25): ``tests/data/filter/pinned.json`` was captured from main before the variable
order, the "no effect" analysis and the printing changed, so none of them may change an
equation, a criterion's verdict, a counterexample of ``check`` or a generated block.
"""

from __future__ import annotations

import json

import pytest

from conftest import ROOT
from synth.codegen.filter_st import filter_block
from synth.errors import InputError, ModelError
from synth.filter.coherence import check
from synth.filter.language_check import load_filter
from synth.filter.solve import synthesis
from synth.output.filter_text import check_text

PINNED = json.loads((ROOT / "tests" / "data" / "filter" / "pinned.json").read_text(encoding="utf-8"))


def test_every_bundled_filter_is_pinned() -> None:
    assert sorted(PINNED) == sorted(p.name for p in (ROOT / "plants").glob("*.filter"))


@pytest.mark.parametrize("name", sorted(PINNED))
def test_solve_and_check_are_unchanged(name: str) -> None:
    want = PINNED[name]
    f = load_filter(str(ROOT / "plants" / name))
    s = synthesis(f, flat=True)
    assert s.equations == want["equations"]
    assert list(s.chained) == want["chained_order"]
    assert s.chained == want["chained"]
    assert [[a.narrows, a.effect] for a in s.applied] == want["criteria"]
    assert s.free == want["free"]
    assert s.inconsistent_text == want["inconsistent"]
    assert check_text(check(f)) == want["check"]


@pytest.mark.parametrize("name", sorted(PINNED))
def test_blocks_are_unchanged(name: str) -> None:
    f = load_filter(str(ROOT / "plants" / name))
    for key, want in PINNED[name]["st"].items():
        algorithm, mode = key.split()
        try:
            text = filter_block(f, algorithm, mode).text
        except (InputError, ModelError):
            assert want is None, key
            continue
        assert text[text.index("FUNCTION_BLOCK"):] == want, key
