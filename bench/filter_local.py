"""Is there a small exact form of a synthesised filter when its flat functions are not
small? Two candidates measured on a bench family, one fresh process per N
(docs/performance.md, "Session 29: grid_edges 8 × 8"):

    python3 bench/filter_local.py chained [--family grid_edges] [--sizes 16,24,32] [--order rows]
    python3 bench/filter_local.py runtime [--family grid_edges] [--sizes 16,24,32,40,48,64] [--check 300]

- ``chained``: each output as a function of the Y near it and the outputs before it in an
  evaluation order (``rows``: station after station, ``columns``: cylinder after cylinder,
  ``reverse``): for output ``o_k`` with flat function ``f`` and ``agree`` (every earlier output
  equal to its function), the interval ``[f ∧ agree ∧ care, f ∨ ¬agree ∨ ¬care]`` holds a
  function free of the variables ``V`` of the cells farther than ``r`` (grid distance) iff
  ``∃V.L ≤ ∀V.U``; per output the smallest such ``r`` (up to 4, else none) and the nodes of
  ``∃V.L`` there. Built from the flat functions, so it runs where they do (to 8 × 4).
- ``runtime``: the chain of narrowings run at one valuation of Y with a truth table per bag
  of the partition (:mod:`synth.logic.partition`: anchor k and its frontier), as a PLC block
  would run it each cycle: the bags' constraints tabulated, then per criterion ``b_j`` (some
  entry of ``F_{k-1} ∧ D_k ∧ g_j ∧ B_{k+1}``; ``D_k ∧= g_j`` when there is one; the messages
  past the narrowed bag recomputed when next asked), then the one solution read back from
  the last bag. Prints the tables' total entries and the entries touched per cycle at
  three seeded points; ``--check K``: its outputs against the synthesis's functions at K
  random points of the care set (``synth filter solve`` runs there too, so small N only).
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import random
import re
import resource
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parent))

from filter_scale import FAMILIES  # noqa: E402  (a sibling script, not a package)

Valuation = tuple[bool, ...]


def _chain(family: str, n: int) -> tuple[Any, Any, list[Any], Any, Any]:
    """The filter's functions, its goods, the partition and the chain's final state."""
    from synth.filter.language import Sense
    from synth.filter.language_check import parse_filter
    from synth.filter.model import functions
    from synth.filter.narrowing import layout
    from synth.filter.solve import criteria

    f = parse_filter(FAMILIES[family](n), f"{family}_{n}.filter")
    m = functions(f)
    e = m.engine
    goods = [e.expr(c.expr) if c.sense is Sense.MAX else ~e.expr(c.expr) for c in criteria(f)]
    p = layout(m, goods)
    s = p.initial
    for g in goods:
        k = p.position(g)
        s = p.refine(s, k, g.equiv(p.project(s, k, g)))
    return m, e, goods, p, s


def _cell(name: str) -> tuple[int, int]:
    found = re.search(r"(\d+)_(\d+)", name)
    assert found is not None, name
    return int(found.group(1)), int(found.group(2))


def chained(family: str, n: int, order: str) -> dict[str, Any]:
    """Per output: the flat function's nodes, the smallest radius of a chained function and its nodes."""
    from synth.filter.narrowing import decided

    m, e, _, p, s = _chain(family, n)
    care, ones, _ = decided(p, s, list(p.anchors))
    outs = list(m.outputs)
    if order == "columns":
        outs.sort(key=lambda o: (_cell(o)[1], _cell(o)[0]))
    elif order == "reverse":
        outs.reverse()
    ys = [v for v in e.names if v not in m.outputs]
    agree, rows = e.true, []
    for idx, o in enumerate(outs):
        f = ones[o]
        low, high, here = f & agree & care, f | ~agree | ~care, _cell(o)
        found: tuple[int, int] | None = None
        for r in range(5):
            far = [v for v in ys + outs[:idx] if abs(_cell(v)[0] - here[0]) + abs(_cell(v)[1] - here[1]) > r]
            lower = e.exists(far, low)
            if e.implies(lower, e.forall(far, high)):
                found = (r, len(lower))
                break
        rows.append({"output": o, "flat": len(f), "radius": found and found[0], "nodes": found and found[1]})
        agree &= e.var(o).equiv(f)
    return {"outputs": rows}


