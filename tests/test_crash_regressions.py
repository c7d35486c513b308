"""The crashes, unlocated errors and slow or hanging inputs a fuzzer found (issue 38), each from
its minimal input: a located message and exit 2, never a traceback, in bounded time and output."""

from __future__ import annotations

import os
import time

import pytest

from conftest import ROOT
from synth.errors import InputError, Location

TOGGLE = (ROOT / "tests/data/filter/toggle.st").read_text()
CYLINDER = """use "lib/single_acting.rules"
element V1 = single_acting(AVANCER=Q1, v0=v10, v1=v11)
constraint REST "push only from rest": ↑Q1 & !v10 = 0
"""
FILTER = 'inputs v10, v11\noutputs Q1\nsafety FROM_REST "push only from rest": ↑Q1 & !v10\n'


@pytest.fixture()
def loop(tmp_path):
    (tmp_path / "c.rules").write_text(CYLINDER)
    (tmp_path / "c.filter").write_text(FILTER)
    return tmp_path


def _verify(cli, d, program: str, name: str = "p.st"):
    (d / name).write_bytes(program.encode())
    return cli("filter", "verify", d / "c.filter", "--plant", d / "c.rules", "--control", d / name)


# ---------------------------------------------------------------- --home folding to a constant


@pytest.mark.parametrize("home", ["1", "X0 & 0", "0 | X1 & 0"])
@pytest.mark.parametrize("g7, rules", [("grafcets/tri.g7", "plants/tri.rules"),  # per situation (timers)
                                       ("tests/data/home/production_loop.g7", "tests/data/home/cylinder.rules")])  # steps
def test_constant_home_on_the_symbolic_engine(cli, g7, rules, home):
    explicit = cli("validate", ROOT / g7, "--plant", ROOT / rules, "--engine", "explicit", "--home", home)
    symbolic = cli("validate", ROOT / g7, "--plant", ROOT / rules, "--engine", "symbolic", "--home", home)
    assert explicit[0] in (0, 1)
    assert symbolic[:2] == explicit[:2]


# ---------------------------------------------------------------- bad ST given to --control


def test_stray_comment_end(cli, loop):
    code, out, err = _verify(cli, loop, TOGGLE.replace("Q1 := NOT Q1_prev;", "Q1 := NOT Q1_prev; *)"))
    assert (code, out) == (2, "")
    assert err == (f"{loop / 'p.st'}:14:20: error: '*)' closes no comment\n"
                   "  14 | Q1 := NOT Q1_prev; *)\n"
                   "     |                    ^\n"
                   "  = note: remove it, or open the comment with '(*'\n")


def test_comment_never_closed(cli, loop):
    code, _, err = _verify(cli, loop, "PROGRAM P\nVAR_OUTPUT Q1 : BOOL; END_VAR\nQ1 := (* open\n")
    assert code == 2
    assert err.splitlines()[0] == f"{loop / 'p.st'}:3:7: error: this comment is never closed"


def test_unknown_type_name(cli, loop):
    code, _, err = _verify(cli, loop, TOGGLE.replace("Q1_prev : BOOL;", "Q1_prev : BOOLX;"))
    assert code == 2
    assert err == (f"{loop / 'p.st'}:12:3: error: unknown type BOOLX\n"
                   "  12 |   Q1_prev : BOOLX;\n"
                   "     |   ^\n"
                   "  = did you mean BOOL?\n")


def test_crlf_line_ends_read_as_lf(cli, loop):
    lf = _verify(cli, loop, TOGGLE, "lf.st")
    crlf = _verify(cli, loop, TOGGLE.replace("\n", "\r\n"), "crlf.st")
    assert lf[0] == crlf[0] == 0
    import re

    def timeless(out: str) -> str:
        return re.sub(r" in \d+\.\d+ s", "", out)

    assert timeless(crlf[1]) == timeless(lf[1]).replace("lf.st", "crlf.st")


def test_st_syntax_error_at_the_end_is_located(cli, loop):
    code, _, err = _verify(cli, loop, "PROGRAM P\nVAR_OUTPUT Q1 : BOOL; END_VAR\nQ1 := TRUE;\n")
    assert code == 2
    assert err.splitlines()[:3] == [f"{loop / 'p.st'}:3:12: error: unexpected end of the text",
                                    "  3 | Q1 := TRUE;", "    |            ^"]
    assert ":-1" not in err


def test_a_line_of_20000_blanks_is_fast(cli, loop):
    start = time.monotonic()
    code, out, _ = _verify(cli, loop, TOGGLE.replace("Q1 := NOT Q1_prev;", "Q1 := NOT Q1_prev;\n" + " " * 20000))
    assert code == 0 and "safe:" in out
    assert time.monotonic() - start < 8  # was 15 s (quadratic in blark's scanner)


def test_a_long_run_of_blanks_inside_a_line_is_refused(cli, loop):
    start = time.monotonic()
    code, _, err = _verify(cli, loop, TOGGLE.replace("Q1 := NOT Q1_prev;", " " * 20000 + "Q1 := NOT Q1_prev;"))
    assert time.monotonic() - start < 8
    assert code == 2
    assert err.splitlines()[0] == (f"{loop / 'p.st'}:14:1: error: 20000 blanks in a row: more than the 1000 synth "
                                   "parses in a line of Structured Text")
    assert len(err) < 600


# ---------------------------------------------------------------- files


