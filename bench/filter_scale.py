"""How the safety logic filter scales with the number of outputs: ``check``, ``solve`` and
``st`` on three families of N outputs, with a truth-table oracle side by side at small N.

    python3 bench/filter_scale.py [--family ring|chain|grid|grid_edges] [--sizes 2,3,4,6,8] [--limit 60]
                                  [--oracle-max 3] [--json FILE]

- ``ring`` (``ring_filter(N)``): cylinders ``Q1..QN`` on a ring, each with ``bk`` (retracted),
  ``hk`` (extended) and ``ik`` (a part in front). Per cylinder, four simple constraints (extend
  only when retracted, not with parts in front of k and k+1, not in front of k while k+1 is
  out, never stop extending before the end) and one combined interlock ``Qk & Qk+1`` (keep
  ``Qk``), with the assumption that the filter never drove two neighbours together.
- ``chain`` (``chain_filter(N)``): outputs ``o1..oN`` and the pairwise exclusions
  ``oi & o(i+1)`` (keep ``oi``), nothing else.
- ``grid`` (``grid_filter(N)``, N a multiple of 8): 8 stations of N/8 outputs ``o<s>_<k>``;
  per output one start condition ``↑o & !ok`` (its own sensor), per station an emergency
  stop ``o & stop<s>`` on its first three outputs, interlocks between neighbours in a
  station ``o<s>_<k> & o<s>_<k+1>`` and between stations ``o<s>_<k> & o<s+1>_<k>`` (keep the
  first); 64 outputs give 200 constraints.
- ``grid_edges`` (``grid_edges_filter(N)``, N a multiple of 8; issue 37): 8 stations of N/8
  cylinders ``o<s>_<k>`` with end sensors ``b<s>_<k>`` (retracted) and ``h<s>_<k>`` (extended);
  per cylinder ``↑o & !b`` (extend only from the retracted end) and ``o & ↑h`` (stop driving
  when the extended end is reached, an edge on the sensor), interlocks between neighbours in
  a station ``o<s>_<k> & o<s>_<k+1>`` (keep the first) and between stations
  ``o<s>_<k> & o<s+1>_<k>`` (keep the *second*: the priorities run both ways across the grid);
  64 outputs give 240 constraints.

Per N, one fresh process runs the stages (``check``: P1–P4 and consistency, then the
keep/force spelling comparison ``synth filter check`` prints; ``st``: the algebraic and the
loop blocks, from the same synthesis) and reports CPU seconds and peak RSS; the sizes stop at the first N
whose process exceeds ``--limit`` seconds. Besides, the box-sorting filter of seed 004 end
to end: ``synth filter check``, ``solve`` and ``st`` as fresh processes (start included).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

STAGES = r"""
import json, resource, sys, time
from itertools import product
t0 = time.perf_counter()
from synth.filter.language_check import load_filter
from synth.filter.model import functions
from synth.filter.coherence import coherence
from synth.filter.solve import synthesis
from synth.codegen.filter_st import filter_block
out = {}
t = time.perf_counter(); f = load_filter(sys.argv[1]); out["parse"] = time.perf_counter() - t
t = time.perf_counter(); m = functions(f); c = coherence(m)
from synth.filter.reliefs import spelling_warnings  # what `synth filter check` adds: the keep/force spellings
w = spelling_warnings(f); out["check"] = time.perf_counter() - t
out["holds"] = c.holds
out["spelling_warnings"], out["spellings_not_compared"] = len(w.warnings), len(w.skipped)
t = time.perf_counter(); s = synthesis(m); out["solve"] = time.perf_counter() - t
out["functional"], out["consistent"] = s.functional, s.consistent
out["equation_chars"] = sum(len(x) for x in s.chained.values())
t = time.perf_counter()
fb = filter_block(f, "algebraic", synthesis=s); lp = filter_block(f, "loop", synthesis=s)  # the solve reused
out["st"] = time.perf_counter() - t
out["st_lines"] = fb.text.count("\n") + lp.text.count("\n")
out["bdd_nodes"] = m.engine.live_nodes()  # live: the table also holds dead nodes until a collection
out["cpu"] = time.process_time()
if int(sys.argv[2]):  # the truth-table oracle: global consistency by enumeration
    from synth.logic.expr import Edge, evaluate
    from synth.logic.past import pre_name
    t = time.perf_counter()
    from synth.logic.expr import names
    used = set()
    for e in [k.expr for k in f.safeties] + [a.expr for a in f.assumptions]:
        for v in names(e):
            used |= {v.name, pre_name(v.name)} if isinstance(v, Edge) else {v.name}
    ys = sorted(used - set(f.outputs))
    def val(e, p):
        def edge(x):
            now, before = p[x.name], p[pre_name(x.name)]
            return (not before and now) if x.rising else (before and not now)
        return bool(evaluate(e, lambda n: p[n], edge))
    bad = 0
    for yv in product((False, True), repeat=len(ys)):
        p = dict(zip(ys, yv))
        if not all(val(a.expr, p) for a in f.assumptions):
            continue
        if not any(not any(val(k.expr, {**p, **dict(zip(f.outputs, ov))}) for k in f.safeties)
                   for ov in product((False, True), repeat=len(f.outputs))):
            bad += 1
    out["oracle"] = time.perf_counter() - t
    out["oracle_consistent"] = bad == 0
    out["oracle_points"] = 2 ** len(ys)
