"""The accounting of an import (synth/codegen/plcopen/meaning.py, accounting.py): every
qualifier, assignment, divergence order, block call and timer of an imported SFC POU is in the
.g7 with its PLC meaning or named by a located warning; what is neither is a silent change."""

from __future__ import annotations

import pytest
from conftest import ROOT

from synth.codegen.plcopen.accounting import account_import, silent_changes
from synth.codegen.plcopen.export import sfc_project_xml
from synth.codegen.plcopen.meaning import ItemKind, meaning_items
from synth.grafcet.language_check import load_grafcet, parse_grafcet

DATA = ROOT / "tests" / "data" / "plcopen"
PRESS = (DATA / "beremiz_accounting.xml").read_bytes()


def test_the_items_of_a_beremiz_chart_with_their_locations():
    items = meaning_items(PRESS, "a.xml")
    assert [(i.kind, i.step, i.what, str(i.location), i.lines) for i in items] == [
        (ItemKind.ASSIGNMENT, "Idle", "lamp := start (N inline action)", "a.xml:45:39", (45, 41)),
        (ItemKind.QUALIFIER, "Idle", "R action on pump", "a.xml:49:15", (49,)),
        (ItemKind.QUALIFIER, "Manual", "N action on valve", "a.xml:108:15", (108,)),
        (ItemKind.QUALIFIER, "Auto", "S action on pump", "a.xml:128:15", (128,)),
        (ItemKind.PRIORITY, "Idle", "selection divergence after Idle (2 branches, priorities 2, 1)", "a.xml:54:13",
         (54, 63, 78)),
    ]


def test_a_warned_change_is_not_silent():
    done = account_import(PRESS, "a.xml")
    assert "  initial step Idle: lamp if start, reset pump\n" in done.text
    assert [str(w.location) for w in done.warnings] == ["a.xml:54:13", "a.xml:41:15"]
    assert done.silent == ()


def test_the_same_change_without_its_warning_is_silent():
    done = account_import(PRESS, "a.xml")
    g = parse_grafcet(done.text, "a.g7")
    assert [c.text() for c in silent_changes(list(done.items), g, [])] == [
        "a.xml:45: lamp := start (N inline action) (step Idle): not in the .g7 as an assignment of lamp kept once "
        "the step is left, and no warning names it"]
    other = [w for w in done.warnings if w.location is not None and w.location.line == 54]  # the divergence's only
    assert [c.item.location.line for c in silent_changes(list(done.items), g, other)] == [45]


def test_a_g7_that_lost_a_priority_or_a_qualifier_is_reported():
    done = account_import(PRESS, "a.xml")
    lost = done.text.replace("when (manual) & !(auto)", "when manual").replace("step Auto: set pump", "step Auto: reset pump")
    assert lost != done.text
    g = parse_grafcet(lost, "a.g7")
    assert [c.text() for c in silent_changes(list(done.items), g, list(done.warnings)[1:])] == [
        "a.xml:128: S action on pump (step Auto): not in the .g7 as a stored set of pump, and no warning names it",
        "a.xml:54: selection divergence after Idle (2 branches, priorities 2, 1): not in the .g7 as exclusive "
        "branches (manual and auto may hold together), and no warning names it"]


def test_the_blinker_names_its_edges():
    """Beremiz's LD blinker: R_TRIG UP and DOWN between each TON and its coil are named by the
    blinker's warning (they were the corpus's last silent items)."""
    data = (DATA / "beremiz_latch_blink.xml").read_bytes()
    done = account_import(data, "l.xml")
    assert done.silent == ()
    g = parse_grafcet(done.text, "l.g7")
    without = [w for w in done.warnings if "blinks LAMP" not in w.message]
    assert [c.item.what for c in silent_changes(list(done.items), g, without)] == ["R_TRIG UP", "R_TRIG DOWN"]
    timer = [w for w in done.warnings if not w.message.startswith("DONE, a local Boolean")]
    assert [c.text() for c in silent_changes(list(done.items), g, timer)] == [
        "l.xml:184: D action on DONE T#5s (step Run): not in the .g7 as DONE under the timer of T#5s on its step, and "
        "no warning names it"]  # the OR that DONE is wired into: named by the warning on Beremiz's blocks


