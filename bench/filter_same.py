"""Whether two synth trees print the same filter reports, byte for byte: ``filter check
--json``, ``check``, ``solve --json``, ``solve``, ``st`` and ``st --algorithm loop`` (stdout,
stderr and exit code) on the bundled ``.filter`` files and the scale families of
``bench/filter_scale.py``. A change meant to make the filter faster keeps every one of them.

    python3 bench/filter_same.py --tree DIR --save OUT        # one tree's reports into OUT
    python3 bench/filter_same.py --compare OUT_A OUT_B        # the files that differ (exit 1 if any)

``--cases chain_256,ring_32`` runs only those cases (a bundled file by its stem, a family
case as ``FAMILY_N``); ``--list`` prints the cases. Each command runs in a fresh process,
``PYTHONPATH`` set to the tree, from the folder of the generated files (so both trees print
the same paths).
"""

from __future__ import annotations

import argparse
import filecmp
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

from filter_scale import FAMILIES  # noqa: E402  (the bench folder is not a package)

SIZES = {"ring": (4, 8, 16, 32), "chain": (16, 64, 128, 256), "grid": (16, 32), "grid_edges": (8, 16)}
COMMANDS = {
    "check_json": ["check", "--json"],
    "check": ["check"],
    "solve_json": ["solve", "--json"],
    "solve": ["solve"],
    "st": ["st"],
    "st_loop": ["st", "--algorithm", "loop"],
}


def bundled() -> list[Path]:
    """The ``.filter`` files of the repository (plants/, tests/data/), in path order."""
    return sorted(p for folder in ("plants", "tests/data") for p in (ROOT / folder).rglob("*.filter"))


def cases() -> dict[str, str]:
    """Case name -> the ``.filter`` text."""
    out = {p.stem: p.read_text(encoding="utf-8") for p in bundled()}
    for family, sizes in SIZES.items():
        out.update((f"{family}_{n}", FAMILIES[family](n)) for n in sizes)
    return out


def save(tree: Path, folder: Path, names: list[str]) -> None:
    """Write each case's reports from ``tree`` into ``folder`` (the inputs in ``folder/in``)."""
    inputs = folder / "in"
    inputs.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, PYTHONPATH=str(tree))
    texts = cases()
    for name in names:
        path = inputs / f"{name}.filter"
        path.write_text(texts[name], encoding="utf-8")
        for label, argv in COMMANDS.items():
            done = subprocess.run([sys.executable, "-m", "synth", "filter", *argv, path.name], cwd=inputs, env=env,
                                  capture_output=True, check=False)
            (folder / f"{name}.{label}.out").write_bytes(done.stdout)
            (folder / f"{name}.{label}.err").write_bytes(done.stderr + f"\nexit {done.returncode}\n".encode())
        print(name, flush=True)


def compare(a: Path, b: Path) -> int:
    """The report files that differ between two saved folders (or exist in one only)."""
    names = sorted({p.name for p in a.glob("*.out")} | {p.name for p in a.glob("*.err")} |
                   {p.name for p in b.glob("*.out")} | {p.name for p in b.glob("*.err")})
    differ = [n for n in names if not ((a / n).exists() and (b / n).exists() and
                                       filecmp.cmp(a / n, b / n, shallow=False))]
    for n in differ:
        print(f"differs: {n}")
    print(f"{len(names) - len(differ)} of {len(names)} files the same")
    return 1 if differ else 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tree", type=Path, help="the synth tree to run (put first on PYTHONPATH)")
    ap.add_argument("--save", type=Path, help="the folder the reports go to")
    ap.add_argument("--compare", type=Path, nargs=2, metavar=("A", "B"), help="two saved folders")
    ap.add_argument("--cases", help="comma-separated case names (default: all)")
    ap.add_argument("--list", action="store_true", help="print the case names")
    args = ap.parse_args()
    names = list(cases())
    if args.list:
        print("\n".join(names))
        return 0
    if args.compare:
        return compare(*args.compare)
    if args.tree is None or args.save is None:
        ap.error("--tree and --save, or --compare")
    chosen = names if args.cases is None else args.cases.split(",")
    unknown = [n for n in chosen if n not in names]
    if unknown:
        ap.error(f"unknown case {unknown[0]} (--list)")
    save(args.tree.resolve(), args.save, chosen)
    return 0


if __name__ == "__main__":
    sys.exit(main())
