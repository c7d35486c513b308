"""Internal variables of the Grafcet language (docs/grafcet.md, "Internal variables"):
declarations, assignments, comparisons, their evolution, both validation engines, ST and SFC."""

from __future__ import annotations

import json
import random
import sys
from pathlib import Path

import pytest

from synth.errors import InputError, InputErrors, SynthError
from synth.grafcet.ass import stable_situation_automaton
from synth.grafcet.language_check import parse_grafcet
from synth.grafcet.machine import GrafcetMachine
from synth.grafcet.situation import OutOfRange
from synth.output.result import validation_json, validation_text
from synth.plant.composition import plant
from synth.plant.rules_check import parse_rules
from synth.symbolic.validate import validate_symbolic
from synth.validation.validate import validate

from conftest import ROOT

sys.path.insert(0, str(ROOT / "tests"))
from randgrafcet import check_seed  # noqa: E402
from randrules import random_rules  # noqa: E402

COUNTING = """\
internal cnt : 0..3 = 0
grafcet G {
  initial step 0
  step 1: cnt := cnt + 1
  step 2: EVAC, cnt := 0 on deactivation
  transition 0 -> 1 when ↑box
  transition 1 -> 0 when cnt < 3
  transition 1 -> 2 when cnt >= 3
  transition 2 -> 0 when done
}
"""


def errors(text: str) -> list[str]:
    with pytest.raises(InputErrors) as info:
        parse_grafcet(text, "g.g7")
    return [e.render().splitlines()[0] + " | " + " ".join(e.suggestions) for e in info.value.errors]


def test_declarations_and_actions_are_read():
    g = parse_grafcet("internal cnt : 0..3\ninternal busy\ninternal lvl : -2..2 = -1\n"
                      "grafcet G { initial step 0: set busy, cnt := cnt - 1 on ↑a\n step 1: reset busy on deactivation\n"
                      " transition 0 -> 1 when cnt <> 2 & busy & lvl >= -1\n transition 1 -> 0 when !busy }", "g.g7")
    assert [v.text() for v in g.internals] == ["internal cnt : 0..3 = 0", "internal busy : bool = 0",
                                              "internal lvl : -2..2 = -1"]
    assert g.inputs == ("a",) and g.outputs == ()
    assert [a.text() for s in g.steps for a in s.actions] == [
        "busy := 1 on activation", "cnt := cnt - 1 on ↑a", "busy := 0 on deactivation"]
    assert g.transitions[0].receptivity.text() == "cnt <> 2 & busy & lvl >= -1"


def test_located_errors_name_what_was_meant():
    assert errors("internal cnt : 3..1\ninternal cnt : 0..1\ninternal X0 : bool\ninternal k : 0..2 = 5\n"
                  "grafcet G { initial step 0: cnt := cnt + tru\n step 1: k\n"
                  " transition 0 -> 1 when cnd >= 1 & k\n transition 1 -> 0 when ↑k }") == [
        "g.g7:1:16: error: the range 3..1 of 'cnt' is empty | ",
        "g.g7:2:10: error: internal variable 'cnt' is declared twice | ",
        "g.g7:3:10: error: internal variable 'X0' has the name of the variable of step 0 | ",
        "g.g7:4:21: error: the initial value 5 of 'k' is outside its range 0..2 | ",
        "g.g7:7:25: error: unknown internal variable 'cnd' in the comparison cnd >= 1 | cnt",
        "g.g7:7:36: error: 'k' is an integer (0..2): compare it, e.g. k >= 1 | ",
        "g.g7:8:26: error: edges of internal variables are not supported: ↑k | ",
        "g.g7:5:36: error: unknown internal variable 'tru' in the assignment to cnt | ",
        "g.g7:6:10: error: internal variable 'k' is changed by assignments only | ",
    ]


def test_counting_evolves_and_its_ass_lists_every_value():
    m = GrafcetMachine(parse_grafcet(COUNTING, "counting.g7"))
    ass = stable_situation_automaton(m)
    assert [(s.situation.text(), s.orders) for s in ass.states] == [
        ("{X0} cnt=0", ()), ("{X0} cnt=1", ()), ("{X0} cnt=2", ()), ("{X2} cnt=3", ("EVAC",))]
    assert [(t.source, t.event, t.condition, t.target) for t in ass.transitions] == [
        (0, "↑box", "any", 1), (1, "↑box", "any", 2), (2, "↑box", "done", 0), (2, "↑box", "!done", 3),
        (3, "↑done", "any", 0)]


