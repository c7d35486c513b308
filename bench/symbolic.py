"""The symbolic engine against the explicit one, side by side, on three families.

    python3 bench/symbolic.py [--par 3..20] [--steep 3..8] [--branches 3x2..6] [--line 10,20]
                              [--budget 60] [--auto] [--json FILE]

- ``par_N`` (bench/gen_par.py: N cylinders extended and retracted together),
  ``steep_N`` (bench/gen_steep.py: N branches started at once on ``↑start``, joined once
  at the end) and ``branches_KxM`` (bench/gen_branches.py: K parallel branches, each a
  sequence of M cylinders, interlocks between neighbouring branches), each with its
  ``_missing`` variant: ``validate`` with ``--engine explicit`` and ``--engine symbolic``
  (and ``--engine auto`` with ``--auto``: which engine it ran, and its time), verdict,
  counts, CPU seconds and peak resident memory. An engine is not run again on a larger
  case of the same family once it exceeded its budget. Both outputs must be identical
  (the text report, byte for byte) where both finish.
- ``line_N`` (bench/gen_line.py): ``sup`` counts with ``--engine symbolic`` (and
  explicit where the plant fits the bitmap, up to line_9).

Each measurement is a fresh process (``python -m synth``, this tree first on the path)
with a CPU-time budget (``RLIMIT_CPU``, ``--budget`` seconds; the wall-clock limit is three
times that, the machine being shared); times are the CPU seconds of the whole command
(start-up included, user + system), memory the peak resident size of that process.
Prints Markdown tables; ``--json`` keeps the raw data.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Iterator

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

from gen_branches import write_branches  # noqa: E402
from gen_line import write_line  # noqa: E402
from gen_par import write_par  # noqa: E402
from gen_steep import write_steep  # noqa: E402

__all__ = ["run", "main", "cases"]

ENGINES = ("explicit", "symbolic")


def run(args: list[str], budget: float, tree: Path = ROOT) -> dict:
    """``python -m synth ARGS`` in a fresh process limited to ``budget`` CPU seconds, the synth
    of ``tree`` first on the path: exit code, stdout, stderr, CPU seconds, peak MiB."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    code = (
        "import resource, runpy, sys\n"
        f"resource.setrlimit(resource.RLIMIT_CPU, ({int(budget) + 1}, {int(budget) + 2}))\n"
        "sys.argv = ['synth'] + sys.argv[1:]\n"
        "try:\n"
        "    runpy.run_module('synth', run_name='__main__')\n"
        "except SystemExit as e:\n"
        "    c = e.code\n"
        "else:\n"
        "    c = 0\n"
        "sys.stdout.flush()\n"
        "u = resource.getrusage(resource.RUSAGE_SELF)\n"
        "sys.stderr.write(f'\\n@@ {u.ru_utime + u.ru_stime} {u.ru_maxrss}\\n')\n"
        "sys.exit(c)\n"
    )
    try:
        p = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, timeout=3 * budget, env=env,
                           cwd=str(tree))  # the tree first: `python -c` puts the working folder first on the path
    except subprocess.TimeoutExpired:
        return {"status": "timeout", "seconds": None, "mib": None}
    tail = [line for line in p.stderr.splitlines() if line.startswith("@@ ")]
    if not tail or p.returncode < 0:  # killed by SIGXCPU: over the budget
        return {"status": "timeout", "seconds": None, "mib": None}
    cpu, kib = float(tail[-1].split()[1]), int(tail[-1].split()[2])
    if cpu > budget:
        return {"status": "timeout", "seconds": None, "mib": None}
    return {"status": "ok" if p.returncode in (0, 1) else f"exit {p.returncode}", "code": p.returncode,
            "seconds": round(cpu, 2), "mib": round(kib / 1024), "stdout": p.stdout,
            "stderr": "\n".join(line for line in p.stderr.splitlines() if not line.startswith("@@ "))}


def _range(text: str) -> list[int]:
    if not text:
        return []
    if ".." in text:
        lo, hi = (int(x) for x in text.split(".."))
        return list(range(lo, hi + 1))
    return [int(x) for x in text.split(",")]


def cases(args: argparse.Namespace, d: str) -> Iterator[tuple[str, str, str, str]]:
    """(family, case name, grafcet path, rules path), smallest first in each family."""
    for n in _range(args.par):
        write_par(n, d)
        for name in (f"par_{n}", f"par_{n}_missing"):
            yield "par", name, f"{d}/{name}.g7", f"{d}/par_{n}.rules"
    for n in _range(args.steep):
        write_steep(n, d)
        for name in (f"steep_{n}", f"steep_{n}_missing"):
            yield "steep", name, f"{d}/{name}.g7", f"{d}/steep_{n}.rules"
    if args.branches:
        k, ms = args.branches.split("x")
        for m in _range(ms):
            write_branches(int(k), m, d)
            base = f"branches_{k}x{m}"
            for name in (base, f"{base}_missing"):
                yield "branches", name, f"{d}/{name}.g7", f"{d}/{base}.rules"


def _head(out: str) -> str:
    return out.splitlines()[0] if out else ""