class Runtime:
    """The chain at one valuation of Y on truth tables, one per bag (module docstring)."""

    def __init__(self, family: str, n: int) -> None:
        from synth.filter.language import Sense
        from synth.filter.language_check import parse_filter
        from synth.filter.model import functions
        from synth.filter.narrowing import layout
        from synth.filter.solve import criteria

        self.filter = parse_filter(FAMILIES[family](n), f"{family}_{n}.filter")
        self.m = m = functions(self.filter)
        e = self.engine = m.engine
        self.goods = [e.expr(c.expr) if c.sense is Sense.MAX else ~e.expr(c.expr) for c in criteria(self.filter)]
        p = self.partition = layout(m, self.goods)
        self.anchors = list(p.anchors)
        self.fronts = [p.frontier(k) for k in range(len(self.anchors))]
        self.bags = [(a, *fr) for a, fr in zip(self.anchors, self.fronts)]
        self.factors: list[list[Any]] = [[] for _ in self.anchors]
        for u in [~u for u in m.constraint.values()] + [m.assumed]:
            self.factors[p.position(u)].append(u)
        self.where = [p.position(g) for g in self.goods]
        self.touched = 0

    @property
    def entries(self) -> int:
        return sum(2 ** len(b) for b in self.bags)

    def _table(self, u: Any, names: tuple[str, ...]) -> dict[Valuation, bool]:
        e = self.engine
        self.touched += 2 ** len(names)
        return {v: e.let(dict(zip(names, v)), u) == e.true for v in itertools.product((False, True), repeat=len(names))}

    def _before(self, k: int) -> tuple[str, ...]:
        return self.fronts[k - 1] if k else ()

    def run(self, point: dict[str, bool]) -> dict[str, bool] | None:
        """The outputs the chain leaves at ``point`` (None: no safe vector there)."""
        e, n = self.engine, len(self.anchors)

        def at(u: Any) -> Any:
            return e.let({v: point[v] for v in e.support(u) if v in point}, u)

        domains = [self._table(at(e.conjunction(self.factors[k])), self.bags[k]) for k in range(n)]
        fwd: dict[int, dict[Valuation, bool]] = {}
        bwd: dict[int, dict[Valuation, bool]] = {}

        def pick(values: Valuation, k: int, names: tuple[str, ...]) -> Valuation:
            ix = {a: i for i, a in enumerate(self.bags[k])}
            return tuple(values[ix[a]] for a in names)

        def forward(k: int) -> dict[Valuation, bool]:  # F_k over the frontier of k
            if k < 0:
                return {(): True}
            if k not in fwd:
                before, msg = forward(k - 1), dict.fromkeys(itertools.product((False, True), repeat=len(self.fronts[k])), False)
                for values, ok in domains[k].items():
                    self.touched += 1
                    if ok and before[pick(values, k, self._before(k))]:
                        msg[values[1:]] = True
                fwd[k] = msg
            return fwd[k]

        def backward(k: int) -> dict[Valuation, bool]:  # B_k over the frontier before k
            if k >= n:
                return {(): True}
            if k not in bwd:
                after, msg = backward(k + 1), dict.fromkeys(itertools.product((False, True), repeat=len(self._before(k))), False)
                for values, ok in domains[k].items():
                    self.touched += 1
                    if ok and after[values[1:] if k + 1 < n else ()]:
                        msg[pick(values, k, self._before(k))] = True
                bwd[k] = msg
            return bwd[k]

        for g, k in zip(self.goods, self.where):
            wanted = self._table(at(g), self.bags[k])
            before, after = forward(k - 1), backward(k + 1)
            best = False
            for values, ok in domains[k].items():
                self.touched += 1
                if ok and wanted[values] and before[pick(values, k, self._before(k))] and \
                        after[values[1:] if k + 1 < n else ()]:
                    best = True
                    break
            if best and any(ok and not wanted[v] for v, ok in domains[k].items()):
                domains[k] = {v: ok and wanted[v] for v, ok in domains[k].items()}
                for j in [j for j in fwd if j >= k]:
                    del fwd[j]
                for j in [j for j in bwd if j <= k]:
                    del bwd[j]
        chosen: dict[str, bool] = {}
        for k in range(n - 1, -1, -1):  # the one solution, back from the last bag
            before = forward(k - 1)
            for values, ok in domains[k].items():
                if ok and before[pick(values, k, self._before(k))] and \
                        all(chosen.get(a, v) == v for a, v in zip(self.bags[k], values)):
                    chosen[self.anchors[k]] = values[0]
                    break
            else:
                return None
        return chosen


