"""CPU seconds of the filter's ``check + solve + st`` for one or more synth trees side by side,
on the families of ``bench/filter_scale.py`` (a loaded machine: trees and runs interleaved,
so a change in the load hits every tree alike; the minimum of the runs is printed).

    python3 bench/filter_trees.py --tree DIR [--tree DIR]... [--cases chain_256,ring_32] [--runs 2]

Each run is a fresh process (the tree first on ``PYTHONPATH``, started from a neutral
folder) that times, in CPU seconds of the process (``time.process_time``): ``check`` (P1–P4
and consistency, then the keep/force spellings ``synth filter check`` prints), ``solve`` and
``st`` (the algebraic and the loop blocks from that synthesis), then the whole process
(imports included) and its peak resident memory.
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
sys.path.insert(0, str(ROOT / "bench"))

from filter_scale import FAMILIES  # noqa: E402  (the bench folder is not a package)

STAGES = r"""
import json, resource, sys, time
from synth.filter.language_check import load_filter
from synth.filter.model import functions
from synth.filter.coherence import coherence
from synth.filter.reliefs import spelling_warnings
from synth.filter.solve import synthesis
from synth.codegen.filter_st import filter_block
out = {}
f = load_filter(sys.argv[1])
t = time.process_time(); coherence(functions(f)); w = spelling_warnings(f); out["check"] = time.process_time() - t
t = time.process_time(); s = synthesis(functions(f)); out["solve"] = time.process_time() - t
t = time.process_time()
filter_block(f, "algebraic", synthesis=s); filter_block(f, "loop", synthesis=s)
out["st"] = time.process_time() - t
usage = resource.getrusage(resource.RUSAGE_SELF)
out["process"] = usage.ru_utime + usage.ru_stime
out["mib"] = usage.ru_maxrss / 1024
out["warnings"] = len(w.warnings)
print(json.dumps(out))
"""


def run(tree: Path, path: Path) -> dict[str, float]:
    done = subprocess.run([sys.executable, "-c", STAGES, str(path)], capture_output=True, text=True, check=True,
                          env=dict(os.environ, PYTHONPATH=str(tree)), cwd=tempfile.gettempdir())
    return dict(json.loads(done.stdout))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tree", type=Path, action="append", required=True)
    ap.add_argument("--cases", default="chain_128,chain_256,ring_16,ring_32")
    ap.add_argument("--runs", type=int, default=2)
    args = ap.parse_args()
    trees = [t.resolve() for t in args.tree]
    print(f"{'case':<14} {'tree':<28} {'check':>7} {'solve':>7} {'st':>6} {'process':>8} {'MiB':>5}", flush=True)
    with tempfile.TemporaryDirectory() as d:
        for case in args.cases.split(","):
            family, _, n = case.rpartition("_")
            path = Path(d) / f"{case}.filter"
            path.write_text(FAMILIES[family](int(n)), encoding="utf-8")
            best: dict[Path, dict[str, float]] = {}
            for _ in range(args.runs):
                for tree in trees:
                    row = run(tree, path)
                    if tree not in best or row["process"] < best[tree]["process"]:
                        best[tree] = row
            for tree in trees:
                r = best[tree]
                print(f"{case:<14} {str(tree)[-28:]:<28} {r['check']:>7.2f} {r['solve']:>7.2f} {r['st']:>6.2f} "
                      f"{r['process']:>8.2f} {r['mib']:>5.0f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
