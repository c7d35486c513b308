"""``synth commission`` against the device under test CI runs: synth's generated program in its
ST interpreter behind a real pymodbus server (or polling synth's), on 127.0.0.1 (issue 36).

Each program is parsed once (blark takes seconds); every device gets its own module and clock.
"""

from __future__ import annotations

import functools
import json
from pathlib import Path

import jsonschema
import pytest

from conftest import ROOT
from schemas import assert_valid
from synth.commission.device import InterpretedPlc, Timing, located_program
from synth.commission.iomap import Layout, Role, layout_map
from synth.commission.modbus import free_port

pytest.importorskip("pymodbus")

RULES = str(ROOT / "plants" / "tri.rules")
TRI = str(ROOT / "grafcets" / "tri.g7")
MISSING = str(ROOT / "grafcets" / "tri_missing_order.g7")
FORBIDDEN = str(ROOT / "tests" / "data" / "commission" / "tri_forbidden.g7")
THESIS = "↑dcy,↑cp12,2s/X101,↓v10,↑v11"


@functools.lru_cache(maxsize=None)
def _parsed(g7: str):
    return located_program(g7, RULES, "openplc-server")


def _plc(g7: str, layout: str = "openplc-server", timing: Timing = Timing.LOCKSTEP, **options) -> tuple[InterpretedPlc, int]:
    parsed, pou, io = _parsed(g7)
    io = layout_map(Layout(layout), [e.name for e in io.of(Role.SENSOR)], [e.name for e in io.of(Role.ORDER)])
    port = free_port()
    return InterpretedPlc(parsed, pou, io, "127.0.0.1", port, timing=timing, **options), port


def _commission(cli, g7: str | None, port: int, *args: str, layout: str = "openplc-server", lock_step: bool = True):
    head = [g7] if g7 else []
    return cli("commission", *head, "--plant", RULES, "--modbus", f"127.0.0.1:{port}", "--io", layout,
               *(["--lock-step"] if lock_step else []), "--quiet", *args)


def _run_json(cli, g7, port, *args, **kw) -> tuple[int, dict]:
    code, out, err = _commission(cli, g7, port, "--json", *args, **kw)
    assert code in (0, 1), err
    data = json.loads(out)
    assert_valid("commission", data)  # every JSON of these tests matches the shipped schema
    return code, data


@pytest.mark.parametrize("layout", ["openplc-server", "openplc-device"])
def test_thesis_trace_in_lock_step_gives_synth_runs_orders_at_every_step(cli, layout: str) -> None:
    plc, port = _plc(TRI, layout)
    with plc:
        code, res = _run_json(cli, TRI, port, "--events", THESIS, layout=layout)
    assert code == 0 and res["verdict"] == "pass"
    steps = res["runs"][0]["walks"][0]["steps"]
    assert [s["event"] for s in steps] == ["initial", "↑dcy", "↑cp12", "2s/X101", "↓v10", "↑v11"]
    assert all(s["orders"] == s["expected"] for s in steps)
    assert [s["orders"] for s in steps[-3:]] == [["TAPIS", "AVANCER1"], ["TAPIS", "AVANCER1"], ["TAPIS", "AVANCER2"]]
    # PLC time is scan time: the 2 s timer is exactly 200 scans of 10 ms, whatever the wall clock did
    assert [s["scans"] for s in steps] == [1, 2, 3, 203, 204, 205]


def test_seeded_walks_in_lock_step_are_deterministic_and_match(cli) -> None:
    plc, port = _plc(TRI, "openplc-device")
    with plc:
        first = _run_json(cli, TRI, port, "--walks", "2", "--steps", "120", "--seed", "7", layout="openplc-device")
        again = _run_json(cli, TRI, port, "--walks", "2", "--steps", "120", "--seed", "7", layout="openplc-device")
    assert first[0] == 0 and first[1]["steps"] == 2 * 121
    assert [w["steps"] for w in first[1]["runs"][0]["walks"]] == [w["steps"] for w in again[1]["runs"][0]["walks"]]


@pytest.mark.parametrize("layout", ["openplc-server", "openplc-device"])
def test_real_time_waits_on_the_plc_clock(cli, layout: str) -> None:
    plc, port = _plc(TRI, layout, Timing.REALTIME, period_ms=5)
    with plc:
        code, res = _run_json(cli, TRI, port, "--events", THESIS, "--period", "5ms", layout=layout, lock_step=False)
    assert code == 0, res
    assert res["timing"] == "real-time" and res["seconds"] >= 2.0  # the 2 s timer took 2 s
    assert all(s["orders"] == s["expected"] for s in res["runs"][0]["walks"][0]["steps"])


