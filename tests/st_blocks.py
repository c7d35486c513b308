"""Generated filter blocks, parsed into blark's tree and compiled by the ST interpreter once
per test session."""

from __future__ import annotations

from functools import lru_cache

from synth.codegen.filter_st import FilterBlock, filter_block
from synth.codegen.interpreter.machine import Module, load_st
from synth.filter.language_check import load_filter

from conftest import ROOT


@lru_cache(maxsize=None)
def interpreted(name: str, algorithm: str, mode: str) -> tuple[FilterBlock, Module]:
    """The block of ``plants/<name>.filter`` and its interpreted module."""
    f = load_filter(ROOT / "plants" / f"{name}.filter")
    block = filter_block(f, algorithm, mode)
    return block, load_st(block.text, f"{name}_{algorithm}_{mode}.st")
