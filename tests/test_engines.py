"""The one engine chooser (synth/engines.py, issue 34): every engine of ``validate``, ``sup``
and ``filter verify`` declares what it serves, ``auto`` reads one threshold table, and each
run reads each input file once, whatever the engine.

:class:`TestEveryEngine` runs the same assertions against every engine of
:data:`~synth.engines.CAPABILITIES` (as dd's tests run one suite against each BDD backend):
the command's plain run and one run per need, the same numbers from every engine that
declares the need, the one refusal (exit 2) from every engine that does not.
"""

from __future__ import annotations

import builtins
import json
from collections import Counter
from pathlib import Path
from typing import Any

import pytest

from conftest import ROOT
from synth.engines import (CAPABILITIES, PROBE_NODES, PROBE_SHARE, THRESHOLDS, Capability, Command, EngineChoice, Need,
                           Threshold, capability, decide, refusal)
from synth.errors import InputError
from synth.plant.composition import load_plant
from synth.probe import Growth, Stop

G, P, D = ROOT / "grafcets", ROOT / "plants", ROOT / "tests" / "data" / "filter"
TRI = ["validate", G / "tri.g7", "--plant", P / "tri.rules", "--json"]
TRI_STATS = {"plant_states": 62208, "sync_states": 150, "aggregated_states": 90, "aggregated_transitions": 280}
TWO = ["filter", "verify", D / "two_no_edge.filter", "--plant", D / "two.rules", "--json"]
TWO_ANY = {"safe": False, "coherent": True, "states": 7, "plant_states": 7, "cycles": 49, "outside_sup": 1}

# (command, need) -> the arguments ({tmp}: the test's folder), the exit code, fields of the JSON
RUNS: dict[tuple[Command, Need | None], tuple[list[Any], int, dict[str, Any]]] = {
    (Command.VALIDATE, None): (TRI, 0, {"verdict": "pass", "stats": TRI_STATS}),
    (Command.VALIDATE, Need.LISTING): ([*TRI, "--cor", "{tmp}/cor.json"], 0, {"verdict": "pass", "stats": TRI_STATS}),
    (Command.VALIDATE, Need.READS): (["validate", G / "tri_boxes.g7", "--plant", P / "tri_boxes.rules", "--json"], 0,
                                     {"verdict": "pass", "stats": {"plant_states": 228096, "sync_states": 336,
                                                                   "aggregated_states": 184,
                                                                   "aggregated_transitions": 550}}),
    (Command.VALIDATE, Need.SFC): ([*TRI, "--semantics", "sfc"], 1,
                                   {"verdict": "fail", "stats": {"plant_states": 62208, "sync_states": 372,
                                                                 "aggregated_states": 221,
                                                                 "aggregated_transitions": 657}}),
    (Command.SUP, None): (["sup", P / "tri.rules", "--json"], 0, {"states": 9180, "transitions": 75708}),
    (Command.SUP, Need.LISTING): (["sup", P / "tri.rules", "--why", "TAPIS,v10,v20,v30,v40", "--json"], 0,
                                  {"state": "{v10,v20,v30,v40,TAPIS}", "status": "kept"}),
    (Command.SUP, Need.READS): (["sup", P / "four_cylinders_pallet.rules", "--json"], 0,
                                {"states": 3168, "transitions": 14352}),
    (Command.FILTER_VERIFY, None): ([*TWO, "--any-control"], 1, TWO_ANY),
    (Command.FILTER_VERIFY, Need.CONTROLLER): ([*TWO, "--grafcet", D / "two.g7"], 1,
                                               {**TWO_ANY, "states": 3, "plant_states": 3, "cycles": 6}),
    (Command.FILTER_VERIFY, Need.PROGRESS): ([*TWO, "--any-control", "--progress", "A"], 1,
                                             {**TWO_ANY, "progress": {"holds": False, "avoiding": 3}}),
    (Command.FILTER_VERIFY, Need.READS): (["filter", "verify", P / "four_cylinders.filter", "--plant",
                                           P / "four_cylinders.rules", "--any-control", "--json"], 0,
                                          {"safe": True, "coherent": True, "states": 2160, "plant_states": 1584,
                                           "cycles": 16376, "outside_sup": 0}),
}


def fields(data: dict[str, Any], expected: dict[str, Any]) -> dict[str, Any]:
    """``data`` cut to the keys of ``expected`` (nested dicts too)."""
    return {k: fields(data[k], v) if isinstance(v, dict) else data[k] for k, v in expected.items()}


def count_reads(monkeypatch: pytest.MonkeyPatch, paths: set[Path]) -> Counter[Path]:
    """How many times each of ``paths`` is opened from now on (every user file is read
    through ``open``, by :func:`synth.syntax.read_source`)."""
    seen: Counter[Path] = Counter()
    real = builtins.open

    def counting(file: Any, *args: Any, **kwargs: Any) -> Any:
        if isinstance(file, (str, Path)) and Path(file).resolve() in paths:
            seen[Path(file).resolve()] += 1
        return real(file, *args, **kwargs)

    monkeypatch.setattr(builtins, "open", counting)
    return seen


def _cases() -> list[Any]:
    return [pytest.param(c, need, id=f"{c.command}-{c.engine}-{need or 'plain'}".replace(" ", "_"))
            for c in CAPABILITIES for (command, need) in RUNS if command is c.command]


