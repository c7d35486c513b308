"""Which form ``synth filter solve`` gives a filter, and what its symbolic chain of narrowings
costs: per case, the size the form is decided by (``synth.filter.narrowing.against``: what
the chain carries back against its elimination order, and the most outputs across one cut),
the form (equations up to ``TABLES_SIZE``, tables past it), and the chain's narrowings run
symbolically up to ``--cap`` CUDD lookups (``Engine.work``, the measure that decided the form
before session 30) with their CPU seconds.

    python3 bench/filter_form.py [--cap 40000000] CASE...

A CASE is a bench family and size (``ring_32``, ``grid_edges_40``), ``grid_edges:N:S`` (N
cylinders on S stations), or a ``.filter`` file. Each case runs in a fresh process.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

CASE = r"""
import json, sys, time
sys.path.insert(0, sys.argv[3])
from filter_scale import FAMILIES, grid_edges_filter
from synth.filter import narrowing
from synth.filter.language import Sense
from synth.filter.language_check import load_filter, parse_filter
from synth.filter.model import functions
from synth.filter.solve import TABLES_SIZE, criteria
case, cap = sys.argv[1], int(sys.argv[2])
if case.endswith(".filter"):
    f = load_filter(case)
elif case.count(":") == 2:
    _, n, stations = case.split(":")
    f = parse_filter(grid_edges_filter(int(n), int(stations)), "x.filter")
else:
    family, _, n = case.rpartition("_")
    f = parse_filter(FAMILIES[family](int(n)), "x.filter")
m = functions(f)
e = m.engine
goods = [e.expr(c.expr) if c.sense is Sense.MAX else ~e.expr(c.expr) for c in criteria(f)]
p = narrowing.layout(m, goods)
size, widest = narrowing.against(p, goods)
out = {"case": case, "size": size, "widest": widest, "form": "tables" if size > TABLES_SIZE else "equations",
       "criteria": len(goods)}
s, start, t = p.initial, e.work(), time.process_time()
for j, g in enumerate(goods):  # the narrowings alone, as synth.filter.narrowing.partitioned runs them
    if e.work() - start > cap:
        out["stopped_at"] = j + 1
        break
    k = p.position(g)
    best = p.project(s, k, g)
    if best & p.project(s, k, ~g) != e.false:
        s = p.refine(s, k, g.equiv(best))
out["lookups"], out["cpu"] = e.work() - start, round(time.process_time() - t, 2)
print(json.dumps(out))
"""


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("cases", nargs="+")
    ap.add_argument("--cap", type=int, default=40_000_000, help="stop the chain past this many lookups")
    args = ap.parse_args()
    print(f"{'case':<22} {'size':>6} {'widest':>6} {'form':<10} {'lookups':>12} {'CPU s':>7}", flush=True)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    for case in args.cases:
        done = subprocess.run([sys.executable, "-c", CASE, case, str(args.cap), str(ROOT / "bench")],
                              capture_output=True, text=True, env=env, check=True)
        r = json.loads(done.stdout)
        lookups = f"{r['lookups']:,}" + (f" (stopped at {r['stopped_at']}/{r['criteria']})" if "stopped_at" in r else "")
        print(f"{case:<22} {r['size']:>6} {r['widest']:>6} {r['form']:<10} {lookups:>12} {r['cpu']:>7.2f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
