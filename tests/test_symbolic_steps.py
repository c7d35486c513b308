"""The steps in the BDD (synth/symbolic/steps/encoding.py, steps/sync.py, steps/reach.py, steps/validate.py).

The exploration over (steps, plant state) must give the per-situation engine's counts;
a model it covers is decided on it (verdicts, components, first nodes, traces) and its
report is the explicit engine's, byte for byte; an unsupported model goes to the
per-situation engine (same report again).
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import pytest

from synth.grafcet.language_check import parse_grafcet
from synth.grafcet.machine import GrafcetMachine
from synth.logic.events import Event
from synth.output.result import validation_json, validation_text
from synth.symbolic import ties, validate as symbolic_validate
from synth.symbolic.encoding import Copy
from synth.symbolic.steps.encoding import StepEncoding, Unsupported, anchors, step_name, unsupported
from synth.symbolic.steps.sync import step_sync
from synth.symbolic.supervisor import SymbolicSupervisor
from synth.symbolic.situations.sync import symbolic_sync
from synth.symbolic.validate import validate_symbolic
from synth.validation.result import load_model
from synth.validation.validate import validate

from conftest import ROOT

sys.path.insert(0, str(ROOT / "bench"))
from gen_par import write_par  # noqa: E402
from gen_steep import write_steep  # noqa: E402

H = ROOT / "tests" / "data" / "home"


def _paths(family: str, n: int, tmp_path: Path) -> tuple[Path, Path, Path]:
    """(rules, passing grafcet, missing-order grafcet) of a generated family."""
    if family == "par":
        return write_par(n, tmp_path)
    r, g, missing = write_steep(n, tmp_path)
    return r, g, missing


@pytest.mark.parametrize("family,n", [("par", 3), ("steep", 3), ("par", 2)])
def test_counts_are_the_per_situation_engines(family, n, tmp_path):
    """Same SYNC states, aggregated states and transitions, situations; both variants."""
    r, g, missing = _paths(family, n, tmp_path)
    for grafcet in (g, missing):
        rs, p, gr = load_model(grafcet, r)
        s = step_sync(p, rs.constraints, GrafcetMachine(gr))
        o = symbolic_sync(p, rs.constraints, GrafcetMachine(gr))
        assert (s.sync_states, s.aggregated_states, s.edge_count, s.situations) == \
            (o.sync_states, o.aggregated_states, o.aggregated_transitions, len(o.situations))
        assert s.reached_steps() == frozenset(st for sit in o.situations for st in sit.steps)


def _probe(monkeypatch) -> list[bool]:
    """Record, per symbolic validation, whether the step path decided it."""
    taken: list[bool] = []
    inner = symbolic_validate.validate_steps

    def probe(*a, **k):
        v = inner(*a, **k)
        taken.append(v is not None)
        return v

    monkeypatch.setattr(symbolic_validate, "validate_steps", probe)
    return taken


def _same(grafcet: Path, rules: Path, homes=(), expert=False) -> None:
    a = validate(grafcet, rules, homes=homes, expert=expert)
    b = validate_symbolic(grafcet, rules, homes=homes, expert=expert)
    assert validation_text(b) == validation_text(a)
    assert json.dumps(validation_json(b), ensure_ascii=False) == json.dumps(validation_json(a), ensure_ascii=False)


@pytest.mark.parametrize("family,n", [("par", 3), ("steep", 3)])
def test_families_take_the_step_path(family, n, tmp_path, monkeypatch):
    r, g, missing = _paths(family, n, tmp_path)
    taken = _probe(monkeypatch)
    _same(g, r)
    _same(g, r, expert=True)
    _same(missing, r)  # blocks: component, first node and trace on the step path
    _same(missing, r, expert=True)
    assert taken == [True, True, True, True]


@pytest.mark.parametrize("grafcet,homes", [
    ("production_loop.g7", ()),  # a livelock without --home
    ("production_loop.g7", ("X1",)),
    ("production_loop.g7", ("X2 & v1",)),
    ("no_restart.g7", ()),  # blocks
    ("never_leaves.g7", ()),  # never leaves its initial step
])
@pytest.mark.parametrize("expert", [False, True])
def test_home_examples(grafcet, homes, expert, monkeypatch):
    taken = _probe(monkeypatch)
    _same(H / grafcet, H / "cylinder.rules", homes, expert)
    assert taken == [True]


@pytest.mark.parametrize("rules", ["cylinder_no_advance_at_rest.rules", "cylinder.rules"])
def test_prohibited_orders(rules, monkeypatch):
    taken = _probe(monkeypatch)
    _same(H / "prohibited_initial.g7", H / rules)
    assert taken == [True]


def test_unsupported_models():
    rs, p, g = load_model(ROOT / "grafcets" / "tri.g7", ROOT / "plants" / "tri.rules")
    assert unsupported(GrafcetMachine(g), p) == "timers"
    stored = parse_grafcet("inputs dcy, v0, v1\noutputs AVANCER, RECULER\n"
                           "grafcet G { initial step 0 step 1: set AVANCER on activation\n"
                           "transition 0 -> 1 when ↑dcy  transition 1 -> 0 when v1 }", "s.g7")
    rs, p, _ = load_model(H / "production_loop.g7", H / "cylinder.rules")
    assert unsupported(GrafcetMachine(stored), p) == "stored actions"


CONFLICT = """inputs dcy, v0, v1
outputs AVANCER, RECULER
grafcet G {
    initial step 0
    step 1: AVANCER
    step 2: AVANCER
    step 3: RECULER
    transition 0 -> 1 when ↑dcy
    transition 0 -> 2 when ↑dcy
    transition 1, 2 -> 3 when v1
    transition 3 -> 0 when v0
}
"""


def test_or_conflict_goes_per_situation(tmp_path, monkeypatch):
    """Two transitions leaving step 0 fire together: the report lists the conflict,
    which the per-situation engine finds; the step exploration gives up."""
    (tmp_path / "c.g7").write_text(CONFLICT)
    rs, p, g = load_model(tmp_path / "c.g7", H / "cylinder.rules")
    with pytest.raises(Unsupported, match="fired in the same round"):
        step_sync(p, rs.constraints, GrafcetMachine(g))
    taken = _probe(monkeypatch)
    _same(tmp_path / "c.g7", H / "cylinder.rules")
    assert taken == [False]


def test_receptivity_from_the_machines_cells():
    """``↑dcy . X2 | !v1``: after ↑dcy, true in step 2 (the edge reads no level: the event
    is the change) or when v1 is false; the edge is false for another event."""
    rs, p, _ = load_model(H / "production_loop.g7", H / "cylinder.rules")
    g = parse_grafcet("inputs dcy, v0, v1\noutputs AVANCER, RECULER\n"
                      "grafcet G { initial step 0 step 2: AVANCER\n"
                      "transition 0 -> 2 when ↑dcy . X2 | !v1  transition 2 -> 0 when v0 }", "r.g7")
    m = GrafcetMachine(g)
    sup = SymbolicSupervisor(p, rs.constraints, anchored=anchors(m, p))
    st = StepEncoding(m, sup.enc)
    e = sup.enc.engine
    x2 = e.var(step_name("2"))
    assert st.receptivity(0, Event.rise("dcy"), Copy.CURRENT) == x2 | ~e.var("v1")
    assert st.receptivity(0, Event.rise("v0"), Copy.CURRENT) == ~e.var("v1")
    assert st.receptivity(0, None, Copy.NEXT) == ~e.var("v1")
    assert st.receptivity(1, None, Copy.CURRENT) == e.var("v0")


@pytest.mark.parametrize("variant", [1, 2], ids=["branches_3x2", "branches_3x2_missing"])
def test_ties_as_the_explicit_engine(variant, tmp_path, monkeypatch):
    """``branches_3x2`` meets ties (docs/symbolic.md): regions that settle in several
    states. Both symbolic paths take, ring by ring, the node the explicit engine numbers
    first (``synth/symbolic/ties.py``) and print the explicit engine's report byte for
    byte. Past the region limit, the smallest node again: the same findings, numbered in
    another order."""
    from gen_branches import write_branches

    paths = write_branches(3, 2, tmp_path)
    rules, grafcet = paths[0], paths[variant]
    taken = _probe(monkeypatch)
    explicit = validate(grafcet, rules)
    steps = validate_symbolic(grafcet, rules)
    assert taken == [True]
    assert validation_text(steps) == validation_text(explicit)
    assert not steps.passed and steps.stats == explicit.stats
    monkeypatch.setattr(symbolic_validate, "unsupported", lambda m, p: "forced")
    assert validation_text(validate_symbolic(grafcet, rules)) == validation_text(explicit)

    def unnumbered(text: str) -> list[str]:
        return sorted(re.sub(r"^(\w+) \d+:", r"\1:", line) for line in text.splitlines())

    monkeypatch.setattr(ties, "REGION_LIMIT", 1)
    for forced in ("forced", None):  # the per-situation path, then the step path
        monkeypatch.setattr(symbolic_validate, "unsupported", lambda m, p, why=forced: why)
        limited = validation_text(validate_symbolic(grafcet, rules))
        assert limited != validation_text(explicit) and unnumbered(limited) == unnumbered(validation_text(explicit))
