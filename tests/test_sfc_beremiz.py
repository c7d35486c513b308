"""Every bundled Grafcet as the PLC runs it (issue 35): exported by ``synth sfc``, turned into
IEC 61131-3 by Beremiz's own generator, compiled by MATIEC's ``iec2c`` and gcc, and run scan by
scan on seeded random input sequences, against ``synth run --semantics sfc`` (the
:class:`~synth.grafcet.machine.GrafcetMachine` of the Grafcet with ``Semantics.SFC``).

The harness writes only the program's ``VAR_INPUT`` (read from the program Beremiz generates):
the plant inputs, and the edge inputs ``_RE_x``/``_FE_x`` computed as the exported program's
contract says (``x AND NOT x_previous``, no edge at the first scan). Each scan the PLC clock
moves on by :data:`PERIOD` ms; at most one plant input changes per scan, as ``synth run``
plays one event at a time. On the machine's side a scan is one call of the machine: the input
edge (or none), with the timers whose preset has passed since their step's activation marked
elapsed first (several at once when they fall in the same scan, as on the PLC). After every
scan the active steps (MATIEC's step flags ``S12.X``) and the outputs must be equal.

Skipped unless Beremiz (``SYNTH_BEREMIZ``, ``SYNTH_BEREMIZ_PYTHON``), ``iec2c`` and gcc are here.
"""

from __future__ import annotations

import random
import re
import shutil
from dataclasses import dataclass, field, replace
from pathlib import Path

import pytest

from beremiz import beremiz_program, find_beremiz
from iec2c import CompiledProgram, find_iec2c
from test_sfc_meaning import GRAFCETS, SHARED
from synth.codegen.plcopen.export import sfc_project_xml
from synth.codegen.plcopen.tc6 import sfc_step_name
from synth.codegen.program import StProgram, case_aliases
from synth.codegen.st import Declaration, Pou, PouKind, SectionKind, VarSection
from synth.grafcet.language import Grafcet, Semantics, Transition
from synth.grafcet.language_check import load_grafcet, parse_grafcet
from synth.grafcet.machine import GrafcetMachine, Situation
from synth.logic.events import Event

PERIOD = 7
"""The PLC's scan period in the harness, in ms: no bundled preset is a multiple of it. On a
clock moving by exact steps that sum to a whole second, MATIEC's step time is one scan late
(:func:`test_matiec_sees_a_whole_second_step_time_one_scan_late`)."""
SEQUENCES, SCANS = 12, 150
"""Random sequences per Grafcet and scans per sequence."""
# GRAFCETS: the bundled ones but source_sink.g7, which synth sfc refuses (not IEC 61131-3 SFC);
EDGE = re.compile(r"_(RE|FE)_(\w+)")

needs_plc = pytest.mark.skipif(find_beremiz() is None or find_iec2c() is None or shutil.which("gcc") is None,
                               reason="Beremiz (SYNTH_BEREMIZ, SYNTH_BEREMIZ_PYTHON), iec2c and gcc are not here")


def program_inputs(text: str) -> list[str]:
    """The names in the ``VAR_INPUT`` sections of the program Beremiz generated."""
    return [n for block in re.findall(r"VAR_INPUT(.*?)END_VAR", text, re.S)
            for n in re.findall(r"^\s*(\w+)\s*:", block, re.M)]


@dataclass
class MachineSide:
    """``synth run --semantics sfc``, one call per PLC scan, with the clock of each step."""

    machine: GrafcetMachine
    sit: Situation
    inputs: dict[str, bool]
    period: int
    now: int
    since: dict[str, int]
    fired: set[Transition] = field(default_factory=set)

    def scan(self, inputs: dict[str, bool]) -> None:
        self.now += self.period
        g = self.machine.grafcet
        due = {t.id for t in g.timers if t.step in self.since and t.id not in self.sit.elapsed
               and self.now - self.since[t.step] >= round(t.seconds * 1000)}
        sit = replace(self.sit, elapsed=tuple(sorted({*self.sit.elapsed, *due}))) if due else self.sit
        changed = [n for n in g.inputs if inputs[n] != self.inputs[n]]
        event = Event.edge(changed[0], inputs[changed[0]]) if changed else None
        after, rounds = self.machine.react_event(sit, event, inputs)
        self.fired.update(t for fire in rounds for t in fire)
        self.since = {s: self.since[s] if s in self.sit.steps else self.now for s in after.steps}
        self.sit, self.inputs = after, dict(inputs)


@dataclass(frozen=True)
class Difference:
    """The first scan of a sequence where the PLC and the machine differ."""

    grafcet: str
    seed: int
    scan: int
    inputs: str
    expected: str
    got: str

    def text(self) -> str:
        return (f"{self.grafcet} seed {self.seed} scan {self.scan} (inputs {self.inputs}): "
                f"synth run --semantics sfc {self.expected}, the PLC {self.got}")


