"""``--target {iec,plcopen,codesys,twincat}`` on ``synth st`` and ``synth filter st`` (issue 22):
every target's files are read back as their readers read them (TwinCAT's through blark's
TwinCAT loader, the XML ones by their ``<pou>`` elements) and go through the same execution
proof as the ST text."""

from __future__ import annotations

import dataclasses
import random
import re

import pytest

from synth.cli.main import main
from synth.codegen.check import differential_check
from synth.codegen.filter_st import filter_block
from synth.codegen.grafcet_st import generate_program
from tc6schema import validation_errors
from synth.codegen.targets import Target, render, st_of
from synth.codegen.twincat import object_id
from synth.filter.cycle import FilterCycle
from synth.filter.language_check import load_filter
from synth.grafcet.language_check import load_grafcet

pytest.importorskip("blark")
from conftest import ROOT


@pytest.mark.parametrize("target", list(Target))
@pytest.mark.parametrize("name", ["timers.g7", "stored.g7", "conditional.g7"])
def test_each_target_of_a_program_passes_the_execution_proof(name, target):
    g = load_grafcet(ROOT / "grafcets" / name)
    program = generate_program(g, version="test")
    files = render(target, program.pous, text=program.text, name=program.program, header=["test"])
    report = differential_check(g, depth=2, program=dataclasses.replace(program, text=st_of(target, files, name)))
    assert report.ok and report.sequences > 1, report.text()


def test_st_check_reads_the_twincat_file_back_through_blark(capsys):
    assert main(["st", "--check", str(ROOT / "grafcets/tri.g7"), "--target", "twincat", "--depth", "1"]) == 0
    assert capsys.readouterr().out.endswith("0 mismatches\n")


def test_twincat_writes_one_tcpou_per_pou_with_stable_ids(tmp_path):
    args = ["st", str(ROOT / "grafcets/tri.g7"), "--plant", str(ROOT / "plants/tri.rules"), "--filter",
            str(ROOT / "plants/tri.filter"), "--target", "twincat"]
    assert main([*args, "-o", str(tmp_path / "a")]) == 0
    assert main([*args, "-o", str(tmp_path / "b")]) == 0
    names = sorted(p.name for p in (tmp_path / "a").iterdir())
    assert names == ["FB_tri_Filter.TcPOU", "tri.TcPOU"]
    for n in names:
        data = (tmp_path / "a" / n).read_bytes()
        assert data == (tmp_path / "b" / n).read_bytes()
        pou = n.removesuffix(".TcPOU")
        assert f'<POU Name="{pou}" Id="{{{object_id(pou)}}}" SpecialFunc="None">'.encode() in data
        st = st_of(Target.TWINCAT, [(n, data)], str(tmp_path))
        assert re.search(rf"^(PROGRAM|FUNCTION_BLOCK) {pou}$", st, re.M)


def test_several_files_need_a_folder(capsys):
    assert main(["st", str(ROOT / "grafcets/tri.g7"), "--filter", str(ROOT / "plants/tri.filter"), "--plant",
                 str(ROOT / "plants/tri.rules"), "--target", "twincat"]) == 2
    assert "error: 2 files to write (FB_tri_Filter.TcPOU, tri.TcPOU): give -o DIR" in capsys.readouterr().err


def test_codesys_carries_object_ids_and_the_project_structure(tmp_path):
    out = tmp_path / "tri.xml"
    assert main(["st", str(ROOT / "grafcets/tri.g7"), "--plant", str(ROOT / "plants/tri.rules"), "--filter",
                 str(ROOT / "plants/tri.filter"), "--target", "codesys", "-o", str(out)]) == 0
    xml = out.read_bytes()
    assert validation_errors(xml) == []
    text = re.sub(r"\s+", " ", xml.decode())
    for pou in ("FB_tri_Filter", "tri"):
        assert (f'<data name="http://www.3s-software.com/plcopenxml/objectid" handleUnknown="discard"> '
                f'<ObjectId>{object_id(pou)}</ObjectId> </data>') in text
    assert ('<data name="http://www.3s-software.com/plcopenxml/projectstructure" handleUnknown="discard"> '
            f'<ProjectStructure> <Object Name="FB_tri_Filter" ObjectId="{object_id("FB_tri_Filter")}"/> '
            f'<Object Name="tri" ObjectId="{object_id("tri")}"/> </ProjectStructure> </data>') in text


def test_xml_is_plcopen_and_refuses_another_target(tmp_path, capsys):
    a, b = tmp_path / "a.xml", tmp_path / "b.xml"
    assert main(["filter", "st", str(ROOT / "plants/tri.filter"), "--xml", "-o", str(a)]) == 0
    assert main(["filter", "st", str(ROOT / "plants/tri.filter"), "--target", "plcopen", "-o", str(b)]) == 0
    assert a.read_bytes() == b.read_bytes()
    assert main(["filter", "st", str(ROOT / "plants/tri.filter"), "--xml", "--target", "twincat"]) == 2
    assert "--xml is --target plcopen; it cannot go with --target twincat" in capsys.readouterr().err


@pytest.mark.parametrize("target", [Target.PLCOPEN, Target.CODESYS, Target.TWINCAT])
def test_each_target_of_a_filter_block_runs_as_the_st_text(target):
    from synth.codegen.interpreter.machine import load_st

    f = load_filter(ROOT / "plants/tri.filter")
    block = filter_block(f)
    files = render(target, [block.pou], text=block.text, name=block.name, header=["test"])
    ours = load_st(st_of(target, files, "tri"), "t.st").instance(block.name)
    text = load_st(block.text, "b.st").instance(block.name)
    rnd = random.Random(7)
    reads = FilterCycle(f).reads
    for _ in range(200):
        values = {n: rnd.random() < 0.5 for n in reads}
        ours.cycle(values)
        text.cycle(values)
        assert [ours[o] for o in f.outputs] == [text[o] for o in f.outputs]