def runtime(family: str, n: int, check: int) -> dict[str, Any]:
    r = Runtime(family, n)
    e, rng = r.engine, random.Random(60848)
    ys = [v for v in e.names if v not in r.m.outputs]
    out: dict[str, Any] = {"outputs": len(r.anchors), "criteria": len(r.goods), "width": r.partition.width,
                           "entries": r.entries, "touched": [], "cpu": []}
    for _ in range(3):
        point = {y: rng.random() < 0.5 for y in ys}
        r.touched, t = 0, time.process_time()
        r.run(point)
        out["touched"].append(r.touched)
        out["cpu"].append(round(time.process_time() - t, 2))
    if check:
        from synth.filter.solve import synthesis

        s, equal = synthesis(r.m), 0
        while equal < check:
            point = {y: rng.random() < 0.5 for y in ys}
            if e.value(s.care, point):
                want = {o: e.value(s.outputs[o], point) for o in r.m.outputs}
                got = r.run(point)
                if got != want:
                    raise SystemExit(f"differs from the synthesis at {point}: {got} != {want}")
                equal += 1
        out["equal_points"] = equal
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("measure", choices=("chained", "runtime"))
    ap.add_argument("--family", choices=sorted(FAMILIES), default="grid_edges")
    ap.add_argument("--sizes", default=None)
    ap.add_argument("--order", choices=("rows", "columns", "reverse"), default="rows")
    ap.add_argument("--check", type=int, default=0, help="runtime: compare with the synthesis at this many points")
    ap.add_argument("--one", type=int, default=None, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one is not None:
        out = chained(args.family, args.one, args.order) if args.measure == "chained" else \
            runtime(args.family, args.one, args.check)
        usage = resource.getrusage(resource.RUSAGE_SELF)
        out["process_cpu"], out["mib"] = usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024
        print(json.dumps(out))
        return 0
    sizes = args.sizes or ("16,24,32" if args.measure == "chained" else "16,24,32,40,48,64")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    for n in (int(x) for x in sizes.split(",")):
        done = subprocess.run([sys.executable, __file__, args.measure, "--family", args.family, "--order", args.order,
                               "--check", str(args.check), "--one", str(n)], capture_output=True, text=True, env=env,
                              check=False)
        if done.returncode:
            print(f"{n}: failed: {(done.stderr or done.stdout).strip().splitlines()[-1:]}", flush=True)
            return 1
        r = json.loads(done.stdout)
        if args.measure == "chained":
            largest = max(r["outputs"], key=lambda row: row["nodes"] if row["nodes"] is not None else 10 ** 9)
            print(f"N={n} largest flat {max(row['flat'] for row in r['outputs'])}, largest chained "
                  f"{largest['nodes']} ({largest['output']}, radius {largest['radius']}), "
                  f"radii {sorted({row['radius'] for row in r['outputs']}, key=str)}, "
                  f"{r['process_cpu']:.1f} CPU s, {r['mib']:.0f} MiB", flush=True)
            for row in r["outputs"]:
                print(f"    {row['output']:<8} flat {row['flat']:>6}  radius {row['radius']}  nodes {row['nodes']}")
        else:
            print(f"N={n} width {r['width']}, criteria {r['criteria']}, table entries {r['entries']}, touched per "
                  f"cycle {r['touched']} ({r['cpu']} CPU s in Python)"
                  + (f", equal to the synthesis at {r['equal_points']} points" if 'equal_points' in r else "")
                  + f", {r['mib']:.0f} MiB", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
