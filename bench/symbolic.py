"""The symbolic engine against the explicit one, side by side.

    python3 bench/symbolic.py [--par 3..12] [--line 10,20] [--timeout 60] [--json FILE]

- ``par_N`` (bench/gen_par.py: N cylinders extended and retracted together) and
  ``par_N_missing``: ``validate`` with ``--engine explicit`` and ``--engine symbolic``,
  verdict, counts, seconds and peak resident memory; the explicit engine is not run
  again for larger N once it exceeded the time limit. Both outputs must be identical
  (the text report, byte for byte) where both finish.
- ``line_N`` (bench/gen_line.py): ``sup`` counts with ``--engine symbolic`` (and
  explicit where the plant fits the bitmap, up to line_9).

Each measurement is a fresh process (``python -m synth``, this tree first on the path);
times are wall seconds of the whole command (start-up included), memory the peak
resident size of that process. Prints a Markdown table; ``--json`` keeps the raw data.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

from gen_line import write_line  # noqa: E402
from gen_par import write_par  # noqa: E402

__all__ = ["run", "main"]


def run(args: list[str], timeout: float) -> dict:
    """``python -m synth ARGS`` in a fresh process: exit code, stdout, seconds, peak MiB."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    code = (
        "import resource, runpy, sys, time\n"
        "t = time.perf_counter()\n"
        "sys.argv = ['synth'] + sys.argv[1:]\n"
        "try:\n"
        "    runpy.run_module('synth', run_name='__main__')\n"
        "except SystemExit as e:\n"
        "    c = e.code\n"
        "else:\n"
        "    c = 0\n"
        "sys.stdout.flush()\n"
        "sys.stderr.write(f'\\n@@ {time.perf_counter() - t} {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss}\\n')\n"
        "sys.exit(c)\n"
    )
    start = time.perf_counter()
    try:
        p = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, timeout=timeout, env=env)
    except subprocess.TimeoutExpired:
        return {"status": "timeout", "seconds": None, "mib": None}
    wall = time.perf_counter() - start
    tail = [line for line in p.stderr.splitlines() if line.startswith("@@ ")]
    kib = int(tail[-1].split()[2]) if tail else 0
    return {"status": "ok" if p.returncode in (0, 1) else f"exit {p.returncode}", "code": p.returncode,
            "seconds": round(wall, 3), "mib": round(kib / 1024), "stdout": p.stdout,
            "stderr": "\n".join(line for line in p.stderr.splitlines() if not line.startswith("@@ "))}


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
    ap.add_argument("--par", default="3..12", help="range of N for par_N, e.g. 3..12")
    ap.add_argument("--line", default="10,20", help="N for line_N SUP counts, comma separated")
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds per run")
    ap.add_argument("--json", metavar="FILE", help="write the raw measurements")
    args = ap.parse_args(argv)
    lo, hi = (int(x) for x in args.par.split(".."))
    rows: list[dict] = []
    with tempfile.TemporaryDirectory() as d:
        explicit_ok = True
        print("| case | verdict | SYNC states | aggregated | explicit s | explicit MiB | symbolic s | symbolic MiB | same output |")
        print("|---|---|---:|---:|---:|---:|---:|---:|---|")
        for n in range(lo, hi + 1):
            write_par(n, d)
            for name in (f"par_{n}", f"par_{n}_missing"):
                base = ["validate", f"{d}/{name}.g7", "--plant", f"{d}/par_{n}.rules", "--quiet"]
                sym = run(base + ["--engine", "symbolic"], args.timeout)
                ex = run(base + ["--engine", "explicit"], args.timeout) if explicit_ok else {"status": "not run"}
                if ex["status"] == "timeout":
                    explicit_ok = False
                same = (ex.get("stdout") == sym.get("stdout")) if ex["status"] == "ok" and sym["status"] == "ok" else None
                head = _head(sym.get("stdout", "")) or _head(ex.get("stdout", ""))
                verdict = head.split(":")[0] if head else sym["status"]
                stats = head.split("SYNC ")[1].rstrip("]") if "SYNC " in head else ""
                sync_states = stats.split(" states")[0] if stats else ""
                agg = stats.split("aggregated ")[1].split(" states")[0] if "aggregated " in stats else ""
                row = {"case": name, "verdict": verdict, "sync_states": sync_states, "aggregated": agg,
                       "explicit": {k: v for k, v in ex.items() if k not in ("stdout", "stderr")},
                       "symbolic": {k: v for k, v in sym.items() if k not in ("stdout", "stderr")},
                       "same_output": same, "symbolic_note": sym.get("stderr", "")[-200:]}
                rows.append(row)

                def cell(r: dict, key: str) -> str:
                    return str(r.get(key)) if r.get("status") == "ok" else r.get("status", "")

                print(f"| {name} | {verdict} | {sync_states} | {agg} | {cell(ex, 'seconds')} | {cell(ex, 'mib')} | "
                      f"{cell(sym, 'seconds')} | {cell(sym, 'mib')} | {'yes' if same else ('–' if same is None else 'NO')} |",
                      flush=True)
        print()
        print("| line | SUP states | SUP transitions | symbolic s | symbolic MiB | explicit s | explicit MiB |")
        print("|---|---:|---:|---:|---:|---:|---:|")
        for n in (int(x) for x in args.line.split(",") if x):
            write_line(n, d)
            rules = f"{d}/line_{n}.rules"
            sym = run(["sup", rules, "--engine", "symbolic", "--json", "--quiet"], args.timeout)
            ex = run(["sup", rules, "--engine", "explicit", "--json", "--quiet"], args.timeout) if n <= 9 else {"status": "not run"}
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