def test_assignments_of_a_phase_are_simultaneous_and_the_last_wins():
    g = parse_grafcet("internal a : 0..3 = 1\ninternal b : 0..3 = 2\n"
                      "grafcet G { initial step 0 step 1: a := b, b := a step 2: a := 3\n"
                      " step 3: a := 0 transition 0 -> 1, 3 when ↑x transition 1 -> 2 when ↑y }", "g.g7")
    m = GrafcetMachine(g)
    s0 = m.initial({"x": False, "y": False})
    s1 = m.react(s0, {"x": False, "y": False}, {"x": True, "y": False})
    assert s1.text() == "{X1, X3} a=0 b=1"  # a := b and b := a swap; step 3's a := 0 comes after step 1's
    assert m.react(s1, {"x": True, "y": False}, {"x": True, "y": True}).text() == "{X2, X3} a=3 b=1"


def test_out_of_range_in_run_and_validate_exits_1_with_the_trace(cli, tmp_path):
    (tmp_path / "ov.g7").write_text("internal cnt : 0..1\ngrafcet G { initial step 0 step 1: cnt := cnt + 1\n"
                                    " transition 0 -> 1 when ↑a\n transition 1 -> 0 when ↓a }\n")
    code, out, err = cli("run", tmp_path / "ov.g7", "--events", "↑a,↓a,↑a")
    assert code == 1 and out == ""
    assert err.splitlines()[0].endswith("ov.g7:2:36: error: cnt := cnt + 1 gives 2, outside the range 0..1 of 'cnt'")
    assert err.splitlines()[-2:] == ["  = note: in situation {X1} cnt=1", "  = note: trace: ↑a ↓a ↑a"]
    small = (ROOT / "grafcets/tri_counting.g7").read_text().replace("boxes : 0..3", "boxes : 0..2")
    (tmp_path / "small.g7").write_text(small)
    outs = [cli("validate", tmp_path / "small.g7", "--plant", ROOT / "plants/tri.rules", "--engine", e)
            for e in ("explicit", "symbolic")]
    assert outs[0] == outs[1] and outs[0][0] == 1
    assert "gives 3, outside the range 0..2 of 'boxes'" in outs[0][2]
    assert outs[0][2].splitlines()[-1] == "  = note: trace: " + " ".join(
        ["↑dcy"] + ["↑cp11 2s/X111 ↓v10 ↑v11 ↓v11 ↑v10 ↓v30 ↑v31 ↓v31 ↑v30"] + 2 * ["↓cp11 ↑cp11 2s/X111 ↓v10 ↑v11 ↓v11 ↑v10 ↓v30 ↑v31 ↓v31 ↑v30"])


def test_the_counting_box_sorting_validates_identically_with_both_engines():
    g7, rules = ROOT / "grafcets/tri_counting.g7", ROOT / "plants/tri.rules"
    a, b = validate(g7, rules), validate_symbolic(g7, rules)
    assert a.passed and b.passed
    assert validation_text(a) == validation_text(b)
    assert json.dumps(validation_json(a)) == json.dumps(validation_json(b))
    assert (a.stats["sync_states"], a.stats["aggregated_states"], a.stats["aggregated_transitions"]) == (451, 271, 841)
    assert len({n.situation for n in a.sync.nodes}) == 46


def test_the_counting_box_sorting_st_passes_st_check(cli):
    pytest.importorskip("blark")
    code, out, _ = cli("st", "--check", ROOT / "grafcets/tri_counting.g7", "--plant", ROOT / "plants/tri.rules")
    assert code == 0 and out.endswith(": 0 mismatches\n")


def _data_programs(seeds: range) -> list[tuple[int, int, int, str]]:
    pytest.importorskip("blark")
    results = [check_seed(seed, 3, data=True) for seed in seeds]
    assert [r[3] for r in results if r[3]] == []
    return results


def test_random_grafcets_with_data_st_equals_synth_run():
    assert sum(r[2] for r in _data_programs(range(5))) > 80


@pytest.mark.nightly
def test_random_grafcets_with_data_st_equals_synth_run_nightly():
    assert sum(r[2] for r in _data_programs(range(5, 300))) > 5000


def _random_data_grafcet(seed: int, inputs: list[str], outputs: list[str]) -> str:
    """tests/test_symbolic.py's random Grafcet, counting in ``k : 0..1``: assignments added to
    some steps, comparisons of ``k`` to some receptivities."""
    from test_symbolic import random_grafcet

    rng = random.Random(seed)
    lines = ["internal k : 0..1"]
    for line in random_grafcet(seed, inputs, outputs).splitlines():
        if line.startswith("  step ") and rng.random() < 0.5:
            act = rng.choice(("k := k + 1", "k := 0 on deactivation", "k := k - 1", "k := 1 on ↑go"))
            line += (", " if ":" in line else ": ") + act
        elif line.startswith("  transition ") and rng.random() < 0.4:
            line += " & " + rng.choice(("k = 0", "k >= 1", "k <> 1"))
        lines.append(line)
    return "\n".join(lines) + "\n"


