"""``synth filter verify --any-control`` on both engines, on a ring of N cylinders turning
pallets (the four cylinders of seed 000 §6, plants/four_cylinders*.rules, grown to N):
states, CPU seconds and peak MiB of each engine side by side.

    python3 bench/verify_scale.py [--sizes 4,5,6,8] [--pallets 1] [--k 1] [--limit 300]
                                  [--engines explicit,symbolic] [--json FILE]
                                  [--counter 15,17] [--tree DIR]...

- ``ring_rules(n, pallets)``: cylinders C1..CN (plants/lib/four_cylinders.rules, ``pusher``)
  and cells CELL1..CELLN (``full_cell`` for the first ``pallets`` cells, ``cell`` otherwise),
  the constraints Ek, Kk, Jk of four_cylinders.rules by analogy;
- ``ring_filter(n)``: plants/four_cylinders.filter by analogy: six simple constraints per
  cylinder, one combined ``ik & Qk & Qk+1 keep Qk``, the observers X3k.

- ``counter_rules(n)``, ``--counter``: one element of n sensors and an order (2^(n+1)
  codes, every sensor rising under the order), its filter, ``--max-states 100``: the cost
  of reading a large element's moves before the first state (tests/test_plant_closure.py).

With ``--tree DIR`` (repeatable) every run is made once per tree, one after the other
(that tree alone on ``PYTHONPATH``, run from a neutral folder): a before and an after
interleaved in the same minutes.

The plant's grid has 24^N states (6 per cylinder, 4 per cell): neither engine holds an
array over it (the explicit one computes what it needs for the states it reaches,
synth/filter/loop/columns.py). Each (N, engine) runs in a fresh process
(``synth filter verify ... --engine E --json``); its CPU seconds and peak RSS come from
``resource.getrusage`` of the child; a run past ``--limit`` seconds is killed.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LIB = ROOT / "plants" / "lib" / "four_cylinders.rules"


def ring_rules(n: int, pallets: int = 1) -> str:
    """The ring of ``n`` cylinders and cells with ``pallets`` pallets, as a rules text."""
    ks = range(1, n + 1)

    def nxt(k: int) -> int:
        return k % n + 1

    def prv(k: int) -> int:
        return (k - 2) % n + 1

    lines = [f"# bench/verify_scale.py: a ring of {n} cylinders, {pallets} pallet(s)",
             "inputs  " + ", ".join(f"b{k}" for k in ks) + ", " + ", ".join(f"h{k}" for k in ks) + ", "
             + ", ".join(f"i{k}" for k in ks),
             "outputs " + ", ".join(f"Q{k}" for k in ks),
             f'use "{LIB}"']
    lines += [f"element C{k} = pusher(Q=Q{k}, b=b{k}, h=h{k}, i=i{k}, t=t{nxt(k)})" for k in ks]
    for k in ks:
        p = prv(k)
        model = "full_cell" if k <= pallets else "cell"
        lines.append(f"element CELL{k} = {model}(i=i{k}, t=t{k}, Qp=Q{p}, bp=b{p}, hp=h{p}, ip=i{p}, "
                     f"Qk=Q{k}, bk=b{k}, tn=t{nxt(k)})")
    lines += [f'constraint E{k} "extend {k} only when retracted": ↑Q{k} & !b{k} = 0' for k in ks]
    lines += [f'constraint K{k} "a pallet travels into cell {k} while cylinder {k} is out": t{k} & !b{k} = 0'
              for k in ks]
    lines += [f'constraint J{k} "a pallet is pushed into the occupied cell {k}": i{prv(k)} & t{k} & i{k} = 0'
              for k in ks]
    return "\n".join(lines) + "\n"


def ring_filter(n: int) -> str:
    """plants/four_cylinders.filter for ``n`` cylinders, as a filter text."""
    ks = range(1, n + 1)

    def nxt(k: int) -> int:
        return k % n + 1

    def prv(k: int) -> int:
        return (k - 2) % n + 1

    lines = [f"# bench/verify_scale.py: the four cylinders' filter for {n} cylinders",
             "inputs  " + ", ".join(f"b{k}, h{k}, i{k}" for k in ks),
             "outputs " + ", ".join(f"Q{k}" for k in ks)]
    for k in ks:
        j = nxt(k)
        lines += [f"safety CSs{k}_1: ↑Q{k} & !b{k}",
                  f"safety CSs{k}_2: ↑Q{k} & i{k} & i{j}",
                  f"safety CSs{k}_3: ↑Q{k} & i{k} & !b{j}",
                  f"safety CSs{k}_4: ↑Q{k} & X3{k}",
                  f"safety CSs{k}_5: ↑Q{k} & Q{j}^-1 & i{k}",
                  f"safety CSs{k}_6: ↓Q{k} & !h{k}"]
    lines += [f"safety CSc{k}: i{k} & Q{k} & Q{nxt(k)}   keep Q{k}" for k in ks]
    lines += [f"observer X3{k} := Q{prv(k)}^-1 & (i{prv(k)} | X3{k}^-1)" for k in ks]
    return "\n".join(lines) + "\n"


def counter_rules(n: int) -> str:
    """One element of ``n`` sensors and an order A: every sensor rises while A is on."""
    ks = range(1, n + 1)
    return (f"inputs {', '.join(f's{i}' for i in ks)}\noutputs A\nmodel counter {{\n    orders A = 0\n"
            f"    sensors {', '.join(f's{i} = 0' for i in ks)}\n" + "\n".join(f"    ↑A [!s{i}] -> ↑s{i}" for i in ks)
            + f'\n}}\nelement C = counter()\nconstraint K "not with the last sensor": A & s{n} = 0\n')


def counter_filter(n: int) -> str:
    return f"inputs s1, s{n}\noutputs A\nsafety K: A & s{n}\n"


def run(filter_path: Path, rules_path: Path, engine: str, k: int, limit: float, tree: Path = ROOT,
        extra: tuple[str, ...] = ()) -> dict:
    """One verification in a fresh process: its JSON summary, CPU seconds, peak MiB."""
    cmd = [sys.executable, "-m", "synth", "filter", "verify", str(filter_path), "--plant", str(rules_path),
           "--any-control", "--events-per-cycle", str(k), "--engine", engine, "--json", *extra]
    env = dict(os.environ, PYTHONPATH=str(tree))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=limit, env=env, cwd=tempfile.gettempdir())
    except subprocess.TimeoutExpired:
        return {"engine": engine, "outcome": f"killed after {limit:.0f} s"}
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    out: dict = {"engine": engine, "wall": round(time.perf_counter() - t0, 2),
                 "cpu": round(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, 2),
                 "peak_mib": round(after.ru_maxrss / 1024)}  # the largest child so far (fresh per call: see main)
    if proc.returncode in (0, 1) or proc.stdout.startswith("{"):  # exit 2 with a report: stopped at the budget
        data = json.loads(proc.stdout)
        out.update(outcome=("safe" if data["safe"] else "unsafe") + ("" if data["complete"] else ", stopped"),
                   states=data["states"],
                   plant_states=data["plant_states"], cycles=data["cycles"])
    else:
        out["outcome"] = proc.stderr.strip().splitlines()[-1][:120] if proc.stderr.strip() else f"exit {proc.returncode}"
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="4,5,6,8", help="rings of N cylinders ('' for none)")
    ap.add_argument("--counter", default="", help="single elements of N sensors (--max-states 100)")
    ap.add_argument("--pallets", type=int, default=1)
    ap.add_argument("--k", type=int, default=1, help="plant events per PLC cycle")
    ap.add_argument("--limit", type=float, default=300.0, help="seconds per run")
    ap.add_argument("--engines", default="explicit,symbolic")
    ap.add_argument("--tree", action="append", type=Path, help="a synth tree (repeatable; default: this one)")
    ap.add_argument("--json", metavar="FILE")
    ap.add_argument("--one", nargs=6, metavar=("FAMILY", "N", "PALLETS", "K", "ENGINE", "TREE"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:  # one run in this (fresh) process: its own peak RSS
        family, n, pallets, k, engine, tree = args.one
        with tempfile.TemporaryDirectory() as tmp:
            r, f = Path(tmp) / f"{family}{n}.rules", Path(tmp) / f"{family}{n}.filter"
            ring = family == "ring"
            r.write_text(ring_rules(int(n), int(pallets)) if ring else counter_rules(int(n)))
            f.write_text(ring_filter(int(n)) if ring else counter_filter(int(n)))
            print(json.dumps(run(f, r, engine, int(k), args.limit, Path(tree),
                                 () if ring else ("--max-states", "100"))))
        return
    trees = args.tree or [ROOT]
    cases = [("ring", int(x)) for x in args.sizes.split(",") if x]
    cases += [("counter", int(x)) for x in args.counter.split(",") if x]
    rows = []
    print(f"{'case':>10} {'grid':>10} {'engine':>9} {'tree':>12} {'outcome':>13} {'states':>8} {'plant st.':>9} "
          f"{'cycles':>10} {'CPU s':>8} {'peak MiB':>9}")
    for family, n in cases:
        grid = 24**n if family == "ring" else 2**(n + 1)
        for engine in args.engines.split(","):
            for tree in trees:
                proc = subprocess.run([sys.executable, __file__, "--limit", str(args.limit), "--one", family, str(n),
                                       str(args.pallets), str(args.k), engine, str(tree.resolve())],
                                      capture_output=True, text=True)
                r = json.loads(proc.stdout) if proc.returncode == 0 else {"engine": engine, "outcome": proc.stderr[-200:]}
                r.update(family=family, n=n, grid=grid, pallets=args.pallets, k=args.k, tree=str(tree))
                rows.append(r)
                outcome = r["outcome"] if len(r["outcome"]) <= 13 else "-"
                print(f"{family + ' ' + str(n):>10} {grid:>10.3g} {engine:>9} {tree.name[-12:]:>12} {outcome:>13} "
                      f"{r.get('states', '-'):>8} {r.get('plant_states', '-'):>9} {r.get('cycles', '-'):>10} "
                      f"{r.get('cpu', '-'):>8} {r.get('peak_mib', '-'):>9}"
                      + ("" if len(r["outcome"]) <= 13 else f"  {r['outcome']}"), flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1) + "\n")


if __name__ == "__main__":
    main()