out["total"] = time.perf_counter() - t0
out["peak_mib"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps(out))
"""


def ring_filter(n: int) -> str:
    """The ring of ``n`` cylinders as a ``.filter`` text."""
    ks = range(1, n + 1)
    nxt = {k: k % n + 1 for k in ks}
    lines = [f"# bench/filter_scale.py: a ring of {n} cylinders",
             "inputs " + ", ".join(f"b{k}, h{k}, i{k}" for k in ks),
             "outputs " + ", ".join(f"Q{k}" for k in ks)]
    lines += [f"assume !(Q{k}^-1 & Q{nxt[k]}^-1)" for k in ks]
    for k in ks:
        j = nxt[k]
        lines += [f"safety S{k}_1: ↑Q{k} & !b{k}",
                  f"safety S{k}_2: ↑Q{k} & i{k} & i{j}",
                  f"safety S{k}_3: ↑Q{k} & i{k} & !b{j}",
                  f"safety S{k}_4: ↓Q{k} & !h{k}",
                  f"safety K{k}: Q{k} & Q{j}   keep Q{k}"]
    return "\n".join(lines) + "\n"


def chain_filter(n: int) -> str:
    """The chain of ``n`` outputs with pairwise exclusions as a ``.filter`` text."""
    lines = [f"# bench/filter_scale.py: a chain of {n} outputs", "outputs " + ", ".join(f"o{k}" for k in range(1, n + 1))]
    lines += [f"safety K{k}: o{k} & o{k + 1}   keep o{k}" for k in range(1, n)]
    return "\n".join(lines) + "\n"


def grid_filter(n: int) -> str:
    """8 stations of ``n // 8`` outputs with interlocks between neighbours as a ``.filter`` text."""
    width = max(1, n // 8)
    cells = [(s, k) for s in range(1, 9) for k in range(1, width + 1)]

    def o(s: int, k: int) -> str:
        return f"o{s}_{k}"

    lines = [f"# bench/filter_scale.py: a grid of 8 stations x {width} outputs",
             "inputs " + ", ".join(f"ok{s}_{k}" for s, k in cells) + ", " + ", ".join(f"stop{s}" for s in range(1, 9)),
             "outputs " + ", ".join(o(s, k) for s, k in cells)]
    for s, k in cells:
        lines.append(f"safety A{s}_{k}: ↑{o(s, k)} & !ok{s}_{k}")
        if k <= 3:
            lines.append(f"safety E{s}_{k}: {o(s, k)} & stop{s}")
        if k < width:
            lines.append(f"safety H{s}_{k}: {o(s, k)} & {o(s, k + 1)}   keep {o(s, k)}")
        if s < 8:
            lines.append(f"safety V{s}_{k}: {o(s, k)} & {o(s + 1, k)}   keep {o(s, k)}")
    return "\n".join(lines) + "\n"


def grid_edges_filter(n: int, stations: int = 8) -> str:
    """``stations`` stations of ``n // stations`` cylinders with edge constraints on their end
    sensors and interlocks between neighbours both ways, as a ``.filter`` text."""
    width = max(1, n // stations)
    cells = [(s, k) for s in range(1, stations + 1) for k in range(1, width + 1)]

    def o(s: int, k: int) -> str:
        return f"o{s}_{k}"

    lines = [f"# bench/filter_scale.py: a grid of {stations} stations x {width} cylinders, edges on the end sensors",
             "inputs " + ", ".join(f"b{s}_{k}, h{s}_{k}" for s, k in cells),
             "outputs " + ", ".join(o(s, k) for s, k in cells)]
    for s, k in cells:
        lines.append(f"safety A{s}_{k}: ↑{o(s, k)} & !b{s}_{k}")  # extend only from the retracted end
        lines.append(f"safety B{s}_{k}: {o(s, k)} & ↑h{s}_{k}")  # stop driving when the extended end is reached
        if k < width:  # in a station: the cylinder before has the priority
            lines.append(f"safety H{s}_{k}: {o(s, k)} & {o(s, k + 1)}   keep {o(s, k)}")
        if s < stations:  # between stations: the later station has the priority
            lines.append(f"safety V{s}_{k}: {o(s, k)} & {o(s + 1, k)}   keep {o(s + 1, k)}")
    return "\n".join(lines) + "\n"


FAMILIES = {"ring": ring_filter, "chain": chain_filter, "grid": grid_filter, "grid_edges": grid_edges_filter}


def _env() -> dict[str, str]:
    return dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))


