"""A seeded slice of the fuzzer (bench/fuzz.py): mutants of the bundled inputs of the nine
languages give no crash, no unlocated error, no slow run and no huge error output. The full
run (20 000 mutants) is `python3 bench/fuzz.py --runs 20000`."""

from __future__ import annotations

import importlib.util
import sys

from conftest import ROOT

spec = importlib.util.spec_from_file_location("synth_bench_fuzz", ROOT / "bench" / "fuzz.py")
assert spec is not None and spec.loader is not None
fuzz = importlib.util.module_from_spec(spec)
sys.modules["synth_bench_fuzz"] = fuzz
spec.loader.exec_module(fuzz)

LANGUAGES = ["rules", "g7", "filter", "xml", "st", "csv", "events", "home", "why"]


def test_a_seeded_slice_finds_nothing():
    tallies = fuzz.fuzz(runs=9 * 10, seed=38, timeout=10.0)
    assert list(tallies) == LANGUAGES
    assert [t.runs for t in tallies.values()] == [10] * 9
    findings = [f for t in tallies.values() for f in t.findings]
    assert findings == []
    # not vacuous: the mutants both pass and fail to read
    assert sum(t.codes.get(2, 0) for t in tallies.values()) > 40
    assert sum(t.codes.get(0, 0) for t in tallies.values()) > 5


def test_the_classifier_catches_what_it_counts():
    assert fuzz.classify(3, "synth: internal error: KeyError: 'x'\n", "") == "crash"
    assert fuzz.classify(2, "", "TypeError: boom") == "crash"
    assert fuzz.classify(None, "", "") == "slow"
    assert fuzz.classify(2, "x" * 70000, "") == "huge"
    assert fuzz.classify(2, "error: unknown variable 'x' in state\n", "") == "unlocated"
    assert fuzz.classify(2, "p.st:-1:-1: error: bad\n", "") == "unlocated"
    assert fuzz.classify(2, "a.rules:3:4: error: unknown variable 'x'\n", "") is None
    assert fuzz.classify(2, "error: cannot read 'x': No such file or directory\n", "") is None
    assert fuzz.classify(1, "", "") is None


def test_mutations_are_deterministic():
    import random

    a = fuzz.mutate("inputs a\noutputs o\n", random.Random(5), fuzz.TOKENS["filter"])
    b = fuzz.mutate("inputs a\noutputs o\n", random.Random(5), fuzz.TOKENS["filter"])
    assert a == b != "inputs a\noutputs o\n"


def test_notes_before_the_error_do_not_hide_its_location():
    err = "x.xml: note: POU P not imported\nx.xml:3:4: error: bad\n  3 | <a>\n    |    ^\n"
    assert fuzz.classify(2, err, "") is None
    assert fuzz.classify(2, "x.xml: note: POU P not imported\nerror: bad\n", "") == "unlocated"
