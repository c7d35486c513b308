"""``synth st --io``: located variables, the address table, bad maps as located errors
(issue 36, build 1)."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from conftest import ROOT
from synth.codegen.grafcet_st import generate_program
from synth.codegen.interpreter.machine import load_st
from tc6schema import validation_errors
from synth.codegen.program import with_locations
from synth.commission.iomap import Coupling, Layout, io_map, layout_map, parse_map
from synth.errors import InputError
from synth.grafcet.language_check import load_grafcet
from synth.plant.rules_check import load_rules

TRI = str(ROOT / "grafcets" / "tri.g7")
RULES = str(ROOT / "plants" / "tri.rules")
TIMERS = str(ROOT / "grafcets" / "timers.g7")


def _tri():
    rs = load_rules(RULES)
    return load_grafcet(TRI, inputs=rs.inputs, outputs=rs.outputs)


def test_openplc_server_layout_puts_sensors_on_coils_and_orders_on_the_next_byte(cli, tmp_path: Path) -> None:
    out = tmp_path / "tri.st"
    code, _, err = cli("st", TRI, "--plant", RULES, "--io", "openplc-server", "--task", "10ms", "-o", out)
    assert code == 0, err
    text = out.read_text()
    assert "  dcy AT %QX0.0 : BOOL;" in text.splitlines()
    assert "  cp12 AT %QX1.2 : BOOL;" in text.splitlines()
    assert "  TAPIS AT %QX2.0 : BOOL;" in text.splitlines()
    assert "  AVANCER4 AT %QX2.6 : BOOL;" in text.splitlines()
    assert "VAR_INPUT" not in text  # every input located: none left in the interface
    rows = list(csv.DictReader((tmp_path / "tri.io.csv").open()))
    assert [(r["name"], r["role"], r["address"], r["modbus_table"], r["modbus_index"]) for r in rows[-3:]] == [
        ("AVANCER4", "order", "%QX2.6", "coil", "22"), ("@grant", "grant", "%MW0", "holding", "1024"),
        ("@done", "done", "%IW0", "input", "0")]
    table = json.loads((tmp_path / "tri.io.json").read_text())
    assert table["coupling"] == "client" and len(table["variables"]) == 11 + 7 + 2


def test_device_and_plain_layouts() -> None:
    g = _tri()
    device = layout_map(Layout.OPENPLC_DEVICE, g.inputs, g.outputs)
    assert device.coupling is Coupling.SERVER
    assert [(e.name, e.address.text, device.slot(e)) for e in device.entries][8:12] == [
        ("v41", "%IX101.0", ("discrete", 8)), ("cp11", "%IX101.1", ("discrete", 9)),
        ("cp12", "%IX101.2", ("discrete", 10)), ("TAPIS", "%QX100.0", ("coil", 0))]
    plain = layout_map(Layout.PLAIN, g.inputs, g.outputs)
    assert plain.locations["dcy"] == "%IX0.0" and plain.locations["TAPIS"] == "%QX0.0"
    with pytest.raises(InputError, match="layout plain puts the sensors on real inputs"):
        plain.check_plant()  # the wrong layout for commissioning: a located error, exit 2


def test_the_located_program_runs_as_the_unlocated_one() -> None:
    g = load_grafcet(TIMERS)
    program = generate_program(g)
    plain = load_st(program.text, "a.st")
    for layout in ("plain", "openplc-server", "openplc-device"):
        m = io_map(layout, g.inputs, g.outputs)
        text = with_locations(program, m.locations, "I/O").text
        assert f"  start AT {m.locations['start']} : BOOL;" in text.splitlines() and "VAR_INPUT" not in text
        loc = load_st(text, "b.st")
        plain.clock_ms = 0
        a, b = plain.instance("timers"), loc.instance("timers")
        seen = []
        for inputs, ms in (({}, 0), ({"start": True}, 0), ({}, 3000), ({"ok": True}, 0), ({"start": False}, 0)):
            plain.advance(ms)
            loc.advance(ms)
            got = {o: a.cycle(inputs)[o] for o in g.outputs}
            assert got == {o: b.cycle(inputs)[o] for o in g.outputs}
            seen.append(tuple(o for o in g.outputs if got[o]))
        assert seen == [(), ("HEAT",), ("ALARM",), (), ()]


def test_st_check_proves_the_located_program_on_every_target(cli) -> None:
    for target in ("iec", "plcopen", "twincat"):
        code, out, err = cli("st", "--check", TIMERS, "--io", "openplc-device", "--depth", "2",
                             "--target", target)
        assert code == 0, err
        assert out.endswith(": 0 mismatches\n")


def test_plcopen_keeps_the_addresses_and_stays_valid(cli, tmp_path: Path) -> None:
    out = tmp_path / "tri.xml"
    assert cli("st", TRI, "--plant", RULES, "--io", "plain", "--xml", "-o", out)[0] == 0
    data = out.read_bytes()
    assert validation_errors(data) == []
    assert b'<variable name="v10" address="%IX0.1">' in data


@pytest.mark.parametrize(("text", "message", "where"), [
    ("name,address\ndcy,%QX0.0\nv1,%QX0.1\n", "unknown name 'v1'", "3:1"),
    ("dcy,%QX0.0\nv10,%QX0.0\n", "address %QX0.0 used twice: dcy (line 1) and v10", "2:5"),
    ("dcy,%QX0.0\nTAPIS,%IX0.1\n", "read-only area written: the program cannot write order TAPIS to %IX0.1", "2:7"),
    ("dcy,%QX0.9\n", "'%QX0.9' is not a bit address", "1:5"),
    ("dcy,%QW3\n", "sensor dcy is a BOOL", "1:5"),
    ("dcy,%QX0.0\ndcy,%QX0.1\n", "dcy is mapped twice", "2:1"),
])
def test_bad_maps_are_located_errors(cli, tmp_path: Path, text: str, message: str, where: str) -> None:
    path = tmp_path / "map.csv"
    path.write_text(text)
    code, out, err = cli("st", TRI, "--plant", RULES, "--io", path)
    assert (code, out) == (2, "")
    assert err.startswith(f"{path}:{where}: error: {message}")


def test_unknown_name_suggests_close_names() -> None:
    with pytest.raises(InputError) as info:
        parse_map("TAPI,%QX0.0\n", "m.csv", ["dcy"], ["TAPIS"])
    assert info.value.suggestions == ("TAPIS",)


def test_map_read_back_from_the_table_and_sensor_on_a_discrete_input_is_read_only(tmp_path: Path) -> None:
    g = _tri()
    table = layout_map(Layout.OPENPLC_SERVER, g.inputs, g.outputs).table_csv()
    again = parse_map(table, "t.csv", g.inputs, g.outputs)
    assert again.locations == layout_map(Layout.OPENPLC_SERVER, g.inputs, g.outputs).locations
    bad = parse_map("dcy,%IX0.0\nTAPIS,%QX0.0\n", "m.csv", g.inputs, g.outputs)
    with pytest.raises(InputError, match="read-only area written: dcy at %IX0.0 is a discrete input the plant cannot write"):
        bad.check_plant()


@pytest.mark.parametrize("layout", ["plain", "openplc-server", "openplc-device"])
def test_the_located_program_with_its_task_compiles_through_iec2c_and_the_c_compiler(cli, tmp_path: Path, layout) -> None:
    """MATIEC's trap: a CONFIGURATION connecting the program to addresses gives a Res0.c that
    does not compile; located variables inside the PROGRAM do (skipped without MATIEC)."""
    import shutil
    import subprocess

    from iec2c import find_iec2c

    found = find_iec2c()
    if found is None or shutil.which("gcc") is None:
        pytest.skip("MATIEC's iec2c or gcc is not installed")
    exe, lib = found
    out = tmp_path / "tri.st"
    assert cli("st", TRI, "--plant", RULES, "--io", layout, "--task", "10ms", "-o", out)[0] == 0
    run = subprocess.run([exe, "-f", "-l", "-p", "-r", "-R", "-a", "-I", str(lib), "-T", str(tmp_path), str(out)],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    located = (tmp_path / "LOCATED_VARIABLES.h").read_text()
    first = "__LOCATED_VAR(BOOL,__IX100_0,I,X,100,0)" if layout == "openplc-device" else (
        "__LOCATED_VAR(BOOL,__QX0_0,Q,X,0,0)" if layout == "openplc-server" else "__LOCATED_VAR(BOOL,__IX0_0,I,X,0,0)")
    assert located.splitlines()[0] == first and len(located.splitlines()) == 11 + 7
    for c in ("Config0.c", "Res0.c"):
        cc = subprocess.run(["gcc", "-c", "-w", "-I", str(lib / "C"), c], cwd=tmp_path, capture_output=True, text=True,
                            timeout=300)
        assert cc.returncode == 0, cc.stderr