class TestEveryEngine:
    """Each engine, on its command's plain run and on every need that command can have."""

    @pytest.mark.parametrize("cap, need", _cases())
    def test_serves_what_it_declares_and_refuses_the_rest(self, cli, monkeypatch, tmp_path, cap: Capability,
                                                          need: Need | None) -> None:
        args, code, expected = RUNS[(cap.command, need)]
        quiet = [] if cap.command is Command.FILTER_VERIFY else ["--quiet"]
        argv = [str(a).replace("{tmp}", str(tmp_path)) for a in args] + ["--engine", str(cap.engine), *quiet]
        inputs = {Path(a).resolve() for a in argv if Path(a).is_file()}
        assert len(inputs) == (1 if cap.command is Command.SUP else 2 + (need is Need.CONTROLLER))
        loaded = load_plant(next(a for a in argv if a.endswith(".rules")))  # before the count
        readers, reads_at = loaded.readers, loaded.reads_at
        reads = count_reads(monkeypatch, inputs)
        got, out, err = cli(*argv)
        if need is None or need in cap.serves:
            data = json.loads(out)
            assert (got, fields(data, expected)) == (code, expected)
            assert ("symbolic" in data or data.get("engine") == "symbolic") == (cap.engine is EngineChoice.SYMBOLIC)
            assert reads == Counter({p: 1 for p in inputs})  # each input file read once
        else:
            refused = refusal(cap.command, need, readers, reads_at)
            text = refused.render() if isinstance(refused, InputError) else f"error: {refused}"
            assert (got, out, err) == (2, "", text + "\n")
            assert max(reads.values(), default=0) <= 1

    def test_every_command_has_an_explicit_engine_serving_every_need(self) -> None:
        for command in Command:
            assert capability(command, EngineChoice.EXPLICIT).serves >= {n for c, n in RUNS if c is command and n}


def test_one_declaration_per_engine_and_command() -> None:
    pairs = [(c.command, c.engine) for c in CAPABILITIES]
    assert sorted(pairs) == sorted({(c, e) for c in Command for e in (EngineChoice.EXPLICIT, EngineChoice.SYMBOLIC)})
    assert set(THRESHOLDS) == set(Command)


def test_auto_reads_the_threshold_table_and_says_why() -> None:
    for command, t in THRESHOLDS.items():
        below = decide(command, "auto", estimate=t.size)
        above = decide(command, "auto", estimate=t.size + 1)
        assert (below.engine, above.engine) == (EngineChoice.EXPLICIT, EngineChoice.SYMBOLIC)
        assert below.reason == f"auto: {t.size} {t.estimate}, not above {t.size}"
        assert above.reason == f"auto: {t.size + 1} {t.estimate}, above {t.size}"
        assert not (below.measured or above.measured)
    asked: list[tuple[int, int]] = []

    def narrow(threshold: Threshold) -> Growth:
        assert threshold.points is not None
        asked.append((threshold.points.nodes, threshold.points.share))
        return Growth(448, 91, Stop.NARROW, share=45)

    t = THRESHOLDS[Command.VALIDATE]
    assert decide(Command.VALIDATE, "auto", estimate=t.size, growth=narrow).reason == \
        f"auto: {t.size} {t.estimate}, not above {t.size}"
    assert asked == []  # below the size, no probe
    chosen = decide(Command.VALIDATE, "auto", estimate=10**9, growth=narrow)
    assert asked == [(PROBE_NODES, PROBE_SHARE)] == [(400, 45)]
    assert (chosen.engine, chosen.measured) == (EngineChoice.EXPLICIT, True)
    assert chosen.reason == \
        "auto: explicit (measured: 91 of the 448 aggregated states met wait to be explored, not more than 45 %)"
    assert decide(Command.VALIDATE, "explicit", estimate=10**9, growth=narrow).reason == "--engine explicit"
    assert decide(Command.VALIDATE, "auto", {Need.SFC}, estimate=10**9, growth=narrow).engine is EngineChoice.EXPLICIT
    assert len(asked) == 1  # a forced engine or an unserved need asks no probe
    big = 10**9
    assert decide(Command.SUP, "auto", estimate=big, readers=("CELLS",)).reason == \
        "auto: the symbolic engine does not serve reads"
    assert decide(Command.FILTER_VERIFY, "auto", estimate=big, readers=("CELLS",)).engine is EngineChoice.SYMBOLIC
    assert decide(Command.FILTER_VERIFY, "auto", {Need.PROGRESS, Need.CONTROLLER}, estimate=big).reason == \
        "auto: the symbolic engine does not serve controller, progress"
    assert decide(Command.SUP, "symbolic").reason == "--engine symbolic"


def test_an_option_the_engine_asked_does_not_serve_is_refused_before_the_model_is_read(cli, monkeypatch) -> None:
    """``validate --report --engine symbolic``: no input read; ``filter verify --progress
    --engine symbolic``: the filter only (the command reads it first)."""
    four = P / "four_cylinders.filter", P / "four_cylinders.rules"
    reads = count_reads(monkeypatch, {G.resolve() / "tri.g7", P.resolve() / "tri.rules", *(f.resolve() for f in four)})
    assert cli(*TRI, "--report", "--engine", "symbolic")[0] == 2
    assert reads == Counter()
    code, _, err = cli("filter", "verify", four[0], "--plant", four[1], "--any-control", "--progress", "↑i2",
                       "--engine", "symbolic")
    assert (code, err) == (2, refusal(Command.FILTER_VERIFY, Need.PROGRESS).render() + "\n")
    assert reads == Counter({four[0].resolve(): 1})
