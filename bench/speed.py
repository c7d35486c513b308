"""CPU seconds of the everyday station, the symbolic SUP of long lines and the explicit
engine per SYNC state, for one or more synth trees side by side (issue 37).

    python3 bench/speed.py [--tree DIR]... [--runs 3] [--lines 100,200,300] [--explicit par_8,line_8]

Each measure runs in a fresh process (``python -m synth`` or a short script, that tree
first on ``PYTHONPATH``, run from a neutral folder so the tree is the one imported) and
is timed in CPU seconds (user + system of the child, ``resource.getrusage``): the machine
is shared, wall time says little. Trees and runs are interleaved, so a change in the
load hits every tree alike; the minimum of the runs is printed, then their median.

- ``four cylinders``: ``synth validate grafcets/four_cylinders.g7 --plant plants/four_cylinders.rules``
  (the whole command: start, constraints, SYNC, diagnosis, report text), its constraint
  grids read from the disk cache a first run wrote (``synth.sup.stored``); ``four cylinders,
  no cache``: the same with ``SYNTH_NO_CACHE=1``;
- ``sup line_N``: ``synth sup line_N.rules --engine symbolic --quiet`` on the line of N
  double-acting cylinders of ``bench/gen_line.py`` (a tree that fails says why);
- ``explicit sup line_N``: ``synth sup line_N.rules --engine explicit --json`` (its peak
  resident memory printed too);
- ``explicit F``: the explicit validation of a bench family (``par_8``: ``gen_par.py``,
  ``line_8``: ``gen_line.py``, ``steep_6``: ``gen_steep.py``, ``branches_2x3``:
  ``gen_branches.py 2 3``), timed inside the process from the loaded model to the
  result, divided by its SYNC states: microseconds per state.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

EXPLICIT = r"""
import json, os, sys, time
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # as the synth console script runs (cli.main.one_blas_thread)
from synth.validation.result import load_model
from synth.validation.validate import validate_loaded
rs, p, g = load_model(sys.argv[1], sys.argv[2])
t = time.process_time()
v = validate_loaded(rs, p, g)
print(json.dumps({"cpu": time.process_time() - t, "states": v.sync.sync_states}))
"""


def _child(tree: Path, argv: list[str], timeout: float) -> tuple[float, str, int, int]:
    """CPU seconds, stdout, exit code and peak resident KiB of one fresh process (an argv
    starting with ``NAME=VALUE`` words sets those in its environment)."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    while argv and "=" in argv[0] and not argv[0].startswith("-"):
        name, _, value = argv[0].partition("=")
        env[name], argv = value, argv[1:]
    with tempfile.TemporaryFile(mode="w+") as out:
        child = subprocess.Popen([sys.executable, *argv], stdout=out, stderr=subprocess.DEVNULL, text=True, env=env,
                                 cwd=tempfile.gettempdir())
        deadline = time.monotonic() + timeout
        while True:
            pid, status, usage = os.wait4(child.pid, os.WNOHANG)
            if pid:
                break
            if time.monotonic() > deadline:
                child.kill()
                pid, status, usage = os.wait4(child.pid, 0)
                return usage.ru_utime + usage.ru_stime, "", -1, usage.ru_maxrss
            time.sleep(0.05)
        child.returncode = os.waitstatus_to_exitcode(status)  # reaped here: Popen must not wait again
        out.seek(0)
        return usage.ru_utime + usage.ru_stime, out.read(), child.returncode, usage.ru_maxrss


def measures(work: Path, lines: list[int], families: list[str], explicit_sup: list[int] = ()) -> dict[str, list[str]]:
    """Name -> argv (after the interpreter) of every measure, its inputs generated into ``work``."""
    station = ["-m", "synth", "validate", str(ROOT / "grafcets/four_cylinders.g7"), "--plant", str(ROOT / "plants/four_cylinders.rules")]
    out = {"four cylinders": station, "four cylinders, no cache": ["SYNTH_NO_CACHE=1", *station]}
    for n in lines:
        subprocess.run([sys.executable, str(ROOT / "bench/gen_line.py"), str(n), str(work)], check=True, capture_output=True)
        out[f"sup line_{n}"] = ["-m", "synth", "sup", str(work / f"line_{n}.rules"), "--engine", "symbolic", "--quiet"]
    for n in explicit_sup:
        subprocess.run([sys.executable, str(ROOT / "bench/gen_line.py"), str(n), str(work)], check=True, capture_output=True)
        out[f"explicit sup line_{n}"] = ["-m", "synth", "sup", str(work / f"line_{n}.rules"), "--engine", "explicit", "--json"]
    for family in families:
        name, n = family.rsplit("_", 1)
        sizes = n.split("x")  # branches_3x2: gen_branches.py 3 2
        subprocess.run([sys.executable, str(ROOT / f"bench/gen_{name}.py"), *sizes, str(work)], check=True, capture_output=True)
        out[f"explicit {family}"] = ["-c", EXPLICIT, str(work / f"{family}.g7"), str(work / f"{family}.rules")]
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--tree", action="append", type=Path, help="a synth source tree (default: this one); repeat to compare")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--lines", default="100,200,300", help="line sizes for the symbolic SUP ('' for none)")
    ap.add_argument("--explicit", default="par_8,line_8", help="bench families for the explicit engine ('' for none)")
    ap.add_argument("--explicit-sup", default="10", help="line sizes for the explicit SUP ('' for none)")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per process")
    args = ap.parse_args()
    trees = args.tree or [ROOT]
    with tempfile.TemporaryDirectory() as tmp:
        todo = measures(Path(tmp), [int(n) for n in args.lines.split(",") if n], [f for f in args.explicit.split(",") if f],
                        [int(n) for n in args.explicit_sup.split(",") if n])
        for name, argv in todo.items():
            best: dict[Path, str] = {}
            cpu: dict[Path, float] = {}
            every: dict[Path, list[float]] = {tree: [] for tree in trees}  # the measure of each run, for the median
            per_state = name.startswith("explicit ") and not name.startswith("explicit sup")  # µs per SYNC state
            for _ in range(args.runs):
                for tree in trees:
                    seconds, out, code, peak = _child(tree, argv, args.timeout)
                    if code not in ((0,) if "sup" in name.split() else (0, 1)):  # validate: 1 is a failing model
                        best[tree] = "timeout" if code == -1 else f"exit {code}"
                        continue
                    if name.startswith("explicit sup"):
                        data = json.loads(out)
                        text = f"{seconds:.2f} CPU s, peak {peak // 1024} MiB, {data['states']} states, {data['transitions']} transitions"
                    elif name.startswith("explicit"):
                        data = json.loads(out)
                        seconds = data["cpu"]
                        text = f"{seconds:.2f} CPU s, {data['states']} SYNC states, {1e6 * seconds / data['states']:.0f} µs/state"
                    else:
                        text = f"{seconds:.2f} CPU s"
                    every[tree].append(1e6 * seconds / data["states"] if per_state else seconds)
                    if tree not in cpu or seconds < cpu[tree]:
                        cpu[tree], best[tree] = seconds, text
            for tree in trees:
                runs = sorted(every[tree])
                median = "" if not runs else (f", median {statistics.median(runs):.1f} µs/state" if per_state
                                              else f", median {statistics.median(runs):.2f} CPU s")
                print(f"{name:22} {str(tree):30} {best.get(tree, '-')}{median}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
