"""The benchmark generator (bench/gen_line.py) and the libFAUDES route (bench/faudes_route.py).

No timing assertions: the timings live in docs/performance.md (bench/compare.py).
"""

from __future__ import annotations

import json

import subprocess
import sys

import pytest

from synth.plant.composition import plant
from synth.output.faudes import supervisor_generator
from synth.plant.rules_check import load_rules
from synth.sup.supervisor import supremal_controllable

from conftest import ROOT

BENCH = ROOT / "bench"
if str(BENCH) not in sys.path:
    sys.path.insert(0, str(BENCH))


def _generate(n, tmp_path):
    done = subprocess.run(
        [sys.executable, str(BENCH / "gen_line.py"), str(n), str(tmp_path)], capture_output=True, text=True, check=True
    )
    paths = [tmp_path / f"line_{n}.rules", tmp_path / f"line_{n}.g7", tmp_path / f"line_{n}_missing.g7"]
    assert done.stdout.split() == [str(p) for p in paths]
    return paths


def test_gen_line_2_loads_with_144_states(tmp_path):
    rules, g7, missing = _generate(2, tmp_path)
    assert "use " not in rules.read_text()  # the model is inlined: the file stands alone
    rs = load_rules(rules)
    p = plant(rs)
    assert p.size == 144 == 12**2
    assert p.count_transitions() == 36 * 2 * 12
    for e in p.elements:
        assert (e.size, e.count(True), e.count(False)) == (12, 24, 12)
    assert [c.id for c in rs.constraints] == ["K1", "K2", "N1"]
    assert "R1" in g7.read_text() and "R1 missing" in missing.read_text()


def test_gen_line_grafcets_parse(tmp_path):
    from synth import grafcet

    rules, g7, missing = _generate(3, tmp_path)
    rs = load_rules(rules)
    for path in (g7, missing):
        g = grafcet.load_grafcet(path, inputs=rs.inputs, outputs=rs.outputs)
        assert len(g.grafcets) == 1 and len(g.grafcets[0].steps) == 7


@pytest.mark.parametrize("n", [2, 3])
def test_line_sup_equals_libfaudes(n, tmp_path):
    faudes = pytest.importorskip("faudes")
    from faudes_route import run_faudes, write_inputs

    rules, _, _ = _generate(n, tmp_path)
    rs = load_rules(rules)
    p = plant(rs)
    sup = supremal_controllable(p, rs.constraints)
    theirs = run_faudes(write_inputs(rs, tmp_path / "faudes"), faudes)
    assert (theirs["plant"].Size(), theirs["plant"].TransRelSize()) == (p.size, p.count_transitions())
    assert (theirs["sup"].Size(), theirs["sup"].TransRelSize()) == (sup.size, sup.count_transitions())
    ours = tmp_path / "ours.gen"
    ours.write_text(supervisor_generator(sup))
    assert faudes.LanguageEquality(theirs["sup"], faudes.System(str(ours)))


def test_line_grafcets_validate(tmp_path, cli):
    """The complete line passes; the one without the middle retraction blocks there."""
    rules, g7, missing = _generate(3, tmp_path)
    code, out, _ = cli("validate", g7, "--plant", rules, "--quiet")
    assert code == 0, out
    code, out, _ = cli("validate", missing, "--plant", rules, "--quiet")
    assert code == 1
    assert "missing order R2" in out


def test_line_10_validates_on_the_fly(tmp_path, cli):
    """12^10 ≈ 6·10^10 plant states: validation explores only the reachable SYNC."""
    rules, g7, missing = _generate(10, tmp_path)
    code, out, _ = cli("validate", g7, "--plant", rules, "--quiet", "--json")
    data = json.loads(out)
    assert code == 0 and data["verdict"] == "pass"
    assert data["stats"]["plant_states"] == 12**10
    code, out, _ = cli("validate", missing, "--plant", rules, "--quiet", "--json")
    data = json.loads(out)
    assert code == 1
    (b,) = data["blocking"]
    assert b["situation"] == ["X10"]
    assert b["diagnosis"]["verdict"] == "missing_order"
    assert b["diagnosis"]["summary"].startswith("missing order R5 in step 10: transition 10->11 of LINE awaits a5_0")
    assert b["trace"][-2:] == ["↓a5_0", "↑a5_1"]