@dataclass(frozen=True)
class Outcome:
    """What a run on the PLC played: scans, transitions the machine fired, differences."""

    scans: int
    fired: frozenset[Transition]
    differences: tuple[Difference, ...]


def run_on_plc(g: Grafcet, folder: Path, seeds: range, scans: int, period: int = PERIOD) -> Outcome:
    """``g`` exported by ``synth sfc``, on the PLC and on the machine, one sequence of ``scans``
    scans per seed; the first difference of each sequence ends it."""
    g = replace(g, semantics=Semantics.SFC)
    folder.mkdir(parents=True, exist_ok=True)
    xml = sfc_project_xml(g, version="test")
    (folder / "plc.xml").write_bytes(xml)
    name = re.search(rb'<pou name="([^"]+)"', xml)[1].decode()  # type: ignore[index]  # clamp.g7: clamp_1
    text = beremiz_text(folder / "plc.xml", folder / "generated.st")
    alias = case_aliases([*g.inputs, *g.outputs, *(v.name for v in g.internals)], [sfc_step_name(s.name) for s in g.steps])
    st = {n: alias.get(n, n) for n in (*g.inputs, *g.outputs)}
    steps = {s.name: sfc_step_name(s.name) for s in g.steps}
    return play(g, PlcProgram(text, name, PouKind.PROGRAM, st, steps), folder, seeds, scans, period)


def beremiz_text(xml: Path, out: Path) -> str:
    """The program Beremiz's generator writes for the project ``xml``."""
    done = beremiz_program(xml, out)
    assert done.returncode == 0, done.stderr
    return out.read_text()


@dataclass(frozen=True)
class PlcProgram:
    """A program Beremiz generated (``text``), the POU that runs it, and the PLC's names of the
    Grafcet's inputs and outputs (``names``) and of the steps compared (``steps``); ``outputs``:
    those compared (None: every output)."""

    text: str
    pou: str
    kind: PouKind
    names: dict[str, str]
    steps: dict[str, str]
    outputs: tuple[str, ...] | None = None


def play(g: Grafcet, program: PlcProgram, folder: Path, seeds: range, scans: int, period: int = PERIOD) -> Outcome:
    """``program`` compiled by MATIEC against ``synth run --semantics sfc`` of ``g``, one sequence
    of ``scans`` scans per seed; the first difference of each sequence ends it."""
    g = replace(g, semantics=Semantics.SFC)
    text, st = program.text, program.names
    outputs = g.outputs if program.outputs is None else program.outputs
    declared = program_inputs(text)
    edges = {n: (m[1] == "RE", next(x for x in g.inputs if st[x] == m[2])) for n in declared if (m := EDGE.fullmatch(n))}
    pou = Pou(program.kind, program.pou, (
        VarSection(SectionKind.INPUT, tuple(Declaration(n) for n in declared)),
        VarSection(SectionKind.OUTPUT, tuple(Declaration(st[o]) for o in outputs)),
        VarSection(SectionKind.LOCAL, tuple(Declaration(f"{s}.X") for s in program.steps.values()))), ())
    machine = GrafcetMachine(g)
    played, differences, fired = 0, [], set()
    plc = CompiledProgram(StProgram(text, pou.name, (), (pou,)), folder / "c", pou=pou.name)
    start = plc.save()  # the program as loaded: each sequence starts from it
    try:
        for seed in seeds:
            rng = random.Random(seed)
            plc.restore(start)
            start = plc.save()
            inputs = {n: rng.random() < 0.3 for n in g.inputs}
            previous = dict(inputs)  # no edge at the first scan
            side: MachineSide | None = None
            for k in range(scans):
                if k and g.inputs and rng.random() < 0.5:
                    x = rng.choice(g.inputs)
                    inputs[x] = not inputs[x]
                if side is None:
                    sit = machine.initial(inputs)
                    initial = set(g.initial_steps)  # active from the start; the others from the first scan
                    side = MachineSide(machine, sit, dict(inputs), period, period,
                                       {s: 0 if s in initial else period for s in sit.steps})
                else:
                    side.scan(inputs)
                cells = {st[n]: v for n, v in inputs.items() if st[n] in declared}
                cells |= {n: inputs[x] != previous[x] and inputs[x] == rising for n, (rising, x) in edges.items()}
                previous = dict(inputs)
                plc.advance(period)
                plc.cycle(cells)
                played += 1
                want = (tuple(s for s in side.sit.steps if s in program.steps),
                        tuple(o for o in outputs if o in machine.orders(side.sit, inputs)))
                got = (tuple(s for s, name in program.steps.items() if plc.value(f"{name}.X")),
                       tuple(o for o in outputs if plc.value(st[o])))
                if sorted(want[0]) != sorted(got[0]) or want[1] != got[1]:
                    values = " ".join(f"{n}={int(v)}" for n, v in inputs.items())
                    differences.append(Difference(Path(g.path).name, seed, k, values, _text(want), _text(got)))
                    break
            fired |= side.fired if side is not None else set()
    finally:
        plc.close()
    return Outcome(played, frozenset(fired), tuple(differences))


