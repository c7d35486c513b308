"""Start-up and end-to-end wall time of ``synth`` commands, a fresh process per run
(``python -S``: interpreter start included, site-packages' ``.pth`` hooks left out).

    python3 bench/startup.py [--runs 9] [--tree DIR] [--tree OTHER_DIR]

Each ``--tree`` is a synth source tree (default: this one); the commands run as
``python -m synth`` with that tree first on ``PYTHONPATH``, so two checkouts (say,
before and after a change) are measured side by side in one run. Prints the median
and the minimum of each command, in milliseconds, process start included.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
COMMANDS = {
    "--help": ["--help"],
    "validate tri.g7": ["validate", str(ROOT / "grafcets/tri.g7"), "--plant", str(ROOT / "plants/tri.rules")],
    "validate tri_missing_order.g7": ["validate", str(ROOT / "grafcets/tri_missing_order.g7"), "--plant", str(ROOT / "plants/tri.rules")],
}


def measure(tree: Path, argv: list[str], runs: int) -> list[float]:
    # -S: no site processing, so an editable install of synth cannot shadow ``tree``;
    # the dependencies come from this interpreter's site-packages, put after the tree.
    deps = [p for p in sys.path if p.endswith("site-packages")]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tree.resolve()), *deps]))
    out = []
    for _ in range(runs):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-S", "-m", "synth", *argv], cwd=tempfile.gettempdir(), env=env, capture_output=True, check=False)
        out.append((time.perf_counter() - start) * 1000)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=9)
    ap.add_argument("--tree", action="append", type=Path, help="a synth source tree (repeatable)")
    args = ap.parse_args()
    trees = args.tree or [ROOT]
    print(f"{'command':<32}" + "".join(f"{t.resolve().name[:24]:>28}" for t in trees))
    for name, argv in COMMANDS.items():
        row = []
        for tree in trees:
            ms = measure(tree, argv, args.runs)
            row.append(f"{statistics.median(ms):9.0f} ms (min {min(ms):5.0f})")
        print(f"{name:<32}" + "".join(f"{r:>28}" for r in row))


if __name__ == "__main__":
    main()