@pytest.mark.parametrize("name", ["beremiz_counter.xml", "beremiz_fbd_blocks.xml", "beremiz_latch_blink.xml",
                                  "beremiz_ld_fbd.xml", "beremiz_tc6_1_0.xml", "codesys_data.xml",
                                  "codesys_v35.xml", "twincat3.xml"])
def test_every_dialect_fixture_imports_without_a_silent_change(name):
    done = account_import((DATA / name).read_bytes(), name)
    assert done.items and done.silent == ()


@pytest.mark.parametrize("name", ["tri.g7", "tri_counting.g7", "or_divergence.g7", "timers.g7"])
def test_what_synth_sfc_writes_comes_back_without_a_silent_change(name):
    """Shared orders (RUN := _N_RUN_S1 OR _N_RUN_S2) are each flag's step emitting RUN."""
    xml = sfc_project_xml(load_grafcet(ROOT / "grafcets" / name), version="0.1.0")
    done = account_import(xml, name + ".xml")
    assert done.silent == ()
    if name == "tri.g7":
        shared = [i for i in done.items if i.kind == ItemKind.ASSIGNMENT and "_N_AVANCER1_S102" in i.value]
        assert shared
        lost = done.text.replace("step 112: AVANCER1\n", "step 112\n")  # one step no longer emits the order
        assert lost != done.text
        changes = silent_changes(list(done.items), parse_grafcet(lost, "t.g7"), list(done.warnings))
        assert len(changes) == 10  # the shared assignment on each of the 9 initial steps, and step S112's flag
        assert changes[0].expected == "the order AVANCER1 emitted by step S112"
        assert changes[5].text() == ("tri.g7.xml:572: N action on _N_AVANCER1_S112 (step S112): not in the .g7 as a "
                                     "continuous action on _N_AVANCER1_S112, and no warning names it")


def test_the_corpus_bench_counts_per_repository(tmp_path):
    """bench/import_corpus.py on two 'repositories': imported, refused with its construct, no SFC."""
    import subprocess
    import sys

    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    (tmp_path / "a" / "press.xml").write_bytes(PRESS)
    (tmp_path / "a" / "blink.xml").write_bytes((DATA / "beremiz_latch_blink.xml").read_bytes())
    (tmp_path / "b" / "power.xml").write_bytes(PRESS.replace(b"<![CDATA[auto]]>", b"<![CDATA[Power ON]]>"))
    (tmp_path / "b" / "st.xml").write_bytes(PRESS.split(b"<SFC>")[0] + b"<ST><xhtml:p>pump := TRUE;</xhtml:p></ST>"
                                            + PRESS.split(b"</SFC>")[1])
    done = subprocess.run([sys.executable, str(ROOT / "bench" / "import_corpus.py"), str(tmp_path)],
                          capture_output=True, text=True, check=True, cwd=ROOT)
    lines = done.stdout.splitlines()
    assert lines[4:] == [
        "repository a: files 2, SFC POUs 2, imported 2, refused 0, no SFC 0, TRACEBACK 0, items 15, silent changes 0",
        "repository b: files 2, SFC POUs 1, imported 0, refused 1, no SFC 1, TRACEBACK 0, items 0, silent changes 0",
        "total files: 4, SFC POUs: 3, imported: 2, refused: 1, no SFC: 1, TRACEBACK: 0, items: 15, silent changes: 0",
        "refused 1: unexpected … in an ST condition",
        "silent changes: 0"]


def test_two_transitions_wired_to_one_step_must_stay_exclusive():
    """Beremiz's counter: Count -> Full when !go & Cnt >= 3, Count -> Start when !go & Cnt < 3,
    both wired to step Count without a divergence; exclusive over the counter's values."""
    done = account_import((DATA / "beremiz_counter.xml").read_bytes(), "c.xml")
    assert [i.what for i in done.items if i.kind == ItemKind.PRIORITY] == [
        "2 transitions wired to step Count without a divergence"]
    assert done.silent == ()
    overlap = done.text.replace("when !go & Cnt < 3", "when !go & Cnt < 4")
    assert overlap != done.text
    assert [c.expected for c in silent_changes(list(done.items), parse_grafcet(overlap, "c.g7"), [])] == [
        "exclusive branches (!go & Cnt >= 3 and !go & Cnt < 4 may hold together)"]
