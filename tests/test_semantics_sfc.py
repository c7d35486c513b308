"""``--semantics sfc``: IEC 61131-3 SFC, one evolution per PLC scan (docs/grafcet.md, "Semantics"),
in run, ass, validate and st; its generated ST equal to synth run, interpreted and compiled."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from synth.grafcet.ass import stable_situation_automaton
from synth.grafcet.language_check import parse_grafcet
from synth.grafcet.machine import GrafcetMachine

from conftest import ROOT

sys.path.insert(0, str(ROOT / "tests"))
from randgrafcet import check_seed  # noqa: E402

CHAIN = """\
grafcet G {
  initial step 1
  step 2: A
  step 3: B
  transition 1 -> 2 when ↑go
  transition 2 -> 3 when 1
  transition 3 -> 1 when !go
  transition 1 -> 1 when stay
}
"""


@pytest.fixture
def chain(tmp_path: Path) -> Path:
    (tmp_path / "chain.g7").write_text(CHAIN)
    return tmp_path / "chain.g7"


def test_run_shows_every_scan_and_a_level_self_loop_is_legal(cli, chain):
    code, out, err = cli("run", chain, "--semantics", "sfc", "--events", "↑go,↓go,↑stay")
    assert code == 0 and err == ""
    assert [line.split() for line in out.splitlines()] == [
        ["0", "initial", "{X1}", "orders:", "-"],
        ["1", "↑go", "{X2}", "orders:", "A", "fired:", "1->2"],
        ["2", "scan", "{X3}", "orders:", "B", "fired:", "2->3"],  # step 2 lasts one scan: A is emitted
        ["3", "↓go", "{X1}", "orders:", "-", "fired:", "3->1"],
        ["4", "↑stay", "{X1}", "orders:", "-", "fired:", "1->1"],
        ["5", "scan", "{X1}", "orders:", "-", "fired:", "1->1"],  # evolves every scan: shown once
    ]
    code, _, err = cli("run", chain, "--events", "↑go,↓go,↑stay")  # IEC 60848: search for stability
    assert code == 2 and "the Grafcet never stabilises: transient cycle through steps 1" in err


def test_the_ass_lists_the_situations_after_each_scan(cli, chain):
    code, out, _ = cli("ass", chain, "--semantics", "sfc")
    assert code == 0 and out.splitlines()[0] == f"ASS of {chain}: 6 situations after a PLC scan (--semantics sfc), 15 transitions"


def test_the_ass_has_a_scan_event_where_the_plc_evolves_without_input_change():
    g = parse_grafcet(CHAIN, "chain.g7", semantics="sfc")
    ass = stable_situation_automaton(GrafcetMachine(g))
    assert [s.situation.text() for s in ass.states] == ["{X1}", "{X2}", "{X3}", "{X1, X2}", "{X1, X3}", "{X1, X2, X3}"]
    assert [(t.source, t.event, t.condition, t.target) for t in ass.transitions if t.event == "scan"] == [
        (1, "scan", "any", 2), (2, "scan", "!go", 0), (3, "scan", "any", 4), (4, "scan", "!go", 0), (5, "scan", "any", 4)]
    plain = stable_situation_automaton(GrafcetMachine(parse_grafcet(CHAIN.replace("transition 1 -> 1 when stay\n", ""))))
    assert [s.situation.text() for s in plain.states] == ["{X1}", "{X3}"]  # step 2 is transient in IEC 60848


def test_validate_the_box_sorting_as_the_plc_runs_it(cli):
    g7, rules = ROOT / "grafcets/tri.g7", ROOT / "plants/tri.rules"
    code, out, _ = cli("validate", g7, "--plant", rules, "--semantics", "sfc")
    assert code == 1
    assert out.splitlines()[0] == ("FAIL: 2 blocking situation(s), 4 situation(s) with prohibited orders  [designer mode; "
                                   "IEC 61131-3 SFC semantics; SYNC 372 states, aggregated 221 states / 657 transitions]")
    data = json.loads(cli("validate", g7, "--plant", rules, "--semantics", "sfc", "--json")[1])
    assert data["semantics"] == "sfc" and "semantics" not in json.loads(cli("validate", g7, "--plant", rules, "--json")[1])
    jsonschema = pytest.importorskip("jsonschema")
    jsonschema.validate(data, json.loads((ROOT / "synth/output/schemas/validate.json").read_text()))
    assert " scan " in out.splitlines()[6]  # the trace holds a PLC scan without input change
    assert cli("validate", g7, "--plant", rules, "--semantics", "sfc", "--engine", "explicit")[1] == out
    code, _, err = cli("validate", g7, "--plant", rules, "--semantics", "sfc", "--engine", "symbolic")
    assert code == 2 and err == "error: --semantics sfc runs on the explicit engine: use --engine explicit (or auto)\n"
    assert cli("validate", g7, "--plant", rules)[0] == 0  # IEC 60848: it passes


def test_st_runs_one_evolution_per_cycle_and_equals_synth_run(cli, chain):
    code, out, _ = cli("st", chain, "--semantics", "sfc")
    assert code == 0 and "  _Fired := FALSE; (* IEC 61131-3 SFC: one evolution per PLC cycle *)" in out.splitlines()
    assert "_Fired := FALSE; (* IEC 61131-3" not in cli("st", chain)[1]
    pytest.importorskip("blark")
    code, out, _ = cli("st", "--check", "--semantics", "sfc", chain)
    assert (code, out) == (0, f"{chain}: the ST program equals synth run on 15 event sequences (24 PLC cycles, depth 3): "
                              "0 mismatches\n")


def test_random_grafcets_in_sfc_semantics_st_equals_synth_run():
    pytest.importorskip("blark")
    results = [check_seed(seed, 3, data=seed % 2 == 1, semantics="sfc") for seed in range(5)]
    assert [r[3] for r in results if r[3]] == []
    assert sum(r[2] for r in results) > 80


def test_the_compiled_program_in_sfc_semantics_equals_synth_run(tmp_path):
    from iec2c import find_iec2c

    if find_iec2c() is None:
        pytest.skip("MATIEC's iec2c is not installed")
    from test_st_compiled import compiled_check

    from synth.grafcet.language_check import load_grafcet
    from synth.plant.rules_check import load_rules

    rs = load_rules(ROOT / "plants/tri.rules")
    for name in ("tri.g7", "tri_counting.g7"):
        g = load_grafcet(ROOT / "grafcets" / name, inputs=rs.inputs, outputs=rs.outputs, semantics="sfc")
        report, cycles = compiled_check(g, tmp_path / name, {v.name: v.initial for v in rs.variables if v.is_input})
        assert report.ok, report.text()
        assert cycles > 1000


def test_import_names_the_steps_a_plc_keeps_for_a_scan(cli, tmp_path):
    xml = ROOT / "tests/data/plcopen/codesys_data.xml"
    code, _, err = cli("import", xml, "-o", tmp_path / "x.g7")
    assert code == 0
    assert err.splitlines()[-1] == (
        f"{xml}: note: steps Check, Hold_on stay active for a PLC scan (IEC 61131-3 SFC, their actions run) where "
        "IEC 60848 passes through them in one evolution: validate with --semantics sfc for the meaning the program "
        "has on the PLC")
    code, _, err = cli("import", ROOT / "tests/data/plcopen/twincat3.xml", "-o", tmp_path / "y.g7")
    assert code == 0 and "PLC scan" not in err


EVENTS = """\
grafcet G {
  initial step 0: set M on ↑p
  step 1: set N on ↑p
  transition 0 -> 1 when p
  transition 1 -> 0 when !p
}
"""


def test_an_event_action_runs_on_the_steps_active_after_the_scan(cli, tmp_path):
    """A PLC runs the action bodies after the scan's evolution: ↑p leaves step 0 (its `set M
    on ↑p` does not run) and enters step 1 (its `set N on ↑p` does); IEC 60848 the reverse.
    Measured on Beremiz and MATIEC (tests/data/plcopen/twincat3.g7: 20 of 20 sequences
    differed before, 0 after). The ST program does the same, interpreted."""
    (tmp_path / "ev.g7").write_text(EVENTS)
    code, out, _ = cli("run", tmp_path / "ev.g7", "--semantics", "sfc", "--events", "↑p")
    assert code == 0 and [line.split() for line in out.splitlines()] == [
        ["0", "initial", "{X0}", "orders:", "-"],
        ["1", "↑p", "{X1}", "stored{N}", "orders:", "N", "fired:", "0->1"]]
    code, out, _ = cli("run", tmp_path / "ev.g7", "--events", "↑p")
    assert code == 0 and out.splitlines()[1].split() == ["1", "↑p", "{X1}", "stored{M}", "orders:", "M", "fired:", "0->1"]
    code, out, _ = cli("st", tmp_path / "ev.g7", "--semantics", "sfc")
    assert "(* IEC 61131-3 SFC: the action bodies run after the cycle's evolution, on the steps then active *)" in out
    pytest.importorskip("blark")
    code, out, _ = cli("st", "--check", "--semantics", "sfc", tmp_path / "ev.g7")
    assert code == 0 and out.endswith(": 0 mismatches\n"), out
