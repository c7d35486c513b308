"""``synth ass`` and ``synth run``."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from synth.cli.main import main
from synth.output.dot import ass_dot
from synth.grafcet.ass import stable_situation_automaton
from synth.grafcet.language_check import load_grafcet
from synth.grafcet.machine import GrafcetMachine

from conftest import ROOT


@pytest.fixture(autouse=True)
def _cwd(monkeypatch):
    monkeypatch.chdir(ROOT)


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_run_box_sorting_cycle(capsys):
    code, out, err = run(
        capsys, "run", "grafcets/tri.g7", "--plant", "plants/tri.rules",
        "--events", "↑dcy,^cp12,2s/X101,_v10,↑v11,↓v20,↑v21,↓v40,↑v41",
    )
    assert (code, err) == (0, "")
    assert out.splitlines() == [
        "0  initial  {X0, X100, X200, X300}  orders: -",
        "1  ↑dcy     {X1, X100, X200, X300}  orders: TAPIS   fired: 0->1",
        "2  ↑cp12    {X1, X101, X200, X300}  orders: TAPIS   fired: 100->101",
        "3  2s/X101  {X1, X102, X200, X300}  orders: TAPIS, AVANCER1   fired: 101->102",
        "4  ↓v10     {X1, X102, X200, X300}  orders: TAPIS, AVANCER1",
        "5  ↑v11     {X1, X103, X200, X300}  orders: TAPIS, AVANCER2   fired: 102->103",
        "6  ↓v20     {X1, X103, X200, X300}  orders: TAPIS, AVANCER2",
        "7  ↑v21     {X1, X104, X200, X301}  orders: TAPIS, AVANCER4   fired: 103->104; 300->301",
        "8  ↓v40     {X1, X104, X200, X301}  orders: TAPIS, AVANCER4",
        "9  ↑v41     {X1, X105, X200, X302}  orders: TAPIS, RECULER1, RECULER2   fired: 301->302; 104->105",
    ]


def test_run_missing_order_blocks_with_only_tapis(capsys):
    code, out, _ = run(capsys, "run", "grafcets/tri_missing_order.g7", "--plant", "plants/tri.rules",
                       "--events", "↑dcy,↑cp12,2s/X101,↓v10,↑v11")
    assert code == 0
    assert out.splitlines()[-1] == "5  ↑v11     {X1, X103, X200, X300}  orders: TAPIS   fired: 102->103"


def test_run_without_plant_and_initial_values(capsys):
    code, out, _ = run(capsys, "run", "grafcets/conditional.g7", "--initial", "high=1", "--events", "↑go,↓high")
    assert code == 0
    assert out.splitlines() == [
        "0  initial  {X0}  orders: -",
        "1  ↑go      {X1}  orders: LIGHT   fired: 0->1",
        "2  ↓high    {X1}  orders: PUMP, LIGHT",
    ]


def test_run_bad_event_name(capsys):
    code, out, err = run(capsys, "run", "grafcets/tri.g7", "--plant", "plants/tri.rules", "--events", "^dcy, ^cp13")
    assert code == 2 and out == ""
    assert err.splitlines() == [
        "--events:1:8: error: unknown input 'cp13' in event ^cp13",
        "  1 | ^dcy, ^cp13",
        "    |        ^~~~",
        "  = did you mean ^cp12 or ^cp11?",
        "  = note: inputs: dcy, v10, v11, v20, v21, v30, v31, v40, v41, cp11, cp12",
    ]


def test_run_unknown_timer_and_impossible_events(capsys):
    code, _, err = run(capsys, "run", "grafcets/tri.g7", "--events", "2s/X102")
    assert code == 2
    assert err.splitlines()[0] == "--events:1:1: error: unknown event '2s/X102'"
    assert "did you mean 2s/X101 or 2s/X111?" in err
    code, _, err = run(capsys, "run", "grafcets/tri.g7", "--events", "2s/X101")
    assert code == 2
    assert err.splitlines()[0] == "--events:1:1: error: timer 2s/X101 cannot elapse now: step 101 is not active"
    code, _, err = run(capsys, "run", "grafcets/tri.g7", "--plant", "plants/tri.rules", "--events", "↑v10")
    assert code == 2
    assert err.splitlines()[0] == "--events:1:1: error: ↑v10 cannot happen: v10 is already 1"


def test_ass_text(capsys):
    code, out, err = run(capsys, "ass", "grafcets/or_divergence.g7")
    assert (code, err) == (0, "")
    assert out == (
        "ASS of grafcets/or_divergence.g7: 3 stable situations, 6 transitions\n"
        "inputs explored: l, r\n"
        "\n"
        "S0  {X0}  (initial)\n"
        "    orders: -\n"
        "    ↑l -> S1\n"
        "    ↑r -> S2\n"
        "\n"
        "S1  {X1}\n"
        "    orders: GO_LEFT\n"
        "    ↓l  [!r] -> S0\n"
        "    ↓l  [r] -> S2\n"
        "\n"
        "S2  {X2}\n"
        "    orders: GO_RIGHT\n"
        "    ↓r  [!l] -> S0\n"
        "    ↓r  [l] -> S1\n"
    )


def test_ass_json(capsys):
    code, out, _ = run(capsys, "ass", "grafcets/timers.g7", "--json")
    assert code == 0
    data = json.loads(out)
    assert [(s["id"], s["situation"], s["orders"], s["conditional_orders"]) for s in data["states"]] == [
        (0, ["0"], [], []),
        (1, ["1"], ["HEAT"], []),
        (2, ["2"], ["ALARM"], ["ALARM"]),
    ]
    assert data["transitions"] == [
        {"source": 0, "event": "↑start", "condition": "any", "target": 1},
        {"source": 1, "event": "3s/X1", "condition": "any", "target": 2},
        {"source": 2, "event": "↓start", "condition": "any", "target": 0},
    ]


def test_ass_of_tri_with_plant_json(capsys):
    code, out, _ = run(capsys, "ass", "grafcets/tri.g7", "--plant", "plants/tri.rules", "--json")
    assert code == 0
    data = json.loads(out)
    # the plant rules out input vectors such as v10 & v11 or cp11 & cp12: fewer transitions
    assert (len(data["states"]), len(data["transitions"])) == (15, 45)
    assert data["states"][0]["situation"] == ["0", "100", "200", "300"]
    assert not any("cp11 & cp12" in t["condition"] for t in data["transitions"])
    code, out, _ = run(capsys, "ass", "grafcets/tri.g7", "--json")
    free = json.loads(out)
    assert (len(free["states"]), len(free["transitions"])) == (15, 83)


def test_ass_dot_and_svg(capsys, tmp_path):
    dot, svg = tmp_path / "a.dot", tmp_path / "a.svg"
    code, _, _ = run(capsys, "ass", "grafcets/edges.g7", "--dot", str(dot), "--svg", str(svg))
    assert code == 0
    assert dot.read_text(encoding="utf-8") == (
        'digraph "grafcets/edges.g7" {\n'
        "  rankdir=TB;\n"
        '  node [shape=box, fontname="Helvetica"];\n'
        '  edge [fontname="Helvetica", fontsize=10];\n'
        '  S0 [label="S0\\n{X0}\\n-", peripheries=2];\n'
        '  S1 [label="S1\\n{X1}\\nLAMP"];\n'
        '  S0 -> S1 [label="↑b"];\n'
        '  S1 -> S0 [label="↑b"];\n'
        "}\n"
    )
    assert svg.read_text(encoding="utf-8").lstrip().startswith("<?xml")
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_ass_dot_condition_labels_are_escaped():
    m = GrafcetMachine(load_grafcet(ROOT / "grafcets/or_divergence.g7"))
    text = ass_dot(stable_situation_automaton(m), 'a "b"')
    assert text.splitlines()[0] == 'digraph "a \\"b\\"" {'
    assert '  S1 -> S0 [label="↓l\\n[!r]"];' in text


@pytest.mark.parametrize(
    "name, first_line",
    [
        ("syntax", "grafcets/bad/syntax.g7:3:26: error: syntax error: unexpected 'b'"),
        ("unknown_step", "grafcets/bad/unknown_step.g7:4:20: error: unknown step 12"),
        ("duplicate_step", "grafcets/bad/duplicate_step.g7:5:16: error: step 0 is declared twice"),
        ("unknown_variable", "grafcets/bad/unknown_variable.g7:5:26: error: unknown variable 'dcx'"),
        ("missing_step_variable", "grafcets/bad/missing_step_variable.g7:4:30: error: X12 refers to step 12, which does not exist"),
        ("not_an_output", "grafcets/bad/not_an_output.g7:4:18: error: 'AVANCR1' is not an output (declared)"),
        ("no_initial_step", "grafcets/bad/no_initial_step.g7:1:9: error: partial grafcet G has no initial step"),
        ("never_stable", "grafcets/bad/never_stable.g7:7:14: error: the Grafcet never stabilises: transient cycle through steps 1, 2"),
    ],
)
def test_bad_files_exit_2_with_caret(capsys, name, first_line):
    code, out, err = run(capsys, "ass", f"grafcets/bad/{name}.g7")
    assert code == 2 and out == ""
    lines = err.splitlines()
    assert lines[0] == first_line
    assert lines[2].strip().startswith("|") and "^" in lines[2]
    assert "Traceback" not in err


def test_unknown_variable_against_the_plant_suggests(capsys, tmp_path):
    f = tmp_path / "g.g7"
    f.write_text("grafcet G { initial step 0 step 1: TAPIS transition 0 -> 1 when dcx }\n", encoding="utf-8")
    code, _, err = run(capsys, "ass", str(f), "--plant", "plants/tri.rules")
    assert code == 2
    assert err.splitlines()[0].endswith(":1:65: error: unknown variable 'dcx' (not an input of the plant)")
    assert "  = did you mean dcy?" in err.splitlines()


def test_python_dash_m_subprocess():
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    p = subprocess.run([sys.executable, "-m", "synth", "run", "grafcets/edges.g7", "--events", "^b,^c"],
                       cwd=ROOT, env=env, capture_output=True, text=True)
    assert p.returncode == 2
    assert p.stderr.splitlines()[0] == "--events:1:5: error: unknown input 'c' in event ^c"
    assert "Traceback" not in p.stderr