def run_size(n: int, directory: Path, limit: float, oracle: bool, family: str = "ring") -> dict:
    path = directory / f"{family}_{n}.filter"
    path.write_text(FAMILIES[family](n), encoding="utf-8")
    try:
        done = subprocess.run([sys.executable, "-c", STAGES, str(path), str(int(oracle))], capture_output=True,
                              text=True, timeout=limit, env=_env(), check=False)
    except subprocess.TimeoutExpired:
        return {"n": n, "timeout": limit}
    if done.returncode != 0:
        return {"n": n, "error": done.stderr.strip().splitlines()[-1:]}
    return {"n": n, **json.loads(done.stdout)}


def end_to_end(runs: int = 5) -> dict[str, float]:
    """Median wall time of the three box-sorting commands, fresh processes, start included."""
    tri = str(ROOT / "plants" / "tri.filter")
    out = {}
    with tempfile.TemporaryDirectory() as d:
        for name, argv in (("check", ["check", tri]), ("solve", ["solve", tri]),
                           ("st", ["st", tri, "-o", str(Path(d) / "fb.st")])):
            times = []
            for _ in range(runs):
                start = time.perf_counter()
                subprocess.run([sys.executable, "-m", "synth", "filter", *argv], capture_output=True, env=_env(), check=False)
                times.append(time.perf_counter() - start)
            out[name] = sorted(times)[len(times) // 2]
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--family", choices=sorted(FAMILIES), default="ring")
    ap.add_argument("--sizes", default="2,3,4,6,8,12,16,24,32,48,64")
    ap.add_argument("--limit", type=float, default=60.0, help="seconds per size (default 60)")
    ap.add_argument("--oracle-max", type=int, default=3, help="largest N checked by truth table (default 3)")
    ap.add_argument("--json", metavar="FILE", help="also write the rows as JSON")
    args = ap.parse_args()
    rows = []
    print(f"{'N':>4} {'outputs':>7} {'check s':>8} {'solve s':>8} {'st s':>7} {'total s':>8} {'CPU s':>6} {'MiB':>6} "
          f"{'BDD nodes':>9} {'eq chars':>8} {'oracle s':>9} {'oracle pts':>10} {'agree':>5}", flush=True)
    with tempfile.TemporaryDirectory() as d:
        for n in (int(x) for x in args.sizes.split(",")):
            row = run_size(n, Path(d), args.limit, n <= args.oracle_max, args.family)
            rows.append(row)
            if "timeout" in row or "error" in row:
                print(f"{n:>4} stopped: {row.get('error') or f'over {args.limit:g} s'}", flush=True)
                break
            oracle = (f"{row['oracle']:>9.3f} {row['oracle_points']:>10} "
                      f"{'yes' if row['oracle_consistent'] == row['consistent'] else 'NO':>5}") if "oracle" in row else ""
            print(f"{n:>4} {n:>7} {row['check']:>8.3f} {row['solve']:>8.3f} {row['st']:>7.3f} {row['total']:>8.3f} {row['cpu']:>6.2f} "
                  f"{row['peak_mib']:>6.0f} {row['bdd_nodes']:>9} {row['equation_chars']:>8} {oracle}", flush=True)
    if args.family != "ring":
        if args.json:
            Path(args.json).write_text(json.dumps({"rows": rows}, indent=2) + "\n", encoding="utf-8")
        return 0
    e2e = end_to_end()
    print("seed 004 box sorting, fresh process, start included (median of 5): "
          + ", ".join(f"filter {k} {v:.3f} s" for k, v in e2e.items()), flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps({"rows": rows, "box_sorting": e2e}, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
