"""CPU seconds of reading generated Structured Text (``load_st``: parse and compile for the
interpreter), for one or more synth trees side by side (session 30).

    python3 bench/st_parse.py [--tree DIR]... [--runs 3] [--check]

Every run of a tree is a fresh process (that tree first on ``PYTHONPATH``, run from a neutral
folder) that generates the texts with its own synth and times each ``load_st`` alone with
``time.process_time``; the first line is the parser's set-up (a one-line program read
first: grammar tables from the disk cache, or built). Trees and runs are interleaved, the
minimum of the runs is printed. ``--check`` also times whole commands in fresh processes
(CPU of the child: ``synth st --check`` of the box sorting at depth 1, of ``tri_counting.g7``).

The texts: the box sorting's filter block (``plants/tri.filter``, loop algorithm with the
blocking mode, and the default algebraic block), the programs of ``tri.g7``,
``tri_counting.g7`` and ``four_cylinders.g7`` as ``st --check`` writes them, the compact
programs of five random Grafcets (``tests/randgrafcet.py``, seeds 1-5).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

SCRIPT = r"""
import json, sys, time
sys.path.insert(1, sys.argv[1] + "/tests")
from synth.codegen.filter_st import filter_block
from synth.codegen.grafcet_st import generate_program
from synth.codegen.interpreter.machine import load_st
from synth.filter.language_check import load_filter
from synth.grafcet.language_check import load_grafcet, parse_grafcet
from randgrafcet import random_grafcet
root = sys.argv[1]
texts = {"set-up (a one-line program)": "PROGRAM P\nVAR x : BOOL; END_VAR\nx := NOT x;\nEND_PROGRAM\n"}
tri = load_filter(root + "/plants/tri.filter")
texts["box sorting filter block, loop blocking"] = filter_block(tri, "loop", "blocking").text
texts["box sorting filter block, algebraic"] = filter_block(tri).text
for name in ("tri", "tri_counting", "four_cylinders"):
    texts[f"{name}.g7 program"] = generate_program(load_grafcet(f"{root}/grafcets/{name}.g7"), version="check").text
texts["5 random Grafcets' programs"] = [
    generate_program(parse_grafcet(random_grafcet(s), f"r{s}.g7"), version="test", comments=False).text for s in range(1, 6)]
out = {}
for name, text in texts.items():
    t = time.process_time()
    for one in ([text] if isinstance(text, str) else text):
        load_st(one, "b.st")
    out[name] = [time.process_time() - t, sum(map(len, [text] if isinstance(text, str) else text))]
print(json.dumps(out))
"""


def _child(tree: Path, argv: list[str]) -> tuple[float, str]:
    """CPU seconds (user + system) and stdout of one fresh process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run([sys.executable, *argv], capture_output=True, text=True, cwd=tempfile.gettempdir(),
                          env=dict(os.environ, PYTHONPATH=str(tree)))
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode not in (0, 1):
        raise SystemExit(f"{tree}: {argv[:4]} exited {done.returncode}: {done.stderr[-500:]}")
    return after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, done.stdout


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--tree", action="append", type=Path, help="a synth source tree (default: this one); repeat to compare")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--check", action="store_true", help="also time synth st --check commands")
    args = ap.parse_args()
    trees = [t.resolve() for t in args.tree or [ROOT]]
    best: dict[tuple[str, Path], float] = {}
    sizes: dict[str, int] = {}
    commands = {
        "st --check tri.g7 --depth 1": ["-m", "synth", "st", "--check", "grafcets/tri.g7", "--depth", "1"],
        "st --check tri_counting.g7 --depth 1": ["-m", "synth", "st", "--check", "grafcets/tri_counting.g7", "--depth", "1"],
    } if args.check else {}
    for _ in range(args.runs):
        for tree in trees:
            _, out = _child(tree, ["-c", SCRIPT, str(tree)])
            for name, (seconds, size) in json.loads(out).items():
                best[name, tree] = min(best.get((name, tree), seconds), seconds)
                sizes[name] = size
            for name, argv in commands.items():
                seconds, _ = _child(tree, [*argv[:4], str(tree / argv[4]), *argv[5:]])
                best[name, tree] = min(best.get((name, tree), seconds), seconds)
    for name in dict.fromkeys(n for n, _ in best):
        size = f" ({sizes[name]} characters)" if name in sizes else ""
        print(f"{name}{size}: " + " | ".join(f"{tree.name}: {best[name, tree]:.3f} CPU s" for tree in trees))
    return 0


if __name__ == "__main__":
    sys.exit(main())
