"""Jobs per second of ``synth check --mutate`` on a line: serial baseline, the local pool
(one worker process per core) and a Dask LocalCluster of 2 worker processes; the plant
compilations per worker; that the three give the same results; and the cache (a second
``synth check`` with nothing changed, process start included).

    python3 bench/line.py [lines/example/synth.toml] [--no-mutate] [--json FILE]

Numbers in docs/performance.md ("A whole line").
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from synth.line.project import load_line  # noqa: E402
from synth.line.run import check_line  # noqa: E402
from synth.line.runners import default_workers  # noqa: E402


def timed(label: str, **kwargs):  # type: ignore[no-untyped-def]
    start = time.perf_counter()
    run = check_line(kwargs.pop("line"), None, **kwargs)
    seconds = time.perf_counter() - start
    n = len(run.results)
    row = {"mode": label, "jobs": n, "seconds": round(seconds, 2), "jobs_per_second": round(n / seconds, 2),
           "compilations_per_worker": sorted(run.stats.compiled.values())}
    print(f"{label:<22} {n:>5} jobs  {seconds:8.2f} s  {n / seconds:7.2f} jobs/s  compilations per worker "
          f"{row['compilations_per_worker']}", flush=True)
    return row, run.results


def cache_rerun(toml: str) -> dict[str, float]:
    """``synth check`` twice on an empty cache folder, as a user runs it (new processes)."""
    with tempfile.TemporaryDirectory() as d:
        cmd = [sys.executable, "-m", "synth", "check", toml, "--cache", f"{d}/cache", "--report", f"{d}/out", "--quiet"]
        times = []
        for _ in range(2):
            start = time.perf_counter()
            subprocess.run(cmd, check=False, capture_output=True, cwd=ROOT)
            times.append(time.perf_counter() - start)
    print(f"synth check, empty cache {times[0]:.2f} s; nothing changed {times[1]:.2f} s "
          f"({100 * times[1] / times[0]:.1f} %)", flush=True)
    return {"first": round(times[0], 2), "second": round(times[1], 2)}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("toml", nargs="?", default=str(ROOT / "lines" / "example" / "synth.toml"))
    p.add_argument("--no-mutate", action="store_true")
    p.add_argument("--json", metavar="FILE")
    args = p.parse_args()
    line = load_line(args.toml)
    mutate = not args.no_mutate
    rows = []
    row, serial = timed("serial", line=line, mutate=mutate, workers=1)
    rows.append(row)
    row, pooled = timed(f"local pool ({default_workers()} workers)", line=line, mutate=mutate)
    rows.append(row)
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster:
        row, dask = timed("Dask (2 workers)", line=line, mutate=mutate, cluster=cluster.scheduler_address)
    rows.append(row)
    same = serial == pooled == dask
    print(f"the same results in the three modes: {same}")
    for a, b, c in zip(serial, pooled, dask):
        if not a == b == c:
            print(f"  differs: {a['id']}")
    out = {"line": args.toml, "mutate": mutate, "runs": rows, "same_results": same, "cache": cache_rerun(args.toml)}
    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=2) + "\n", encoding="utf-8")
    if not same:
        sys.exit(1)


if __name__ == "__main__":
    main()
