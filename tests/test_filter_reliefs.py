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
        "(the equations of Q1, Q2 differ)",
        "  45 | safety CSc1: i1 & Q1 & Q2   keep Q1",
        "     |                                  ^~",
        "  = note: the algebraic filter uses `keep Q1`, as written; the loop algorithm reads either spelling as "
        "`force Q2=0`"]
    assert sum("warning:" in line for line in err) == 4


def test_a_force_relief_is_compared_with_its_keep_spelling():
    text = (ROOT / "plants/four_cylinders.filter").read_text().replace("keep Q1", "force Q2=0")
    f = parse_filter(text, "square.filter")
    first = spelling_warnings(f)[0]
    assert first.message == ("CSc1's relief `force Q2=0` written `keep Q1` gives another algebraic filter "
                             "(the equations of Q1, Q2 differ)")
    assert first.render().splitlines()[0].startswith("square.filter:45:35: warning:")  # at Q2=0


def test_no_warning_where_the_spellings_agree_or_criteria_are_stated():
    assert spelling_warnings(parse_filter("inputs i\noutputs a, b\nsafety K: i & a & b keep a", "k.filter")) == []
    assert spelling_warnings(load_filter(ROOT / "plants/tri.filter")) == []  # explicit criteria: no priority criteria
