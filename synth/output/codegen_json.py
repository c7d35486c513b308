"""The JSON of ``synth run``, ``synth st``, ``synth sfc`` and ``synth import`` (``--json``):
JSON-ready dicts over what the commands computed, never recomputing anything. Their schemas
are ``synth/output/schemas/{run,codegen_files,st_check,import,import_list}.json``."""

from __future__ import annotations

import hashlib
from typing import TYPE_CHECKING, Any, Sequence

if TYPE_CHECKING:  # pragma: no cover
    from synth.codegen.check import DifferentialReport
    from synth.codegen.plcopen.importer import PouSummary
    from synth.grafcet.simulation import SimulationStep

__all__ = ["run_json", "st_check_json", "files_json", "import_json", "import_list_json"]


def run_json(grafcet: str, rows: "Sequence[SimulationStep]") -> dict[str, Any]:
    """``synth run --json``: one row per event, ``initial`` first."""
    return {"grafcet": grafcet, "rows": [
        {"event": r.event, "situation": r.situation.text(), "steps": list(r.situation.steps),
         "orders": list(r.orders), "fired": [list(f) for f in r.fired]}
        for r in rows]}


def st_check_json(report: "DifferentialReport") -> dict[str, Any]:
    """``synth st --check --json``: the proof's counts and its mismatches."""
    return {"grafcet": report.grafcet, "equal": report.ok, "depth": report.depth, "sequences": report.sequences,
            "cycles": report.cycles, "out_of_range": report.out_of_range,
            "mismatches": [{"events": list(m.events), "aspect": str(m.aspect), "expected": m.expected, "got": m.got}
                           for m in report.mismatches]}


def files_json(command: str, name: str, target: str, sources: Sequence[str],
               files: Sequence[tuple[str, bytes]], written: Sequence[str | None]) -> dict[str, Any]:
    """``synth st --json`` / ``synth sfc --json``: what was generated, from what, and where
    it went; a file printed nowhere else (no ``-o``) carries its text."""
    out = []
    for (file, data), path in zip(files, written):
        entry: dict[str, Any] = {"name": file, "path": path, "bytes": len(data), "sha256": hashlib.sha256(data).hexdigest()}
        if path is None:
            entry["text"] = data.decode("utf-8")
        out.append(entry)
    return {"command": command, "pou": name, "target": target, "sources": list(sources), "files": out}


def import_json(file: str, output: str | None, text: str, notes: Sequence[str], warnings: Sequence[str],
                scan_only: Sequence[str]) -> dict[str, Any]:
    """``synth import --json``: the Grafcet read (its text when no ``-o``), notes and warnings."""
    return {"file": file, "output": output, "g7": text if output is None else None, "notes": list(notes),
            "warnings": list(warnings), "scan_only_steps": list(scan_only)}


def import_list_json(file: str, pous: "Sequence[PouSummary]") -> dict[str, Any]:
    """``synth import --list --json``: the POUs of the project and what an import reads."""
    return {"file": file, "pous": [{"name": p.name, "kind": p.kind, "language": p.language, "imported": p.imported,
                                    "note": p.note} for p in pous]}
