"""``validate --engine auto`` against the faster of the two engines, on every family of ``bench/``.

    python3 bench/auto.py [--par 3..9] [--steep 3..6] [--line 8,16] [--wide 2..5] [--branches 2..8]
                          [--timed-par 5,6] [--timed-branches 2..3] [--internal-par 5..7] [--missing] [--runs 2]
                          [--budget 60] [--before DIR] [--json FILE]

Families (each written by its generator into a temporary folder):

- ``par_N`` (gen_par.py: N cylinders extended together, then retracted together),
- ``steep_N`` (gen_steep.py: N branches started at once, joined once),
- ``line_N`` (gen_line.py: one sequence of N cylinders, neighbour interlocks),
- ``branches_Kx2`` (gen_branches.py, ``--wide``: K branches of two cylinders each: the
  width grows),
- ``branches_3xM`` (gen_branches.py, ``--branches``: three branches, each a sequence of M
  cylinders, interlocks between neighbouring branches: the depth grows),
- ``par_N_timed`` and ``branches_3xM_timed`` (gen_branches.with_timers: each extension
  waits 1 s once out): the symbolic engine explores them one stable situation at a time,
  and wins on the first (its situations hold many states) but not on the second;
- ``par_N_internal`` (gen_par.py with an internal variable the Grafcet never uses): the
  explicit engine explores it state by state (no frontier path), about five times slower;
- the bundled Grafcets with their plants (``grafcets/tri*.g7``, ``four_cylinders.g7``).

Each case runs ``synth validate`` with ``--engine explicit``, ``--engine symbolic`` and
``--engine auto`` (and ``auto`` of the tree ``--before``, e.g. a ``git archive`` of main),
every one a fresh process (bench/symbolic.py's ``run``: CPU seconds of the whole command,
user + system, start-up included), the engines and the runs interleaved so that a change
of the machine's load hits them alike; the minimum of ``--runs`` is kept. An engine over
``--budget`` CPU seconds is not run again on a larger case of its family. Printed: a
Markdown table with the engine ``auto`` ran and ``auto / faster``, the target being ≤ 1.3
everywhere. The texts of the three runs must be the same (the engines' reports agree).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path
from typing import Callable, Iterator

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))

from gen_branches import with_timers, write_branches  # noqa: E402
from gen_line import write_line  # noqa: E402
from gen_par import write_par  # noqa: E402
from gen_steep import write_steep  # noqa: E402
from symbolic import _range, machine, run  # noqa: E402

__all__ = ["cases", "main"]

BUNDLED = [("tri", "grafcets/tri.g7", "plants/tri.rules"),
           ("tri_missing_order", "grafcets/tri_missing_order.g7", "plants/tri.rules"),
           ("tri_counting", "grafcets/tri_counting.g7", "plants/tri.rules"),
           ("four_cylinders", "grafcets/four_cylinders.g7", "plants/four_cylinders.rules")]


def cases(args: argparse.Namespace, d: Path) -> Iterator[tuple[str, str, Path, Path]]:
    """(family, case, grafcet, rules), smallest first in each family."""
    for name, g7, rules in BUNDLED:
        yield "bundled", name, ROOT / g7, ROOT / rules
    families = [("par", _range(args.par), lambda n: write_par(n, d), "par_{}"),
                ("steep", _range(args.steep), lambda n: write_steep(n, d), "steep_{}"),
                ("line", _range(args.line), lambda n: write_line(n, d), "line_{}"),
                ("wide", _range(args.wide), lambda k: write_branches(k, 2, d), "branches_{}x2"),
                ("branches", _range(args.branches), lambda m: write_branches(3, m, d), "branches_3x{}"),
                ("timed par", _range(args.timed_par), lambda n: timed(write_par(n, d)), "par_{}_timed"),
                ("timed branches", _range(args.timed_branches), lambda m: timed(write_branches(3, m, d)),
                 "branches_3x{}_timed"),
                ("internal par", _range(args.internal_par), lambda n: internal(write_par(n, d)), "par_{}_internal")]
    for family, sizes, write, name in families:
        for n in sizes:
            rules, g7, missing = write(n)
            yield family, name.format(n), Path(g7), Path(rules)
            if args.missing:
                yield family, name.format(n) + "_missing", Path(missing), Path(rules)


def variant(paths: tuple[Path, Path, Path], suffix: str, change: Callable[[str], str]) -> tuple[Path, Path, Path]:
    """The generator's files with the Grafcets' variants ``change(text)`` beside them (``_suffix.g7``)."""
    rules, *grafcets = paths
    out = []
    for g7 in grafcets:
        t = g7.with_name(f"{g7.stem}_{suffix}.g7")
        t.write_text(change(g7.read_text(encoding="utf-8")), encoding="utf-8")
        out.append(t)
    return rules, out[0], out[1]


def timed(paths: tuple[Path, Path, Path]) -> tuple[Path, Path, Path]:
    """Each extension waits 1 s once out (gen_branches.with_timers)."""
    return variant(paths, "timed", with_timers)


def internal(paths: tuple[Path, Path, Path]) -> tuple[Path, Path, Path]:
    """An internal variable declared that no step uses: the explicit engine explores state by state."""
    return variant(paths, "internal", lambda text: text.replace("\ngrafcet ", "\ninternal k : 0..1 = 0\n\ngrafcet ", 1))


def _chose(res: dict) -> str:
    err = res.get("stderr", "")
    return "symbolic" if "symbolic engine:" in err else "explicit"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--par", default="3..9")
    ap.add_argument("--steep", default="3..6")
    ap.add_argument("--line", default="8,16")
    ap.add_argument("--wide", default="2..5", help="K for branches_Kx2")
    ap.add_argument("--branches", default="2..8", help="M for branches_3xM")
    ap.add_argument("--timed-par", default="5,6", help="N for par_N_timed (every extension waits 1 s)")
    ap.add_argument("--timed-branches", default="2..3", help="M for branches_3xM_timed")
    ap.add_argument("--internal-par", default="5..7", help="N for par_N_internal (explored state by state)")
    ap.add_argument("--missing", action="store_true", help="also each family's _missing variant")
    ap.add_argument("--runs", type=int, default=2)
    ap.add_argument("--budget", type=float, default=60.0, help="CPU seconds per run")
    ap.add_argument("--before", type=Path, help="another synth tree: its auto is run too")
    ap.add_argument("--json", metavar="FILE")
    args = ap.parse_args(argv)
    engines = [("explicit", ROOT), ("symbolic", ROOT), ("auto", ROOT)]
    engines += [("auto", args.before)] if args.before else []
    labels = [e if t == ROOT else f"{e} before" for e, t in engines]
    rows, worst, bad = [], 0.0, 0
    head = "| case | SYNC states | explicit s | symbolic s | auto → | auto s | auto / faster |"
    if args.before:
        head += " auto before → | auto before s | before / faster |"
    print(head)
    print("|" + "---|" * (head.count("|") - 1))
    with tempfile.TemporaryDirectory() as tmp:
        over: set[tuple[str, str]] = set()
        for family, name, g7, rules in cases(args, Path(tmp)):
            best: dict[str, dict] = {}
            for _ in range(args.runs):
                for (engine, tree), label in zip(engines, labels):
                    if (family, label) in over:
                        continue
                    res = run(["validate", str(g7), "--plant", str(rules), "--engine", engine], args.budget, tree)
                    if res["status"] != "ok":
                        over.add((family, label))
                        best[label] = res
                        continue
                    kept = best.get(label, {}).get("seconds")
                    if kept is None or res["seconds"] < kept:
                        best[label] = res
            ok = {k: v for k, v in best.items() if v.get("status") == "ok"}
            texts = {v["stdout"] for v in ok.values()}
            head_line = next(iter(texts)).splitlines()[0] if texts else ""
            states = head_line.split("SYNC ")[1].split(" states")[0] if "SYNC " in head_line else ""
            engines_ok = [ok[e]["seconds"] for e in ("explicit", "symbolic") if e in ok]
            faster = min(engines_ok) if engines_ok else None

            def cell(label: str) -> str:
                r = best.get(label)
                return "not run" if r is None else (str(r["seconds"]) if r.get("status") == "ok" else r["status"])

            def ratio(label: str) -> float | None:
                if label not in ok or faster is None or len(engines_ok) < 2:
                    return None
                return round(ok[label]["seconds"] / faster, 2)

            r_auto = ratio("auto")
            line = (f"| {name} | {states} | {cell('explicit')} | {cell('symbolic')} | "
                    f"{_chose(ok['auto']) if 'auto' in ok else '–'} | {cell('auto')} | {r_auto if r_auto else '–'} |")
            if args.before:
                r_before = ratio("auto before")
                line += (f" {_chose(ok['auto before']) if 'auto before' in ok else '–'} | {cell('auto before')} | "
                         f"{r_before if r_before else '–'} |")
            print(line + ("" if len(texts) <= 1 else "  **reports differ**"), flush=True)
            bad += len(texts) > 1
            worst = max(worst, r_auto or 0.0)
            rows.append({"family": family, "case": name, "sync_states": states,
                         **{label: {k: v for k, v in r.items() if k not in ("stdout", "stderr")} | {"chose": _chose(r)}
                            for label, r in best.items()}, "auto_over_faster": r_auto})
    print(f"\nworst auto / faster: {worst} (target ≤ 1.3); machine: {machine()}")
    if args.json:
        Path(args.json).write_text(json.dumps({"machine": machine(), "rows": rows}, indent=2) + "\n")
    return 1 if bad or worst > 1.3 else 0


if __name__ == "__main__":
    sys.exit(main())