def test_long_use_path_in_a_filter_is_cannot_read(cli, tmp_path):
    f = tmp_path / "long.filter"
    f.write_text('use "' + "a" * 5000 + '.rules"\ninputs i\noutputs o\nsafety S: i & o\n')
    code, out, err = cli("filter", "check", f)
    assert (code, out) == (2, "")
    first = err.splitlines()[0]
    assert first.startswith(f"{f}:1:5: error: cannot read '{tmp_path}/aaa")
    assert first.endswith("…': File name too long")
    assert len(err) < 1200


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no named pipes here")
@pytest.mark.parametrize("kind", ["rules", "filter", "direct"])
def test_a_named_pipe_is_refused_not_waited_on(cli, tmp_path, kind):
    fifo = tmp_path / "pipe.rules"
    os.mkfifo(fifo)
    start = time.monotonic()
    if kind == "direct":
        code, _, err = cli("plant", fifo)
        assert err == f"error: cannot read '{fifo}': not a regular file\n"
    else:
        (tmp_path / f"u.{kind}").write_text(f'use "{fifo}"\n' + ("inputs i\noutputs o\nsafety S: i & o\n"
                                                               if kind == "filter" else ""))
        code, _, err = cli("filter" if kind == "filter" else "plant", *(["check"] if kind == "filter" else []),
                           tmp_path / f"u.{kind}")
        assert err.splitlines()[0] == f"{tmp_path / f'u.{kind}'}:1:5: error: cannot read '{fifo}': not a regular file"
    assert code == 2
    assert time.monotonic() - start < 5


# ---------------------------------------------------------------- PLCopen XML


def test_a_4300_digit_local_id(cli, tmp_path):
    text = (ROOT / "tests/data/plcopen/beremiz_counter.xml").read_text()
    big = "9" * 4300
    f = tmp_path / "big.xml"
    f.write_text(text.replace('localId="1"', f'localId="{big}"').replace('refLocalId="1"', f'refLocalId="{big}"'))
    code, out, err = cli("import", f)
    assert (code, out) == (2, "")
    assert err.splitlines()[0] == f"{f}:28:13: error: localId of 4300 digits: synth reads identifiers of at most 18"
    assert len(err) < 600


def test_an_infinite_coordinate(cli, tmp_path):
    text = (ROOT / "tests/data/plcopen/beremiz_counter.xml").read_text()
    f = tmp_path / "inf.xml"
    f.write_text(text.replace('<position x="285" y="120"/>', '<position x="1e400" y="120"/>', 1))
    code, _, err = cli("import", f)
    assert code == 2
    assert 'error: x="1e400" is not a coordinate (a finite number below 10^15)' in err.splitlines()[0]


def test_a_huge_attribute_gives_a_bounded_error(cli, tmp_path):
    text = (ROOT / "tests/data/plcopen/beremiz_counter.xml").read_text()
    f = tmp_path / "huge.xml"
    f.write_text(text.replace('name="counter"', 'name="' + "A" * (11 * 1024 * 1024) + '"', 1))
    code, out, err = cli("import", f)
    assert (code, out) == (2, "")
    assert len(err) < 1000  # was 60 MB for a 50 MB attribute
    line, caret = err.splitlines()[2:4]
    assert line.startswith("  4 | …AAAA") and line.endswith("A…")
    assert caret.index("^") == line.index("A") + 40  # the column, 40 characters into the window


def test_render_quotes_a_window_around_the_column():
    text = "x" * 5000 + "BAD" + "y" * 5000
    err = InputError("unknown name 'BAD'", Location("f", 1, 5001, text, 3))
    _, line, caret = err.render().splitlines()
    assert line == "  1 | …" + "x" * 40 + "BAD" + "y" * 77 + "…"
    assert caret == "    | " + " " * 41 + "^~~"
    short = InputError("m", Location("f", 2, 3, "abcdef", 2)).render().splitlines()
    assert short == ["f:2:3: error: m", "  2 | abcdef", "    |   ^~"]


def test_many_errors_are_capped(cli, tmp_path):
    """A span repeated 50 times gave 160 KB of "declared twice": the first 20, then a count."""
    f = tmp_path / "many.filter"
    f.write_text("inputs a, b, c, d\n" * 10 + "outputs o\nsafety S: a & o\n")
    code, _, err = cli("filter", "check", f)
    assert code == 2
    assert err.count("error: ") == 20
    assert err.endswith("\n\n… and 16 more errors\n")


def test_why_state_errors_are_located(cli):
    code, _, err = cli("sup", ROOT / "plants/tri_annex.rules", "--why", "TAPIS,v1O,v20")
    assert code == 2
    assert err.splitlines()[:3] == ["--why:1:7: error: unknown variable 'v1O' in the state",
                                    "  1 | TAPIS,v1O,v20", "    |       ^~~"]


def test_a_pou_variable_without_a_name(cli, tmp_path):
    """From the full fuzz run: `<variable nam="LAMP">` in an interface was an AttributeError."""
    text = (ROOT / "tests/data/plcopen/beremiz_tc6_1_0.xml").read_text()
    f = tmp_path / "noname.xml"
    f.write_text(text.replace('<variable name="LAMP">', '<variable nam="LAMP">', 1))
    code, out, err = cli("import", f)
    assert (code, out) == (2, "")
    assert err.splitlines()[0] == f"{f}:22:13: error: a variable of POU lamp's interface has no name"