def test_missing_order_ends_blocked_with_the_thesis_diagnosis(cli) -> None:
    plc, port = _plc(MISSING)
    with plc:
        code, walked = _run_json(cli, MISSING, port, "--walks", "1", "--steps", "400", "--seed", "1")
        _, scripted = _run_json(cli, MISSING, port, "--events", THESIS)
    assert code == 1 and walked["verdict"] == "fail"
    for res in (walked, scripted):
        walk = res["runs"][0]["walks"][0]
        assert walk["outcome"] == "blocked"
        assert walk["steps"][-1]["steps"] == ["1", "103", "200", "300"]
        assert walk["steps"][-1]["orders"] == ["TAPIS"]
        assert walk["details"][0].startswith("diagnosis [missing_order]: missing order AVANCER2 in step 103")
        assert walk["details"][-1] == "validate's trace: ↑dcy ↑cp12 2s/X101 ↓v10 ↑v11"
    assert scripted["runs"][0]["walks"][0]["trace"] == THESIS.split(",")
    scripted["runs"][0]["walks"][0]["outcome"] = "stuck"  # the schema does reject drift
    with pytest.raises(jsonschema.ValidationError):
        assert_valid("commission", scripted)


def test_a_forbidden_order_ends_unsafe_with_its_trace(cli, tmp_path: Path) -> None:
    plc, port = _plc(FORBIDDEN)
    junit, sarif = tmp_path / "j.xml", tmp_path / "s.sarif"
    with plc:
        code, out, _ = _commission(cli, FORBIDDEN, port, "--events", THESIS, "--junit", str(junit), "--sarif", str(sarif),
                                   "--report", str(tmp_path / "report"))
        going, res = _run_json(cli, FORBIDDEN, port, "--events", THESIS, "--keep-going")
    walk = res["runs"][0]["walks"][0]
    assert (going, walk["outcome"], walk["trace"]) == (1, "unsafe", THESIS.split(","))  # refused, then on to the end
    assert walk["details"] == ["2 step(s) with an unsafe move refused; the first: ↑RECULER1 leaves SUP in state "
                               "{dcy,v10,v20,v30,v40,cp12,TAPIS,AVANCER1}: constraint C2_1 can then be violated "
                               "(trace ↑dcy ↑cp12 2s/X101)"]
    assert code == 1
    assert "walk 1: unsafe: ↑RECULER1 leaves SUP in state {dcy,v10,v20,v30,v40,cp12,TAPIS,AVANCER1}: constraint C2_1" in out
    assert "    trace: ↑dcy ↑cp12 2s/X101\n" in out
    assert junit.read_text().count("<failure ") == 1
    html = (tmp_path / "report" / "index.html").read_text()
    assert '<h1 class="fail">FAIL</h1>' in html and "<h3>Walk 1: unsafe</h3>" in html
    assert "<td><code>2s/X101</code></td><td>TAPIS, AVANCER1, RECULER1</td><td>TAPIS, AVANCER1, RECULER1</td>" in html
    result = json.loads(sarif.read_text())["runs"][0]["results"]
    assert [(r["ruleId"], r["level"]) for r in result] == [("unsafe", "error")]


def test_faults_are_reported_with_the_walk_that_shows_them(cli) -> None:
    plc, port = _plc(TRI)
    with plc:
        code, res = _run_json(cli, TRI, port, "--walks", "1", "--steps", "150", "--seed", "1",
                              "--fault", "v11=0", "--fault", "AVANCER2")
        _, late = _run_json(cli, TRI, port, "--events", THESIS + ",↓v20,↑v21", "--fault", "↑v21+500ms")
    assert code == 0  # the machine as modelled passes; the faults block it, never make it unsafe
    nominal, stuck, lost = res["runs"]
    assert nominal["walks"][0]["outcome"] == "pass"
    assert (stuck["fault"], stuck["fault_kind"], stuck["survived"]) == ("v11=0", "stuck sensor", True)
    assert stuck["walks"][0]["outcome"] == "blocked" and "v11" not in stuck["walks"][0]["steps"][-1]["orders"]
    assert stuck["walks"][0]["steps"][-1]["steps"][1] == "112"  # V1 advanced, v11 never seen: X112 waits for ever
    assert (lost["fault_kind"], lost["walks"][0]["outcome"]) == ("lost order", "blocked")
    normal, delayed = (r["walks"][0]["steps"][-1]["scans"] for r in late["runs"])
    assert (normal, delayed) == (207, 257)  # 500 ms late: 50 more scans of 10 ms before the PLC sees ↑v21


