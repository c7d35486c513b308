"""Draw the pipeline of synth's packages: ``docs/architecture.svg`` (and ``.dot``).

    python3 scripts/architecture.py

The picture is generated from the package list below and from the imports that the
packages really make (read from the source, so a new dependency shows up in the
picture); it needs Graphviz's ``dot`` for the SVG.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from synth.output.dot import dot_graph  # noqa: E402
from synth.output.files import write_atomic  # noqa: E402

# package → (what it holds, what flows out of it)
PACKAGES = {
    "logic": ("expressions, events, cubes", "Expr, Event"),
    "plant": ("rules language, element automata, composition", "RuleSet, Plant"),
    "sup": ("constraints, SUP, explanations", "Supervisor"),
    "grafcet": (".g7 language, IEC 60848 machine, ASS", "Grafcet, GrafcetMachine, ASS"),
    "validation": ("SYNC, analysis, diagnosis", "Validation"),
    "symbolic": ("BDD engine for SUP and validation", "same results, symbolically"),
    "probe": ("auto's measure: the explicit run watched, its growth counted", "Growth"),
    "engines": ("the one engine chooser: capabilities, thresholds", "the engine that runs"),
    "filter": ("safety logic filter: check, solve, verify", "equations, filter FB"),
    "codegen": ("IEC 61131-3 ST, PLCopen XML, ST interpreter", "program, proof"),
    "output": ("summaries, DOT, HTML report, libFAUDES, files", "JSON, text, files"),
    "commission": ("I/O maps, closed loop with a PLC runtime, Modbus, OPC UA", "walks, findings"),
    "line": ("a whole line: synth.toml, jobs, cache, pool/Dask, mutants", "line reports, score"),
    "cli": ("one thin module per command group", "exit 0 / 1 / 2"),
}


def package_imports() -> set[tuple[str, str]]:
    """(importer, imported) pairs between synth's packages, from the source files."""
    edges: set[tuple[str, str]] = set()
    for pkg in PACKAGES:
        where = ROOT / "synth" / pkg
        for path in sorted(where.rglob("*.py")) if where.is_dir() else [where.with_suffix(".py")]:
            tree = ast.parse(path.read_text(encoding="utf-8"))
            for node in ast.walk(tree):
                if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("synth."):
                    target = node.module.split(".")[1]
                    if target in PACKAGES and target != pkg:
                        edges.add((target, pkg))
    return edges


def architecture_dot() -> str:
    nodes = [(p, f"{p}{'/' if (ROOT / 'synth' / p).is_dir() else '.py'}\n{what}\n→ {out}",
              {"shape": "box", "style": "rounded"}) for p, (what, out) in PACKAGES.items()]
    edges = [(a, b, "", {}) for a, b in sorted(package_imports())]
    return dot_graph("synth", nodes, edges)


def main() -> None:
    text = architecture_dot()
    write_atomic(ROOT / "docs" / "architecture.dot", text)
    from synth.output.html import svg

    write_atomic(ROOT / "docs" / "architecture.svg", svg(text))
    print("docs/architecture.dot and docs/architecture.svg written")


if __name__ == "__main__":
    main()
