"""The ST interpreter on blark's tree: each construct of the subset, timers, errors."""

from __future__ import annotations

import pytest

from synth.codegen.interpreter.runtime import Array
from synth.codegen.interpreter.machine import load_st
from synth.errors import InputError

PROGRAM = """
FUNCTION_BLOCK FB_Count
VAR_INPUT
    go : BOOL;
END_VAR
VAR_OUTPUT
    n : INT;
    big : BOOL;
END_VAR
IF go THEN
    n := n + 1;
END_IF;
big := n >= 3;
END_FUNCTION_BLOCK

PROGRAM Main
VAR
    start, stop : BOOL;
    lamp : BOOL;
    t1 : TON;
    edge : R_TRIG;
    fall : F_TRIG;
    counter : FB_Count;
    count : INT;
    large : BOOL;
    mask : ARRAY[1..2, 1..3] OF BOOL := [TRUE, FALSE, TRUE, 3(FALSE)];
    row : ARRAY[1..3] OF BOOL;
    i, loops, sum : INT;
    up : BOOL;
    down : BOOL;
END_VAR
edge(CLK := start);
fall(CLK := start);
up := edge.Q;
down := fall.Q;
t1(IN := start AND NOT stop, PT := T#1s500ms);
lamp := t1.Q;
counter(go := up, n => count, big => large);
FOR i := 1 TO 3 DO
    row[i] := mask[1, i] XOR mask[2, i];
END_FOR;
loops := 0;
sum := 0;
WHILE TRUE DO
    loops := loops + 1;
    IF loops > 4 THEN
        EXIT;
    END_IF;
    sum := sum + loops MOD 3;
END_WHILE;
END_PROGRAM
"""


@pytest.fixture(scope="module")
def module():
    return load_st(PROGRAM, "main.st")


def test_timer_edge_counter_and_loops(module) -> None:
    main = module.instance("Main")
    main.cycle({"start": True})
    assert (main["up"], main["down"], main["lamp"], main["count"], main["large"]) == (True, False, False, 1, False)
    module.advance(1499)
    main.cycle()
    assert (main["up"], main["lamp"], main["t1"]["ET"]) == (False, False, 1499)
    module.advance(1)
    main.cycle()
    assert main["lamp"] is True and main["t1"]["ET"] == 1500
    main.cycle({"start": False})
    assert (main["down"], main["lamp"], main["t1"]["ET"]) == (True, False, 0)
    for _ in range(2):
        main.cycle({"start": True})
        main.cycle({"start": False})
    assert (main["count"], main["large"]) == (3, True)
    assert main["row"] == Array(((1, 3),), [True, False, True])
    # 1 MOD 3 + 2 MOD 3 + 3 MOD 3 + 4 MOD 3, exit at 5
    assert (main["loops"], main["sum"]) == (5, 4)


def test_instances_are_independent(module) -> None:
    a, b = module.instance("FB_Count"), module.instance("FB_Count")
    a.cycle({"go": True})
    assert (a["n"], b["n"]) == (1, 0)
    assert "N" in a and a["N"] == 1  # names are case-insensitive


def test_f_trig_follows_the_standard_on_its_first_call(module) -> None:
    fall = module.instance("F_TRIG")
    # IEC 61131-3: Q := NOT CLK AND NOT M; M := NOT CLK, with M = FALSE at start
    assert fall.cycle({"CLK": False})["Q"] is True
    assert fall.cycle({"CLK": False})["Q"] is False
    assert fall.cycle({"CLK": True})["Q"] is False
    assert fall.cycle({"CLK": False})["Q"] is True


def test_syntax_error_is_located() -> None:
    with pytest.raises(InputError) as e:
        load_st("PROGRAM P\nVAR x : BOOL; END_VAR\nx := x AND ;\nEND_PROGRAM\n", "bad.st")
    assert str(e.value.location) == "bad.st:3:12"
    assert "x := x AND ;" in e.value.render()


def test_construct_outside_the_subset_is_located() -> None:
    text = "PROGRAM P\nVAR x : INT; END_VAR\nCASE x OF\n1: x := 2;\nEND_CASE;\nEND_PROGRAM\n"
    with pytest.raises(InputError) as e:
        load_st(text, "case.st")
    assert str(e.value.location) == "case.st:3:1"
    assert e.value.message == "CaseStatement is outside the subset synth executes"


def test_unknown_variable_is_reported_where_it_is_read() -> None:
    m = load_st("PROGRAM P\nVAR x : BOOL; END_VAR\nx := y;\nEND_PROGRAM\n", "u.st")
    with pytest.raises(InputError) as e:
        m.instance("P").cycle()
    assert (str(e.value.location), e.value.message) == ("u.st:3:6", "unknown variable y")


@pytest.mark.parametrize(("text", "where", "message"), [
    ("PROGRAM P\nVAR x : INT; END_VAR\nx := 16#FF;\nEND_PROGRAM\n",
     "n.st:3:6", "HexInteger is outside the subset synth executes"),  # a subclass of Integer is not Integer
    ("PROGRAM P\nVAR x : REAL; END_VAR\nx := 1.5;\nEND_PROGRAM\n",
     "n.st:3:6", "Real is outside the subset synth executes"),
    ("PROGRAM P\nVAR_EXTERNAL x : INT; END_VAR\nx := 1;\nEND_PROGRAM\n",
     "n.st:2:1", "ExternalVariableDeclarations is outside the subset synth executes"),
    ("PROGRAM P\nEND_PROGRAM\nFUNCTION F : INT\nF := 1;\nEND_FUNCTION\n",
     "n.st:3:1", "Function is outside the subset synth executes (PROGRAM, FUNCTION_BLOCK)"),
])
def test_node_types_outside_the_subset_are_located(text: str, where: str, message: str) -> None:
    with pytest.raises(InputError) as e:
        load_st(text, "n.st")
    assert (str(e.value.location), e.value.message) == (where, message)


def test_var_temp_is_initialised_again_at_every_call() -> None:
    """IEC 61131-3: a VAR_TEMP keeps nothing between calls (MATIEC's iec2c sets it at the
    start of every call); a VAR keeps its value."""
    from synth.codegen.interpreter.machine import load_st

    m = load_st("PROGRAM P\nVAR_INPUT a : BOOL; END_VAR\nVAR n : INT; END_VAR\nVAR_TEMP r : INT := 2; "
                "f : ARRAY[1..2] OF BOOL; END_VAR\nr := r + 1;\nIF a THEN f[1] := TRUE; END_IF;\n"
                "IF f[1] THEN n := n + 10; END_IF;\nn := n + r;\nEND_PROGRAM\n", "t.st")
    p = m.instance("P")
    seen = [(p.cycle({"a": a})["n"], p["r"]) for a in (True, False, False)]
    assert seen == [(13, 3), (16, 3), (19, 3)]
