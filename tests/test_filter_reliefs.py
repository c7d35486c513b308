"""``keep`` and ``force`` spellings of one relief (issue 23, item 5): the loop algorithm reads
them alike, the algebraic synthesis may not; ``filter check`` warns, located at the relief."""

from __future__ import annotations


from synth.cli.main import main
from synth.filter.language_check import load_filter, parse_filter
from synth.filter.reliefs import SPELLING_SIZE, spelling_warnings

from conftest import ROOT


WITNESS_NOTE = ("  = note: `synth filter check --all-spellings` compares on every input and names every output it "
                "drives differently")


def test_the_four_cylinders_keep_reliefs_differ_from_their_force_spelling(capsys):
    """A point shows CSc1's spellings different: the warning gives it (the variables at 1)
    and what the other spelling does there; ``--all-spellings`` names every output."""
    path = ROOT / "plants/four_cylinders.filter"
    assert main(["filter", "check", str(path)]) in (0, 1)
    err = capsys.readouterr().err.splitlines()
    assert err[:5] == [
        f"{path}:45:34: warning: CSc1's relief `keep Q1` written `force Q2=0` gives another algebraic filter "
        "(it drives Q2 differently when only R_Q1, i1, R_Q2, h2, Q2^-1 are 1)",
        "  45 | safety CSc1: i1 & Q1 & Q2   keep Q1",
        "     |                                  ^~",
        "  = note: the algebraic filter uses `keep Q1`, as written; the loop algorithm reads either spelling as "
        "`force Q2=0`",
        WITNESS_NOTE]
    assert sum("warning:" in line for line in err) == 4
    assert main(["filter", "check", "--all-spellings", str(path)]) in (0, 1)
    err = capsys.readouterr().err.splitlines()
    assert err[0].endswith("gives another algebraic filter (it drives Q1, Q2, Q3, Q4 differently)")
    assert WITNESS_NOTE not in err and sum("warning:" in line for line in err) == 4


def test_a_force_relief_is_compared_with_its_keep_spelling():
    text = (ROOT / "plants/four_cylinders.filter").read_text().replace("keep Q1", "force Q2=0")
    f = parse_filter(text, "square.filter")
    first = spelling_warnings(f).warnings[0]
    assert first.message == ("CSc1's relief `force Q2=0` written `keep Q1` gives another algebraic filter "
                             "(it drives Q2 differently when only R_Q1, i1, R_Q2, h2, Q2^-1 are 1)")
    assert first.render().splitlines()[0].startswith("square.filter:45:35: warning:")  # at Q2=0
    assert spelling_warnings(f, limit=None).warnings[0].message.endswith("(it drives Q1, Q2, Q3, Q4 differently)")


def test_no_warning_where_the_spellings_agree_or_criteria_are_stated():
    assert spelling_warnings(parse_filter("inputs i\noutputs a, b\nsafety K: i & a & b keep a", "k.filter")).reports() == []
    assert spelling_warnings(load_filter(ROOT / "plants/tri.filter")).reports() == []  # explicit criteria: no priority criteria


def _syntheses(f):
    """The filter of ``f`` and, per relief with another spelling, the filter with that
    relief spelt the other way: each as one BDD (not the partitioned chain)."""
    import dataclasses

    from synth.filter.reliefs import _other
    from synth.filter.solve import synthesis

    base, others = synthesis(f, partitioned=False), {}
    for s in f.combined:
        other = _other(s) if s.has_priority else None
        if other is not None:
            t = dataclasses.replace(s, keep=other.keep, force=other.force)
            others[s.id] = synthesis(dataclasses.replace(f, safeties=tuple(t if u is s else u for u in f.safeties)),
                                     partitioned=False)
    return base, others


def _by_definition(f):
    """The warnings' definition: synthesise the filter with each relief spelt the other way
    and compare the care sets and each output's ``∃O.(S∧o)`` and ``∃O.(S∧!o)``, as texts (a
    function's cover is its own)."""
    def relation(s):
        e, outs = s.functions.engine, s.functions.outputs
        one = {o: e.text(e.exists(outs, s.admissible & e.var(o))) for o in f.outputs}
        zero = {o: e.text(e.exists(outs, s.admissible & ~e.var(o))) for o in f.outputs}
        return e.text(s.care), one, zero

    synthesised, others = _syntheses(f)
    base, found = relation(synthesised), []
    for name, other in others.items():
        alt = relation(other)
        if alt != base:
            found.append((name, [o for o in f.outputs if (base[1][o], base[2][o]) != (alt[1][o], alt[2][o])]
                          or list(f.outputs)))
    return found


