"""``synth mutate G.g7 --plant P.rules``: a mutation campaign that measures a plant model.

Every mutant of the Grafcet (and of the filter's equations) is validated; the **mutation
score** is the mutants caught over the mutants that change behaviour (a mutant whose ASS
equals the original's is equivalent and not counted); every surviving mutant is listed:
there the plant model and its constraints say nothing, which is what the expert must look
at. Known survivors (``--allow ID``) do not fail the run.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

from synth.errors import SynthError
from synth.line.jobs import Job, JobKind

__all__ = ["Campaign", "run_mutation", "mutation_json", "mutation_text"]


@dataclass(frozen=True)
class Campaign:
    """The mutants' results (in id order of generation) and the allowed survivors."""

    grafcet: str
    plant: str
    filter: str | None
    mutants: tuple[dict[str, Any], ...]
    allow: tuple[str, ...] = ()

    def _count(self, status: str) -> int:
        return sum(m["status"] == status for m in self.mutants)

    @property
    def caught(self) -> int:
        return self._count("caught")

    @property
    def changing(self) -> int:
        return self.caught + self._count("survived")

    @property
    def equivalent(self) -> int:
        return self._count("equivalent")

    @property
    def score(self) -> float | None:
        return self.caught / self.changing if self.changing else None

    @property
    def survivors(self) -> tuple[str, ...]:
        return tuple(m["id"] for m in self.mutants if m["status"] == "survived")

    @property
    def unexpected(self) -> tuple[str, ...]:
        return tuple(i for i in self.survivors if i not in self.allow)

    @property
    def exit_code(self) -> int:
        if any(m["status"] == "error" for m in self.mutants):
            return 2
        return 1 if self.unexpected else 0


def run_mutation(grafcet: str, plant: str, filter_path: str | None = None, *, semantics: str = "grafcet",
                 engine: str = "auto", homes: Sequence[str] = (), allow: Sequence[str] = (),
                 workers: int | None = None) -> Campaign:
    """Validate the original (it must pass), then every mutant, on ``workers`` processes."""
    from synth.line.run import filter_mutant_jobs, grafcet_mutant_jobs, run_jobs

    options = (("semantics", semantics), ("engine", engine), ("homes", "\n".join(homes)), ("expert", "false"))
    original, _ = run_jobs([Job("mutate", JobKind.VALIDATE, "original", plant, grafcet, None, options)], None, workers=1)
    if original[0]["verdict"] == "error":
        raise SynthError(original[0]["text"])
    if original[0]["verdict"] != "pass":
        raise SynthError(f"{grafcet} fails validation against {plant} ({original[0]['summary']}): mutants measure a "
                         "plant model against a Grafcet that passes")
    jobs = grafcet_mutant_jobs("mutate", plant, grafcet, options)
    if filter_path is not None:
        jobs += filter_mutant_jobs("mutate", filter_path)
    results, _ = run_jobs(jobs, None, workers=workers)
    return Campaign(grafcet, plant, filter_path, tuple(r["mutant"] for r in results), tuple(allow))


def mutation_json(c: Campaign) -> dict[str, Any]:
    return {"grafcet": c.grafcet, "plant": c.plant, "filter": c.filter, "mutants": list(c.mutants),
            "caught": c.caught, "changing": c.changing, "equivalent": c.equivalent,
            "score": None if c.score is None else round(c.score, 4), "survivors": list(c.survivors),
            "allowed": [i for i in c.survivors if i in c.allow], "unexpected": list(c.unexpected)}


def mutation_text(c: Campaign) -> str:
    score = "-" if c.score is None else f"{c.caught}/{c.changing} = {100 * c.score:.1f}%"
    lines = [f"{c.grafcet} against {c.plant}: {len(c.mutants)} mutants, {c.equivalent} equivalent (equal ASS, not "
             f"counted), {c.changing} change behaviour",
             f"mutation score: {score}"]
    if c.survivors:
        lines.append("surviving mutants (the plant model and its constraints say nothing here):")
        for m in c.mutants:
            if m["status"] == "survived":
                allowed = " (allowed)" if m["id"] in c.allow else ""
                lines.append(f"  {m['id']}{allowed}: {m['description']} ({m['file']}:{m['line']}:{m['column']})")
    lines.append("mutants:")
    lines += [f"  {m['status']:<10} {m['id']}: {m['why'] if m['status'] == 'error' else m['description']}"
              for m in c.mutants]
    return "\n".join(lines) + "\n"
