"""Start-up and end-to-end time of ``synth`` commands, a fresh process per run
(``python -S``: interpreter start included, site-packages' ``.pth`` hooks left out).

    python3 bench/startup.py [--runs 15] [--tree DIR] [--tree OTHER_DIR]

Each ``--tree`` is a synth source tree (default: this one); the commands run as
``python -S -m synth`` with that tree first on ``PYTHONPATH``, so two checkouts (say,
before and after a change) are measured side by side in one run, their runs
interleaved so that a change in the machine's load hits both alike. Prints the median
and the minimum of each command, in milliseconds, process start included, and the
floors under them measured the same way: the bare interpreter (``-c pass``),
``import numpy``, ``import lark`` and ``import numpy, lark`` (issue 37's floor, also run
interleaved with each command's runs, and each tree's median and minimum divided by it). The time
is the child's CPU time (user + system, ``resource.getrusage``: what a loaded machine
changes least), or its wall time with ``--wall``.

Like an installed wheel (pip compiles its ``.pyc`` files), every run reads compiled
bytecode: ``PYTHONDONTWRITEBYTECODE`` is removed from the environment, bytecode goes
to a temporary ``PYTHONPYCACHEPREFIX`` (the trees are left untouched), and one
untimed warm-up run per command and tree fills it (and lark's grammar cache) first.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
COMMANDS = {
    "--help": ["--help"],
    "validate --help": ["validate", "--help"],
    "validate tri.g7": ["validate", str(ROOT / "grafcets/tri.g7"), "--plant", str(ROOT / "plants/tri.rules")],
    "validate tri_missing_order.g7": ["validate", str(ROOT / "grafcets/tri_missing_order.g7"), "--plant", str(ROOT / "plants/tri.rules")],
}
FLOORS = {
    "python -S -c pass": ["-c", "pass"],
    "python -S -c 'import numpy'": ["-c", "import numpy"],
    "python -S -c 'import lark'": ["-c", "import lark"],
    "python -S -c 'import numpy, lark'": ["-c", "import numpy, lark"],
}
FLOOR = "python -S -c 'import numpy, lark'"  # issue 37's floor, run beside every command
WALL = False  # --wall: wall time instead of CPU time


def environment(tree: Path | None, pycache: str) -> dict[str, str]:
    """``tree`` first on ``PYTHONPATH`` (then this interpreter's site-packages, since
    ``-S`` leaves them out, so an editable install of synth cannot shadow ``tree``),
    bytecode read from and written to ``pycache``."""
    deps = [p for p in sys.path if p.endswith("site-packages")]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPATH"] = os.pathsep.join([*([str(tree.resolve())] if tree else []), *deps])
    env["PYTHONPYCACHEPREFIX"] = pycache
    return env


def run_once(args: list[str], env: dict[str, str], cwd: str) -> float:
    """CPU time (or wall time, ``WALL``) of one fresh ``python -S ARGS`` process, in
    milliseconds, run in ``cwd``, an empty folder (the current folder comes first on
    ``sys.path``: a stray ``.py`` file there could shadow a module)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-S", *args], cwd=cwd, env=env, capture_output=True, check=False)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if WALL:
        elapsed = (time.perf_counter() - start) * 1000
    else:
        elapsed = (after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime) * 1000
    if done.returncode not in (0, 1):  # validate exits 1 when it finds problems
        sys.exit(f"{' '.join(args)} failed ({done.returncode}):\n{done.stderr.decode(errors='replace')}")
    return elapsed


def measure(columns: list[tuple[list[str], dict[str, str]]], runs: int, cwd: str) -> list[list[float]]:
    """``runs`` timings of each column's command, the columns interleaved run by run,
    after one untimed warm-up run of each."""
    for args, env in columns:
        run_once(args, env, cwd)
    out: list[list[float]] = [[] for _ in columns]
    for _ in range(runs):
        for times, (args, env) in zip(out, columns):
            times.append(run_once(args, env, cwd))
    return out


def cell(ms: list[float]) -> str:
    return f"{statistics.median(ms):6.0f} ms (min {min(ms):4.0f})"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=15)
    ap.add_argument("--tree", action="append", type=Path, help="a synth source tree (repeatable)")
    ap.add_argument("--wall", action="store_true", help="wall time instead of the child's CPU time")
    ap.add_argument("--only", help="the commands to time, comma-separated names of COMMANDS (default: all)")
    args = ap.parse_args()
    global WALL
    WALL = args.wall
    trees = args.tree or [ROOT]
    with tempfile.TemporaryDirectory(prefix="synth-pycache-") as pycache, \
            tempfile.TemporaryDirectory(prefix="synth-startup-") as cwd:
        envs = [environment(tree, pycache) for tree in trees]
        floor_env = environment(None, pycache)
        print(f"python {sys.version.split()[0]}, {args.runs} runs per cell, median (minimum) "
              f"{'wall' if WALL else 'CPU'} time, "
              f"bytecode cached in a temporary PYTHONPYCACHEPREFIX; each row's runs interleaved with "
              f"those of the `import numpy, lark` floor, and each tree's ratio to it (medians, minimums)")
        print(f"{'command':<32}" + "".join(f"{t.resolve().name[:24]:>26}" for t in trees)
              + f"{'floor, same runs':>26}" + "".join(f"{'÷ floor':>16}" for _ in trees))
        for name, argv in COMMANDS.items():
            if args.only and name not in args.only.split(","):
                continue
            *row, floor = measure([(["-m", "synth", *argv], env) for env in envs] + [(FLOORS[FLOOR], floor_env)],
                                  args.runs, cwd)
            ratios = [f"{statistics.median(ms) / statistics.median(floor):.2f} {min(ms) / min(floor):.2f}" for ms in row]
            print(f"{name:<32}" + "".join(f"{cell(ms):>26}" for ms in [*row, floor]) + "".join(f"{r:>16}" for r in ratios))
        for name, argv in FLOORS.items():
            (ms,) = measure([(argv, floor_env)], args.runs, cwd)
            print(f"{name:<32}{cell(ms):>26}")


if __name__ == "__main__":
    main()
