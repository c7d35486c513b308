"""``keep`` and ``force`` spellings of one relief (issue 23, item 5): the loop algorithm reads
them alike, the algebraic synthesis may not; ``filter check`` warns, located at the relief."""

from __future__ import annotations

from pathlib import Path

from synth.cli.main import main
from synth.filter.language_check import load_filter, parse_filter
from synth.filter.reliefs import spelling_warnings

ROOT = Path(__file__).resolve().parent.parent


def test_the_four_cylinders_keep_reliefs_differ_from_their_force_spelling(capsys):
    assert main(["filter", "check", str(ROOT / "plants/four_cylinders.filter")]) in (0, 1)
    err = capsys.readouterr().err.splitlines()
    path = ROOT / "plants/four_cylinders.filter"
    assert err[:4] == [
        f"{path}:45:34: warning: CSc1's relief `keep Q1` written `force Q2=0` gives another algebraic filter "
        "(it drives Q1, Q2, Q3, Q4 differently)",
        "  45 | safety CSc1: i1 & Q1 & Q2   keep Q1",
        "     |                                  ^~",
        "  = note: the algebraic filter uses `keep Q1`, as written; the loop algorithm reads either spelling as "
        "`force Q2=0`"]
    assert sum("warning:" in line for line in err) == 4


def test_a_force_relief_is_compared_with_its_keep_spelling():
    text = (ROOT / "plants/four_cylinders.filter").read_text().replace("keep Q1", "force Q2=0")
    f = parse_filter(text, "square.filter")
    first = spelling_warnings(f).warnings[0]
    assert first.message == ("CSc1's relief `force Q2=0` written `keep Q1` gives another algebraic filter "
                             "(it drives Q1, Q2, Q3, Q4 differently)")
    assert first.render().splitlines()[0].startswith("square.filter:45:35: warning:")  # at Q2=0


def test_no_warning_where_the_spellings_agree_or_criteria_are_stated():
    assert spelling_warnings(parse_filter("inputs i\noutputs a, b\nsafety K: i & a & b keep a", "k.filter")).reports() == []
    assert spelling_warnings(load_filter(ROOT / "plants/tri.filter")).reports() == []  # explicit criteria: no priority criteria


def _by_definition(f):
    """The warnings' definition: synthesise the filter with each relief spelt the other way,
    on one BDD (not the partitioned chain), and compare the care sets and each output's
    ``∃O.(S∧o)`` and ``∃O.(S∧!o)``, as texts (a function's cover is its own)."""
    import dataclasses

    from synth.filter.reliefs import _other
    from synth.filter.solve import synthesis

    def relation(g):
        s = synthesis(g, partitioned=False)
        e, outs = s.functions.engine, s.functions.outputs
        one = {o: e.text(e.exists(outs, s.admissible & e.var(o))) for o in g.outputs}
        zero = {o: e.text(e.exists(outs, s.admissible & ~e.var(o))) for o in g.outputs}
        return e.text(s.care), one, zero

    base, found = relation(f), []
    for s in f.combined:
        other = _other(s) if s.has_priority else None
        if other is None:
            continue
        t = dataclasses.replace(s, keep=other.keep, force=other.force)
        alt = relation(dataclasses.replace(f, safeties=tuple(t if u is s else u for u in f.safeties)))
        if alt != base:
            found.append((s.id, [o for o in f.outputs if (base[1][o], base[2][o]) != (alt[1][o], alt[2][o])]
                          or list(f.outputs)))
    return found


def test_the_warnings_follow_their_definition_on_the_bench_families():
    """One chain, each other spelling run from the state before its criterion until it
    rejoins the chain: the same warnings as a synthesis per relief."""
    import sys

    sys.path.insert(0, str(ROOT / "bench"))
    from filter_scale import chain_filter, grid_filter, ring_filter

    texts = [ring_filter(4), chain_filter(6), grid_filter(8),
             (ROOT / "plants/four_cylinders.filter").read_text().replace("keep Q1", "force Q2=0")]
    for n, text in enumerate(texts):
        f = parse_filter(text, f"f{n}.filter")
        got = [(w.message.split("'")[0], w.message.split("it drives ")[1].split(" differently")[0].split(", "))
               for w in spelling_warnings(f).reports()]
        assert got == _by_definition(f), n
        assert got  # every family has reliefs whose spellings differ


def test_past_the_work_limit_the_other_reliefs_are_listed_not_compared(capsys):
    """The first relief is always compared; with no work left the others are named, located
    at the first of them, and ``--all-spellings`` lifts the limit."""
    f = load_filter(ROOT / "plants/four_cylinders.filter")
    found = spelling_warnings(f, limit=1)
    assert [w.message.split("'")[0] for w in found.warnings] == ["CSc1"]
    assert [s.id for s in found.skipped] == ["CSc2", "CSc3", "CSc4"]
    last = found.reports()[-1].render().splitlines()
    assert last[0].endswith(":46:34: warning: the keep/force spellings of 3 relief(s) from CSc2 on were not compared: "
                            "over the work limit of the comparison (1 BDD steps)")
    assert last[-1] == "  = note: `synth filter check --all-spellings` compares them all, whatever it costs"
    assert spelling_warnings(f, limit=None).skipped == ()
    assert main(["filter", "check", "--all-spellings", str(ROOT / "plants/four_cylinders.filter")]) in (0, 1)
    assert sum("warning:" in line for line in capsys.readouterr().err.splitlines()) == 4
