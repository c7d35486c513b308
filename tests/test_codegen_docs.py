"""Every example of docs/codegen.md is a test: the ST lines shown are in the program generated
for the ``.g7`` shown, and the differential check finds no difference on it."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from synth.codegen.check import differential_check
from synth.codegen.grafcet_st import grafcet_program
from synth.grafcet.language_check import parse_grafcet

DOC = Path(__file__).resolve().parent.parent / "docs/codegen.md"
PAIRS = re.findall(r"```g7\n(.*?)```\n```st\n(.*?)```", DOC.read_text(), re.S)


def test_the_document_has_its_examples():
    assert len(PAIRS) == 9


@pytest.mark.parametrize("g7, st", PAIRS, ids=[f"example{i + 1}" for i in range(len(PAIRS))])
def test_example(g7: str, st: str):
    g = parse_grafcet(g7, "example.g7")
    lines = [line.strip() for line in grafcet_program(g, version="doc").splitlines()]
    for expected in st.strip().splitlines():
        assert expected.strip() in lines
    report = differential_check(g, depth=3)
    assert report.ok, report.text()
