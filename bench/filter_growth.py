"""How large the functions ``synth filter solve`` computes grow with the width of a bench
family: the chain of narrowings alone (no races, no covers), per N in a fresh process.

    python3 bench/filter_growth.py [--family grid_edges] [--sizes 8,16,24,32,40] [--limit 300] [--sift]

Per N: the partition's elimination width, the chain's CPU seconds (its criteria applied one
after the other, then each output's ``∃O.(S ∧ o)`` and ``∃O.(S ∧ !o)``, as
:func:`synth.filter.narrowing.partitioned` does without its "no effect" races), the largest
``b_j = ∃O.(S_j ∧ g_j)`` of a criterion, the largest forward or backward message of the final
state, the BDD nodes of every output's ``∃O.(S ∧ o)`` added up (what the equations are
printed from), and the process's peak RSS. ``--sift``: then CUDD's sifting on the manager,
and the same sum of nodes in the order it finds (is the size the order's or the
function's?). The sizes stop at the first N over ``--limit`` CPU seconds.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parent))

from filter_scale import FAMILIES  # noqa: E402  (a sibling script, not a package)

CHAIN = r"""
import gc, json, resource, sys, time
from synth.filter.language import Sense
from synth.filter.language_check import load_filter
from synth.filter.model import functions
from synth.filter.narrowing import decided, layout
from synth.filter.solve import criteria
f = load_filter(sys.argv[1])
m = functions(f)
e = m.engine
goods = [e.expr(c.expr) if c.sense is Sense.MAX else ~e.expr(c.expr) for c in criteria(f)]
t = time.process_time()
p = layout(m, goods)
s, widest = p.initial, 0
for g in goods:
    k = p.position(g)
    best = p.project(s, k, g)
    widest = max(widest, len(best))
    s = p.refine(s, k, g.equiv(best))
care, ones, zeros = decided(p, s, list(p.anchors))
out = {"width": p.width, "criteria": len(goods), "chain_cpu": time.process_time() - t, "largest_best": widest}
n = len(p.anchors)
out["largest_message"] = max(len(u) for k in range(n) for u in (p.forward(s, k), p.backward(s, k)))
out["ones_nodes"] = sum(len(u) for u in ones.values())
if int(sys.argv[2]):
    del p, s
    gc.collect()
    t = time.process_time()
    e.bdd.reorder()
    out["sift_cpu"] = time.process_time() - t
    out["ones_nodes_sifted"] = sum(len(u) for u in ones.values())
out["peak_mib"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps(out))
"""


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--family", choices=sorted(FAMILIES), default="grid_edges")
    ap.add_argument("--sizes", default="8,16,24,32,40")
    ap.add_argument("--limit", type=float, default=300.0, help="seconds per size (default 300)")
    ap.add_argument("--sift", action="store_true", help="also sift the variable order and measure again")
    args = ap.parse_args()
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    print(f"{'N':>4} {'width':>5} {'chain s':>8} {'max b_j':>8} {'max msg':>8} {'Σ ∃O.(S∧o)':>11} "
          f"{'sifted':>8} {'MiB':>6}", flush=True)
    with tempfile.TemporaryDirectory() as d:
        for n in (int(x) for x in args.sizes.split(",")):
            path = Path(d) / f"{args.family}_{n}.filter"
            path.write_text(FAMILIES[args.family](n), encoding="utf-8")
            try:
                done = subprocess.run([sys.executable, "-c", CHAIN, str(path), str(int(args.sift))], capture_output=True,
                                      text=True, timeout=args.limit, env=env, check=False)
            except subprocess.TimeoutExpired:
                print(f"{n:>4} stopped: over {args.limit:g} s", flush=True)
                break
            if done.returncode:
                print(f"{n:>4} failed: {done.stderr.strip().splitlines()[-1:]}", flush=True)
                break
            r = json.loads(done.stdout)
            print(f"{n:>4} {r['width']:>5} {r['chain_cpu']:>8.2f} {r['largest_best']:>8} {r['largest_message']:>8} "
                  f"{r['ones_nodes']:>11} {r.get('ones_nodes_sifted', ''):>8} {r['peak_mib']:>6.0f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
