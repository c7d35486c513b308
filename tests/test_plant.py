"""Element automata and their asynchronous composition (issue: plant models from rules)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from synth.plant.composition import plant
from synth.plant.element import element_automaton
from synth.plant.rules_check import load_rules, parse_rules

from conftest import ROOT

LIB = (ROOT / "plants" / "lib" / "double_acting.rules").read_text() + (ROOT / "plants" / "lib" / "single_acting.rules").read_text()


def _element(text: str):
    rs = parse_rules(LIB + text, "t.rules")
    return element_automaton(rs.elements[-1])


def test_v1_annex_table1_counts():
    a = _element("element V1 = double_acting(AVANCER=AVANCER1, RECULER=RECULER1, v0=v10, v1=v11)")
    assert (a.size, a.count(True), a.count(False)) == (12, 24, 12)
    assert a.state_label(a.initial) == "{v10}"


def test_v1_uncontrollable_transitions_exact():
    a = _element("element V1 = double_acting(AVANCER=AVANCER1, RECULER=RECULER1, v0=v10, v1=v11)")
    got = sorted(
        (a.state_label(int(a.src[t])), a.event(t), a.state_label(int(a.dst[t])))
        for t in range(a.src.size)
        if not a.controllable[t]
    )
    # both ↑v10 and ↑v11 are possible from the middle states without orders (figure A1.2)
    assert got == sorted([
        ("{AVANCER1,v10}", "↓v10", "{AVANCER1}"),
        ("{AVANCER1,RECULER1,v10}", "↓v10", "{AVANCER1,RECULER1}"),
        ("{AVANCER1}", "↑v11", "{AVANCER1,v11}"),
        ("{AVANCER1,RECULER1}", "↑v11", "{AVANCER1,RECULER1,v11}"),
        ("{AVANCER1,RECULER1}", "↑v10", "{AVANCER1,RECULER1,v10}"),
        ("{RECULER1}", "↑v10", "{RECULER1,v10}"),
        ("{RECULER1}", "↑v11", "{RECULER1,v11}"),
        ("{RECULER1,v11}", "↓v11", "{RECULER1}"),
        ("{AVANCER1,RECULER1,v11}", "↓v11", "{AVANCER1,RECULER1}"),
        ("{}", "↑v11", "{v11}"),
        ("{}", "↑v10", "{v10}"),
        ("{AVANCER1}", "↑v10", "{AVANCER1,v10}"),
    ])


def test_single_acting_counts():
    a = _element("element V3 = single_acting(AVANCER=AVANCER3, v0=v30, v1=v31)")
    assert (a.size, a.count(True), a.count(False)) == (6, 6, 4)


def test_precedence_restricts_consequence():
    text = """
    element E {
      order A = 0
      sensors s = 0, t = 0
      ↑A -> ↑s
      ↑A -> ↑t
      ↑A: ↑s < ↑t
    }"""
    a = _element(text)
    # ↑t only once s holds: from {A} only ↑s; from {A,s} ↑t
    moves = {(a.state_label(int(a.src[t])), a.event(t)) for t in range(a.src.size) if not a.controllable[t]}
    assert moves == {("{A}", "↑s"), ("{A,s}", "↑t")}


def test_free_input_and_held_order():
    rs = parse_rules("free dcy = 0\nelement C { order T = 0\n sensor b = 0\n ↑T -> ↑b }\nhold T = 1", "t.rules")
    p = plant(rs)
    assert p.shape == (2, 2)  # dcy free (2 states); C with T held at 1: {T}, {T,b}
    assert p.count_transitions(True) == 0
    assert p.label(p.initial) == "{T}"


def test_tri_annex_plant_size(cli):
    code, out, _ = cli("plant", ROOT / "plants" / "tri_annex.rules", "--json")
    data = json.loads(out)
    assert code == 0
    assert data["states"] == 15552 == 12 * 12 * 6 * 6 * 3
    assert data["transitions"] % 1296 == 0
    # E0 and Z0 of the annex, in the thesis's order (declared with `inputs` / `outputs`)
    assert data["initial"]["E"] == "1010101000" and data["initial"]["Z"] == "1000000"
    assert data["outputs"][0] == "TAPIS" and data["inputs"][-2:] == ["cp11", "cp12"]


def test_composition_counts_match_enumeration():
    rs = load_rules(ROOT / "plants" / "tri_annex.rules")
    p = plant(rs)
    n = sum(src.size for _, src, _ in p.transition_arrays())
    assert n == p.count_transitions()
    # every enumerated transition flips exactly one variable
    codes = np.arange(p.size)
    for t, src, dst in list(p.transition_arrays())[:20]:
        for s, d in zip(src[:50].tolist(), dst[:50].tolist()):
            a, b = p.valuation(p.local(s)), p.valuation(p.local(d))
            assert sum(a[v] != b[v] for v in a) == 1
    assert codes.size == 15552


def test_element_cli_text(cli):
    code, out, _ = cli("plant", ROOT / "plants" / "tri.rules", "--element", "V3")
    assert code == 0
    assert out.splitlines()[0] == "element V3: 6 states, 10 transitions (6 controllable, 4 uncontrollable)"


def test_element_svg_and_export(cli, tmp_path):
    pytest.importorskip("graphviz")
    svg = tmp_path / "v1.svg"
    gen = tmp_path / "v1.gen"
    code, _, _ = cli("plant", ROOT / "plants" / "tri.rules", "--element", "V1", "--svg", svg, "--export", gen)
    assert code == 0
    text = svg.read_text()
    assert text.lstrip().startswith("<?xml") or "<svg" in text
    assert "↑AVANCER1" in text
    assert '"AVANCER1_up" +C+' in gen.read_text()
    faudes = pytest.importorskip("faudes")
    g = faudes.System(str(gen))
    assert (g.Size(), g.TransRelSize()) == (12, 36)
    assert faudes.System(str(gen)).ControllableEvents().Size() == 4


def test_plant_export_reads_in_faudes(cli, tmp_path):
    faudes = pytest.importorskip("faudes")
    gen = tmp_path / "annex.gen"
    code, _, _ = cli("plant", ROOT / "plants" / "tri_annex.rules", "--export", gen)
    assert code == 0
    g = faudes.System(str(gen))
    assert (g.Size(), g.TransRelSize()) == (15552, 155520)


def test_unknown_element_is_an_error(cli):
    code, _, err = cli("plant", ROOT / "plants" / "tri.rules", "--element", "V5")
    assert code == 2
    assert "did you mean" in err and "Traceback" not in err


def test_rule_that_never_applies_is_a_warning(cli, tmp_path):
    f = tmp_path / "dead.rules"
    f.write_text(
        "element V3 {\n  order A = 0\n  sensors v0 = 1, v1 = 0\n  incoherent v0 & v1\n"
        "  ↑A [v0] -> ↓v0\n  ↑A [v0 & v1] -> ↑v1\n  ↓A [!v0 & !v1] -> ↑v0\n}\n"
    )
    code, out, err = cli("plant", f)
    assert code == 0  # a warning, not an error
    assert err.splitlines()[0] == f"{f}:6:4: warning: rule ↑A [v0 & v1] -> ↑v1 of element V3 never applies in any reachable state"
    code, _, err = cli("plant", ROOT / "plants" / "tri.rules")
    assert err == ""  # the library models have no dead rule