def machine() -> dict:
    cpu = "?"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {"cpu": cpu, "nproc": os.cpu_count(), "python": platform.python_version(), "platform": platform.platform(),
            "load": os.getloadavg()}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--par", default="3..20", help="N for par_N: a range 3..20 or a list 3,5")
    ap.add_argument("--steep", default="3..8", help="N for steep_N")
    ap.add_argument("--branches", default="3x2..6", help="K x (M range) for branches_KxM, e.g. 3x2..6")
    ap.add_argument("--line", default="10,20", help="N for line_N SUP counts, comma separated")
    ap.add_argument("--budget", type=float, default=60.0, help="CPU seconds per run")
    ap.add_argument("--auto", action="store_true", help="also run --engine auto (which engine, its time)")
    ap.add_argument("--json", metavar="FILE", help="write the raw measurements")
    args = ap.parse_args(argv)
    rows: list[dict] = []
    with tempfile.TemporaryDirectory() as d:
        over: set[tuple[str, str]] = set()  # (family, engine) that exceeded the budget
        print("| case | verdict | SYNC states | aggregated | explicit s | explicit MiB | symbolic s | symbolic MiB | same output"
              + (" | auto → | auto s |" if args.auto else " |"))
        print("|---|---|---:|---:|---:|---:|---:|---:|---" + ("|---|---:|" if args.auto else "|"))
        for family, name, g7, rules in cases(args, d):
            base = ["validate", g7, "--plant", rules, "--quiet"]
            res: dict[str, dict] = {}
            for engine in ENGINES:
                if (family, engine) in over:
                    res[engine] = {"status": "not run"}
                    continue
                res[engine] = run(base + ["--engine", engine], args.budget)
                if res[engine]["status"] == "timeout":
                    over.add((family, engine))
            ex, sym = res["explicit"], res["symbolic"]
            auto: dict = {}
            if args.auto and not {(family, e) for e in ENGINES} <= over:
                auto = run(["validate", g7, "--plant", rules, "--engine", "auto"], args.budget)
                auto["chose"] = "symbolic" if "symbolic engine:" in auto.get("stderr", "") else "explicit"
            same = (ex.get("stdout") == sym.get("stdout")) if ex["status"] == "ok" and sym["status"] == "ok" else None
            head = _head(sym.get("stdout", "")) or _head(ex.get("stdout", ""))
            verdict = head.split(":")[0] if head else sym["status"]
            stats = head.split("SYNC ")[1].rstrip("]") if "SYNC " in head else ""
            sync_states = stats.split(" states")[0] if stats else ""
            agg = stats.split("aggregated ")[1].split(" states")[0] if "aggregated " in stats else ""
            row = {"family": family, "case": name, "verdict": verdict, "sync_states": sync_states, "aggregated": agg,
                   "explicit": {k: v for k, v in ex.items() if k not in ("stdout", "stderr")},
                   "symbolic": {k: v for k, v in sym.items() if k not in ("stdout", "stderr")},
                   "same_output": same, "symbolic_note": sym.get("stderr", "")[-200:]}
            if auto:
                row["auto"] = {k: v for k, v in auto.items() if k not in ("stdout", "stderr")}
            rows.append(row)

            def cell(r: dict, key: str) -> str:
                return str(r.get(key)) if r.get("status") == "ok" else r.get("status", "")

            line = (f"| {name} | {verdict} | {sync_states} | {agg} | {cell(ex, 'seconds')} | {cell(ex, 'mib')} | "
                    f"{cell(sym, 'seconds')} | {cell(sym, 'mib')} | {'yes' if same else ('–' if same is None else 'NO')} |")
            if args.auto:
                line += f" {auto.get('chose', '–')} | {cell(auto, 'seconds') if auto else '–'} |"
            print(line, flush=True)
        print()
        print("| line | SUP states | SUP transitions | symbolic s | symbolic MiB | explicit s | explicit MiB |")
        print("|---|---:|---:|---:|---:|---:|---:|")
        for n in (int(x) for x in args.line.split(",") if x):
            write_line(n, d)
            rules = f"{d}/line_{n}.rules"
            sym = run(["sup", rules, "--engine", "symbolic", "--json", "--quiet"], args.budget)
            ex = run(["sup", rules, "--engine", "explicit", "--json", "--quiet"], args.budget) if n <= 9 else {"status": "not run"}
            data = json.loads(sym["stdout"]) if sym["status"] == "ok" else {}
            if ex["status"] == "ok":
                e = json.loads(ex["stdout"])
                assert (e["states"], e["transitions"]) == (data["states"], data["transitions"]), "engines disagree"
            rows.append({"case": f"line_{n} sup", "states": data.get("states"), "transitions": data.get("transitions"),
                         "symbolic": {k: v for k, v in sym.items() if k not in ("stdout", "stderr")},
                         "explicit": {k: v for k, v in ex.items() if k not in ("stdout", "stderr")}})
            print(f"| line_{n} | {data.get('states')} | {data.get('transitions')} | {sym.get('seconds')} | {sym.get('mib')} | "
                  f"{ex.get('seconds', ex['status'])} | {ex.get('mib', '')} |", flush=True)
    info = machine()
    print(f"\nmachine: {info}")
    if args.json:
        Path(args.json).write_text(json.dumps({"machine": info, "rows": rows}, indent=2) + "\n")
    return 1 if any(r.get("same_output") is False for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