def _text(state: tuple[tuple[str, ...], tuple[str, ...]]) -> str:
    return "steps {" + ", ".join(sorted(state[0])) + "} outputs {" + ", ".join(state[1]) + "}"


RANDOM_MISSES = {"tri_counting.g7": ["1->2", "2->0"]}
"""Transitions random inputs without a plant do not fire within the sequences played: three
boxes sorted in one cycle take some forty input changes in their order."""


@needs_plc
@pytest.mark.parametrize("path", GRAFCETS, ids=lambda p: p.name)
def test_the_plc_runs_every_bundled_grafcet_as_synth_run_sfc(path, tmp_path):
    g = load_grafcet(path)
    scans = scans_for(g)
    out = run_on_plc(g, tmp_path, range(SEQUENCES), scans)
    assert [d.text() for d in out.differences] == []
    assert out.scans == SEQUENCES * scans
    # every transition fired (the PLC: the same steps), but those random inputs do not reach
    assert [t.name for t in g.transitions if t not in out.fired] == RANDOM_MISSES.get(path.name, [])


def scans_for(g: Grafcet) -> int:
    """:data:`SCANS`, plus enough for the longest timer to elapse twice."""
    return SCANS + 2 * max((round(t.seconds * 1000) for t in g.timers), default=0) // PERIOD


# test_sfc_meaning's chart with RUN in two parallel steps, started and left on edges
SHARED_EDGES = SHARED.replace("0 -> 1, 2 when go", "0 -> 1, 2 when ↑go").replace("2 -> 4 when b", "2 -> 4 when ↓b")


@needs_plc
def test_the_plc_keeps_a_shared_order_and_its_edges_as_synth_run_sfc(tmp_path):
    """RUN emitted by two parallel steps (one conditionally), one of them left by a falling edge."""
    g = parse_grafcet(SHARED_EDGES, "shared.g7")
    assert [t.receptivity.text() for t in g.transitions] == ["↑go", "a", "↓b", "!go"]
    out = run_on_plc(g, tmp_path, range(SEQUENCES), SCANS)
    assert [d.text() for d in out.differences] == [] and out.scans == SEQUENCES * SCANS
    assert len(out.fired) == len(g.transitions)



@needs_plc
def test_a_shared_order_is_kept_when_the_initial_step_is_left_at_the_first_scan(tmp_path):
    """MATIEC sets an S action only while its step is active after a scan: the OR is carried by
    the steps the first scan reaches too (4 of the 12 seeds start with go)."""
    g = parse_grafcet(SHARED.replace("RUN if c", "RUN"), "first_scan.g7")
    out = run_on_plc(g, tmp_path, range(SEQUENCES), SCANS)
    assert [d.text() for d in out.differences] == [] and len(out.fired) == len(g.transitions)


TIMED = """inputs start
outputs HEAT
grafcet G {
  initial step 0
  step 1: HEAT
  step 2
  transition 0 -> 1 when start
  transition 1 -> 2 when %s/X1
  transition 2 -> 0 when !start
}
"""


@needs_plc
def test_matiec_sees_a_whole_second_step_time_one_scan_late(tmp_path):
    """MATIEC adds each scan's elapsed time to a step's ``T`` and normalises the sum only past
    10^9 ns: on a clock moving by exactly 10 ms (Beremiz's emulated cycle, OpenPLC's tick),
    ``T`` reaches 1 s as 0 s + 10^9 ns, which is less than ``T#1s``, so ``S1.T >= T#1s`` holds
    one scan after the preset; 990 ms is on time."""
    late = run_on_plc(parse_grafcet(TIMED % "1s", "late.g7"), tmp_path / "1s", range(1), 120, period=10)
    assert [d.text() for d in late.differences] == [
        "late.g7 seed 0 scan 102 (inputs start=1): synth run --semantics sfc steps {2} outputs {}, "
        "the PLC steps {1} outputs {HEAT}"]
    on_time = run_on_plc(parse_grafcet(TIMED % "990ms", "on_time.g7"), tmp_path / "990ms", range(1), 120, period=10)
    assert on_time.differences == () and len(on_time.fired) == 3