def test_cover_reaches_every_plant_transition_reachable_under_the_grafcet(cli) -> None:
    plc, port = _plc(TRI)
    with plc:
        code, res = _run_json(cli, TRI, port, "--walks", "2", "--steps", "250", "--seed", "1", "--cover")
    assert code == 0
    cov = res["coverage"]
    assert cov["plant_transitions"] == {"reachable": 26, "seen": 26, "missing": []}
    assert cov["grafcet_steps"]["missing"] == [] and cov["grafcet_steps"]["reachable"] == 21


def test_without_a_grafcet_safety_and_blocking_alone(cli, tmp_path: Path) -> None:
    table = tmp_path / "tri.io.csv"
    parsed, pou, io = _parsed(TRI)
    table.write_text(io.table_csv())
    plc, port = _plc(TRI)
    with plc:
        code, out, err = cli("commission", "--plant", RULES, "--modbus", f"127.0.0.1:{port}", "--io", str(table),
                             "--lock-step", "--walks", "1", "--steps", "60", "--seed", "2", "--json", "--quiet")
    res = json.loads(out)
    assert code == 0, err
    steps = res["runs"][0]["walks"][0]["steps"]
    assert len(steps) == 61 and all(s["expected"] is None for s in steps)


@pytest.mark.parametrize(("options", "message"), [
    ({"stall_after": 4}, "the runtime did not run the 200 scan(s) granted (@grant 203): @done stayed 4 for 0.5 s"),
    ({"drop_after": 4}, "Modbus TCP 127.0.0.1:"),
])
def test_a_slow_or_dropping_plc_is_a_clear_exit_2_with_what_was_reached(cli, tmp_path: Path, options, message) -> None:
    plc, port = _plc(TRI, **options)
    junit = tmp_path / "j.xml"
    with plc:
        code, out, err = _commission(cli, TRI, port, "--events", THESIS, "--timeout", "0.5", "--junit", str(junit))
    assert (code, out) == (2, "")
    assert message in err
    assert "reached walk 1, step 2 (trace ↑dcy ↑cp12), 3 scans since its reset" in err
    assert not junit.exists()  # no half-written report


def test_dead_plc_wrong_layout_and_bad_options_exit_2(cli, tmp_path: Path) -> None:
    port = free_port()
    code, _, err = _commission(cli, TRI, port, "--events", THESIS, "--timeout", "0.5")
    assert code == 2 and f"no Modbus TCP server at 127.0.0.1:{port}" in err
    code, _, err = _commission(cli, TRI, port, "--events", THESIS, layout="plain")
    assert code == 2 and "--io:1:1: error: layout plain puts the sensors on real inputs (%IX)" in err
    code, _, err = _commission(cli, TRI, port, "--fault", "v12=0")
    assert code == 2 and err.startswith("--fault:1:1: error: unknown sensor 'v12'")
    bad = tmp_path / "m.csv"
    bad.write_text("dcy,%IX0.0\n")
    code, _, err = _commission(cli, TRI, port, layout=str(bad))
    assert code == 2 and err.startswith(f"{bad}:1:1: error: read-only area written: dcy at %IX0.0")


def test_an_event_that_cannot_happen_is_located(cli) -> None:
    plc, port = _plc(TRI)
    with plc:
        code, _, err = _commission(cli, TRI, port, "--events", "↑dcy,↑v11")
    assert code == 2 and err.startswith("--events:1:6: error: ↑v11 cannot happen now")


def test_opc_ua_gives_the_same_run_as_modbus(cli) -> None:
    pytest.importorskip("asyncua")
    from synth.commission.opcua import InterpretedUaPlc

    parsed, pou, io = _parsed(TRI)
    url = f"opc.tcp://127.0.0.1:{free_port()}/"
    ua = InterpretedUaPlc(parsed, pou, [e.name for e in io.of(Role.SENSOR)], [e.name for e in io.of(Role.ORDER)], url)
    plc, port = _plc(TRI)
    runs = {}
    with ua, plc:
        for name, where in (("opcua", ["--opcua", url]), ("modbus", ["--modbus", f"127.0.0.1:{port}", "--io", "openplc-server"])):
            code, out, err = cli("commission", TRI, "--plant", RULES, *where, "--lock-step", "--quiet", "--json",
                                 "--walks", "1", "--steps", "40", "--seed", "5")
            assert code == 0, err
            runs[name] = json.loads(out)
    assert runs["opcua"]["protocol"].startswith("OPC UA opc.tcp://127.0.0.1:")
    assert runs["opcua"]["runs"] == runs["modbus"]["runs"]
    code, _, err = cli("commission", TRI, "--plant", RULES, "--opcua", f"opc.tcp://127.0.0.1:{free_port()}/",
                       "--timeout", "0.5", "--quiet")
    assert code == 2 and "no OPC UA server at opc.tcp://127.0.0.1:" in err
