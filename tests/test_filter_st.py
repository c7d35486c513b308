"""``synth filter st``: run by the ST interpreter, the block computes what ``solve`` computed
(algebraic) or the corrected loop of docs/filter.md (loop). That blark parses every bundled filter's
blocks is the business of ``test_filter_deployed.py``."""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from synth.cli.main import main
from synth.codegen.filter_st import filter_block
from synth.codegen.interpreter.machine import load_st
from synth.errors import InputError, ModelError
from synth.logic.past import pre_name
from synth.filter.language_check import load_filter, parse_filter
from synth.filter.solve import requested, synthesis
from st_blocks import interpreted

from conftest import ROOT


def _reference_cycle(s, f, point: dict[str, bool]) -> dict[str, bool]:
    """The synthesised outputs as BDD functions evaluated at one point (Y, R, past values)."""
    e = s.functions.engine
    return {o: e.value(s.output(o), {n: point.get(n, False) for n in e.support(s.output(o))}) for o in f.outputs}


def _random_run(f, fb, cycles: int, seed: int, blocking: bool = False):
    """Drive the interpreted block and the reference with the same random inputs; yield
    (cycle, interpreted outputs, reference outputs)."""
    rnd = random.Random(seed)
    s = synthesis(f)
    e = s.functions.engine
    care = s.care
    past: dict[str, bool] = {}
    blocked = False
    raw = [e.expr(requested(c.expr, f.outputs)) for c in f.safeties]
    for n in range(cycles):
        y = {x: rnd.random() < 0.5 for x in (*f.inputs, *f.observer_names)}
        r = {req: rnd.random() < 0.6 for req in f.requests}
        ack = rnd.random() < 0.2
        point = {**y, **r, **{pre_name(x): past.get(x, False) for x in (*f.inputs, *f.observer_names, *f.outputs)}}
        for d in f.observers:  # `observer P := EXPR`: the block computes it, from the raw requests
            if d.definition is not None:
                x = e.expr(d.definition)
                y[d.name] = point[d.name] = e.value(x, {v: point.get(v, False) for v in e.support(x)})
        if blocking:
            if ack:
                blocked = False
            if any(e.value(u, {v: point.get(v, False) for v in e.support(u)}) for u in raw):
                blocked = True
            point.update({req: point[req] and not blocked for req in f.requests})
        fb.cycle({**y, **r, **({"Ack": ack} if blocking else {})})
        past.update(y)
        if not e.value(care, {v: point.get(v, False) for v in e.support(care)}):
            past.update({o: fb[o] for o in f.outputs})  # outside the care set the equations promise nothing
            continue
        expected = _reference_cycle(s, f, point)
        got = {o: fb[o] for o in f.outputs}
        yield n, got, expected
        past.update(got)


@pytest.mark.parametrize("name", ["tri", "tri_printed30", "seed004_eq13", "seed004_eq22", "four_cylinders", "loop_b"])
@pytest.mark.parametrize("mode", ["supervisor", "blocking"])
def test_algebraic_block_computes_the_synthesised_equations(name: str, mode: str) -> None:
    f = load_filter(ROOT / "plants" / f"{name}.filter")
    block, module = interpreted(name, "algebraic", mode)
    fb = module.instance(block.name)
    compared = 0
    for n, got, expected in _random_run(f, fb, 300, seed=len(name), blocking=mode == "blocking"):
        assert got == expected, f"cycle {n}"
        compared += 1
    assert compared >= 100


def test_a_flipped_operator_in_the_block_is_caught() -> None:
    f = load_filter(ROOT / "plants" / "tri.filter")
    block = filter_block(f, "algebraic")
    broken = block.text.replace("A0 := R_A0 AND NOT P01", "A0 := R_A0 OR NOT P01", 1)
    assert broken != block.text
    fb = load_st(broken, "broken.st").instance(block.name)
    assert any(got != expected for _, got, expected in _random_run(f, fb, 200, seed=1))


def _loop_outputs(name: str, requests: tuple[int, ...], mode: str = "supervisor") -> tuple[tuple[int, ...], bool]:
    f = load_filter(ROOT / "plants" / f"{name}.filter")
    block, module = interpreted(name, "loop", mode)
    fb = module.instance(block.name)
    fb.cycle({f"R_{o}": bool(v) for o, v in zip(f.outputs, requests)})
    return tuple(int(fb[o]) for o in f.outputs), fb["Fallback"]


def test_loop_examples_give_the_corrected_results() -> None:
    # docs/filter.md, "The correction loop"
    assert _loop_outputs("loop_a", (1, 1)) == ((1, 0), False)  # the literal published code: (0,0)
    assert _loop_outputs("loop_b", (1, 1, 1)) == ((1, 0, 0), False)  # literal: oscillates, then (0,0,0)
    assert _loop_outputs("loop_c", (1, 1, 1)) == ((0, 0, 0), True)  # a GO cycle: fallback
    assert _loop_outputs("loop_no_cycle", (1, 1)) == ((0, 0), False)