def _at(s, ones):
    """Each output's (may be 1, may be 0) in synthesis ``s`` where exactly ``ones`` of what
    the filter reads are 1."""
    e = s.functions.engine
    point = {e.declare(n): n in ones for n in e.names if n not in s.functions.outputs}
    there = e.bdd.let(point, s.admissible)
    return {o: ((there & e.var(o)) != e.false, (there & ~e.var(o)) != e.false) for o in s.functions.outputs}


def _families():
    import sys

    sys.path.insert(0, str(ROOT / "bench"))
    from filter_scale import chain_filter, grid_filter, ring_filter

    return [ring_filter(4), chain_filter(6), grid_filter(8),
            (ROOT / "plants/four_cylinders.filter").read_text().replace("keep Q1", "force Q2=0")]


def test_the_warnings_follow_their_definition_on_the_bench_families():
    """``--all-spellings``: one chain, each other spelling run from the state before its
    criterion until it rejoins the chain; the same warnings as a synthesis per relief."""
    for n, text in enumerate(_families()):
        f = parse_filter(text, f"f{n}.filter")
        got = [(w.message.split("'")[0], w.message.split("it drives ")[1].split(" differently")[0].split(", "))
               for w in spelling_warnings(f, limit=None).reports()]
        assert got == _by_definition(f), n
        assert got  # every family has reliefs whose spellings differ


def test_the_points_witnesses_hold_on_the_syntheses():
    """The same reliefs warned as by definition (past a size limit of 1, some are listed
    instead); where a point shows the difference (the sparse points first, the others
    past the limit), the two syntheses evaluated there differ on exactly the outputs named."""
    witnessed = 0
    for n, text in enumerate(_families()):
        f = parse_filter(text, f"f{n}.filter")
        base, others = _syntheses(f)
        definition = dict(_by_definition(f))
        for limit in (SPELLING_SIZE, 1):
            found = spelling_warnings(f, limit=limit)
            warned = [w.message.split("'")[0] for w in found.warnings]
            if limit == SPELLING_SIZE:
                assert warned == list(definition) and not found.skipped, n
            assert set(warned) <= set(definition) <= set(warned) | {s.id for s in found.skipped}, n
            for w in found.warnings:
                name = w.message.split("'")[0]
                outputs = w.message.split("it drives ")[1].split(" differently")[0].split(", ")
                if " when " not in w.message:
                    assert outputs == definition[name]
                    continue
                witnessed += 1
                ones = w.message.split(" when only ")[1].split(" are 1)")[0].split(" is 1)")[0].split(", ") \
                    if " when only " in w.message else []
                mine, theirs = _at(base, ones), _at(others[name], ones)
                assert [o for o in f.outputs if mine[o] != theirs[o]] == outputs, w.message
                assert set(outputs) <= set(definition[name])
    assert witnessed >= 10


def test_past_the_limit_the_reliefs_left_are_tried_at_the_other_points():
    """On the chain of 6 outputs no sparse point shows a relief different: K1 is compared
    on every input (its spellings agree), the limit of 1 is then spent, and the points with
    the free variables at 1 (then random) show K2 and K4 (their witnesses made sparse)."""
    import sys

    sys.path.insert(0, str(ROOT / "bench"))
    from filter_scale import chain_filter

    found = spelling_warnings(parse_filter(chain_filter(6), "c.filter"), limit=1)
    assert [w.message.split(" gives another algebraic filter ")[1] for w in found.warnings] == [
        "(it drives o3 differently when only R_o1, R_o2, R_o3 are 1)",
        "(it drives o5 differently when only R_o3, R_o4, R_o5 are 1)"]
    assert [w.message.split("'")[0] for w in found.warnings] == ["K2", "K4"]
    assert [s.id for s in found.skipped] == ["K3", "K5"]