def _outcome(engine, folder: Path, homes: tuple[str, ...] = ()) -> tuple[str, str]:
    try:
        v = engine(folder / "g.g7", folder / "r.rules", homes=homes)
        return validation_text(v), json.dumps(validation_json(v))
    except OutOfRange:
        return "out of range", ""
    except SynthError as e:
        return type(e).__name__, str(e).splitlines()[0]


def _write_case(seed: int, folder: Path) -> None:
    rules = random_rules(seed) + "free go = 0\n"
    p = plant(parse_rules(rules))
    (folder / "r.rules").write_text(rules)
    (folder / "g.g7").write_text(_random_data_grafcet(seed, [v for v in p.inputs if v != "go"] or ["go"],
                                                      list(p.outputs)))


@pytest.mark.parametrize("seed", range(30))
def test_random_plants_with_counting_grafcets_identical(seed, tmp_path):
    _write_case(seed, tmp_path)
    homes = ("X0",) if seed % 2 else ()
    assert _outcome(validate, tmp_path, homes) == _outcome(validate_symbolic, tmp_path, homes)


def test_random_counting_cases_are_not_trivial(tmp_path):
    """The cases above meet passing and failing models and assignments out of range."""
    kinds = []
    for seed in range(30):
        _write_case(seed, tmp_path)
        kinds.append(_outcome(validate, tmp_path, ("X0",) if seed % 2 else ())[0].split(":")[0])
    assert kinds.count("PASS") >= 1 and kinds.count("FAIL") >= 5 and kinds.count("out of range") >= 2, kinds


def test_a_boolean_takes_an_expression_of_boolean_internal_variables(cli, tmp_path):
    text = ("internal p : bool\ninternal q : bool = 1\ngrafcet G { initial step 0\n"
            " step 1: p := (q & !p | !q & p), q := (!q)\n transition 0 -> 1 when ↑a\n transition 1 -> 0 when ↓a }\n")
    (tmp_path / "b.g7").write_text(text)
    code, out, _ = cli("run", tmp_path / "b.g7", "--events", "↑a,↓a,↑a,↓a,↑a")
    assert code == 0 and [line.split()[3:5] for line in out.splitlines()] == [
        ["p=0", "q=1"], ["p=1", "q=0"], ["p=1", "q=0"], ["p=1", "q=1"], ["p=1", "q=1"], ["p=0", "q=0"]]
    assert "IF _Enter[2] THEN _Next_p := q AND NOT p OR NOT q AND p; END_IF;" in cli("st", tmp_path / "b.g7")[1]
    pytest.importorskip("blark")
    assert cli("st", "--check", "--depth", "6", tmp_path / "b.g7")[0] == 0
    assert errors("internal k : 0..3\ninternal b : bool\ngrafcet G { initial step 0: k := (b), b := (↑x & b) }") == [
        "g.g7:3:29: error: 'k' is an integer: assign a sum such as k + 1, not a Boolean expression | ",
        "g.g7:3:39: error: unknown internal variable 'x' in the assignment to b | ",
        "g.g7:3:46: error: an edge in the assignment to b: ↑x | ",
    ]


def test_import_reads_a_boolean_expression_and_refuses_a_sequential_read():
    from synth.codegen.plcopen.importer import import_sfc

    xml = (ROOT / "tests/data/plcopen/beremiz_counter.xml").read_text()
    xml = xml.replace('<variable name="Cnt"><type><INT/></type></variable>',
                      '<variable name="A"><type><BOOL/></type></variable><variable name="B"><type><BOOL/></type></variable>')
    body = xml.replace("Cnt := Cnt + 1;", "A := B XOR A; B := NOT B;").replace("Cnt := 0;", "A := FALSE;")
    body = body.replace("NOT go AND 3 <= Cnt", "NOT go AND A").replace("NOT go AND Cnt < 3", "NOT go AND NOT A")
    text = import_sfc(body.encode(), "x.xml")
    assert "  step Count: A := (B & !A | !B & A), B := (!B)\n" in text
    with pytest.raises(InputError) as info:
        import_sfc(body.replace("A := B XOR A; B := NOT B;", "B := NOT B; A := B XOR A;").encode(), "x.xml")
    assert info.value.render().splitlines()[0] == (
        "x.xml:66:51: error: A := … in action P1 (inline) reads B, assigned before it in the same body: the PLC runs "
        "the statements in sequence, .g7 the assignments of a phase at once (each reads the values before the phase)")