def test_loop_bounds_its_iterations_to_ncsc_plus_one() -> None:
    f = load_filter(ROOT / "plants" / "loop_c.filter")
    block = filter_block(f, "loop")
    fb = load_st(block.text, "c.st").instance(block.name)
    fb.cycle({"R_o1": True, "R_o2": True, "R_o3": True})
    assert fb["Cpt"] == len(f.combined) + 1


def test_blocking_mode_latches_until_ack() -> None:
    f = parse_filter("inputs i\noutputs o, p\nsafety S: i & o\nsafety K: o & p keep o", "b.filter")
    block = filter_block(f, "loop", "blocking")
    fb = load_st(block.text, "b.st").instance(block.name)
    steps = [({"i": False, "R_o": True, "R_p": False, "Ack": False}, (1, 0, False)),
             ({"i": True, "R_o": True, "R_p": False, "Ack": False}, (0, 0, True)),   # S violated by the request
             ({"i": False, "R_o": True, "R_p": False, "Ack": False}, (0, 0, True)),  # latched
             ({"i": False, "R_o": True, "R_p": False, "Ack": True}, (1, 0, False)),  # acknowledged
             ({"i": False, "R_o": True, "R_p": True, "Ack": False}, (0, 0, True))]   # K violated
    for n, (inputs, (o, p, blocked)) in enumerate(steps):
        fb.cycle(inputs)
        assert (int(fb["o"]), int(fb["p"]), fb["Blocked"]) == (o, p, blocked), f"cycle {n}"


def test_past_values_are_stored_at_the_end() -> None:
    f = parse_filter("inputs c\noutputs o\nsafety S: ↓o & !c", "p.filter")
    text = filter_block(f).text
    body = text[text.index("END_VAR\no :="):]
    assert body.splitlines()[1:] == ["o := R_o OR NOT c AND o_1;", "(* the previous cycle's values *)",
                                     "o_1 := o;", "END_FUNCTION_BLOCK"]


def test_loop_needs_a_priority_on_every_combined_constraint() -> None:
    f = parse_filter("outputs o, p\nsafety K: o & p", "k.filter")
    with pytest.raises(InputError) as e:
        filter_block(f, "loop")
    assert str(e.value.location) == "k.filter:2:8"
    assert "K has no priority" in e.value.message


def test_reserved_words_cannot_be_st_names() -> None:
    f = parse_filter("inputs IN\noutputs o\nsafety S: IN & o", "r.filter")
    with pytest.raises(InputError) as e:
        filter_block(f)
    assert e.value.message == "cannot write the filter as Structured Text: IN is a reserved word of IEC 61131-3"
    assert str(e.value.location) == "r.filter:3:11"


def test_not_functional_is_a_model_failure() -> None:
    f = parse_filter("outputs o\nminimize 0", "n.filter")
    s = synthesis(f)
    if s.functional:  # the implicit Sim decides o = R_o
        assert filter_block(f).text.count("o := R_o;") == 1
    else:
        with pytest.raises(ModelError):
            filter_block(f)


def test_cli_writes_the_same_bytes_twice(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    a, b = tmp_path / "a.st", tmp_path / "b.st"
    assert main(["filter", "st", str(ROOT / "plants" / "four_cylinders.filter"), "--algorithm", "loop",
                 "--mode", "blocking", "-o", str(a)]) == 0
    assert main(["filter", "st", str(ROOT / "plants" / "four_cylinders.filter"), "--algorithm", "loop",
                 "--mode", "blocking", "-o", str(b)]) == 0
    assert a.read_bytes() == b.read_bytes()
    assert "FUNCTION_BLOCK FB_four_cylinders_Filter" in a.read_text()
    assert main(["filter", "st", str(ROOT / "plants" / "seed004_eq22.filter"), "--name", "Eq22"]) == 0
    out = capsys.readouterr().out
    assert "FUNCTION_BLOCK FB_Eq22_Filter" in out and "O2 := R_O2 AND NOT O1;" in out


def test_cli_bad_filter_is_exit_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "k.filter"
    bad.write_text("outputs o, p\nsafety K: o & p\n")
    out = tmp_path / "k.st"
    assert main(["filter", "st", str(bad), "--algorithm", "loop", "-o", str(out)]) == 2
    assert not out.exists()
    assert "k.filter:2:8: error: K has no priority" in capsys.readouterr().err


def test_cli_xml_is_valid_tc6(tmp_path: Path) -> None:
    from lxml import etree

    from tc6schema import validation_errors

    out = tmp_path / "fb.xml"
    assert main(["filter", "st", str(ROOT / "plants" / "loop_b.filter"), "--algorithm", "loop", "--xml",
                 "-o", str(out)]) == 0
    data = out.read_bytes()
    assert validation_errors(data) == []
    ns = {"tc6": "http://www.plcopen.org/xml/tc6_0201"}
    pou = etree.fromstring(data).find(".//tc6:pou", ns)
    assert (pou.get("name"), pou.get("pouType")) == ("FB_loop_b_Filter", "functionBlock")