def test_past_the_work_limit_the_other_reliefs_are_listed_not_compared(capsys, monkeypatch):
    """Without points, the first relief is always compared; with no work left the others
    are named, located at the first of them, and ``--all-spellings`` lifts the limit."""
    from synth.filter import points

    monkeypatch.setattr(points, "POINT_DEFAULTS", ())
    monkeypatch.setattr(points, "POINT_ROUNDS", 0)
    f = load_filter(ROOT / "plants/four_cylinders.filter")
    found = spelling_warnings(f, limit=1)
    assert [w.message.split("'")[0] for w in found.warnings] == ["CSc1"]
    assert [s.id for s in found.skipped] == ["CSc2", "CSc3", "CSc4"]
    last = found.reports()[-1].render().splitlines()
    assert last[0].endswith(":46:34: warning: the keep/force spellings of 3 relief(s) (CSc2, CSc3, CSc4) were not "
                            "compared: over the size limit of the comparison (1 BDD nodes × variables)")
    assert last[-1] == "  = note: `synth filter check --all-spellings` compares them all, whatever it costs"
    assert spelling_warnings(f, limit=None).skipped == ()
    assert main(["filter", "check", "--all-spellings", str(ROOT / "plants/four_cylinders.filter")]) in (0, 1)
    assert sum("warning:" in line for line in capsys.readouterr().err.splitlines()) == 4


def test_a_relief_a_point_shows_is_warned_past_the_limit():
    """Points come before the size limit: on the four cylinders, two reliefs are shown at
    points and the other two compared on every input, one past a limit of 1."""
    found = spelling_warnings(load_filter(ROOT / "plants/four_cylinders.filter"), limit=1)
    assert [(w.message.split("'")[0], " when only " in w.message) for w in found.warnings] == [
        ("CSc1", True), ("CSc2", True), ("CSc3", False)]
    assert [s.id for s in found.skipped] == ["CSc4"]


def test_a_witness_gives_the_integer_observers_as_integers():
    """The palletizer's counter ``cpt : 0..3`` is two Boolean bits in the BDDs; the witness
    gives it (and ``cpt^-1``) as a value: with no layer on the pallet ``keep lift`` cannot
    lift and leaves the push requested, ``force push=0`` drops it all the same."""
    f = load_filter(ROOT / "tests/data/filter/palletizer.filter")
    (w,) = spelling_warnings(f).warnings
    assert w.message == ("BOTH's relief `keep lift` written `force push=0` gives another algebraic filter "
                         "(it drives push differently when only R_push, ready, R_lift are 1, cpt = 0, cpt^-1 = 0)")
    base, others = _syntheses(f)
    ones = ["R_push", "ready", "R_lift"]  # the bits of cpt and cpt^-1 at 0
    assert (_at(base, ones)["push"], _at(others["BOTH"], ones)["push"]) == ((True, False), (False, True))


def test_the_size_limit_is_read_on_the_filter(monkeypatch):
    """``SPELLING_SIZE`` counts, per relief compared on every input, the nodes of the chain's
    local relations from its criterion to the last times the variables its region reads:
    numbers of the filter and its chain (pinned here), not of the work the comparison does.
    Without points, the first relief is compared, then each while the sizes of those
    compared so far stay under the limit."""
    import dataclasses

    from synth.filter import points
    from synth.filter.reliefs import _other
    from synth.filter.spelling_chain import SpellingChain

    monkeypatch.setattr(points, "POINT_DEFAULTS", ())
    monkeypatch.setattr(points, "POINT_ROUNDS", 0)
    f = load_filter(ROOT / "plants/four_cylinders.filter")
    swapped = [(s, dataclasses.replace(s, keep=o.keep, force=o.force)) for s in f.combined for o in (_other(s),)]
    chain = SpellingChain(f, swapped)
    sizes = [chain.size(n) for n in range(4)]
    assert sizes == [83410, 81620, 83145, 68418]
    assert sizes[0] == sum(len(chain.p.local(s, k)) for s, k in zip(chain.states, chain.where)) * 19
    for limit, skipped in ((1, ["CSc2", "CSc3", "CSc4"]), (83409, ["CSc2", "CSc3", "CSc4"]),
                           (83410, ["CSc3", "CSc4"]), (165029, ["CSc3", "CSc4"]), (165030, ["CSc4"]),
                           (248175, [])):
        found = spelling_warnings(f, limit=limit)
        assert [s.id for s in found.skipped] == skipped, limit
        assert [w.message.split("'")[0] for w in found.warnings] == ["CSc1", "CSc2", "CSc3", "CSc4"][:4 - len(skipped)]
    assert [w.render() for w in found.reports()] == [w.render() for w in spelling_warnings(f, limit=None).reports()]
