"""CLI commands of a whole line: ``synth check [synth.toml]`` and ``synth mutate G.g7 --plant P.rules``.

``synth check`` runs every station's checks (docs/line.md), from the cache when nothing
they read has changed, on a local pool of worker processes or on a Dask cluster
(``--cluster tcp://HOST:8786``); it writes one JUnit, one SARIF and an HTML index, prints
a summary table and exits 0 only when every station meets its expectation (1 otherwise,
2 for bad input or a job that could not run).
"""

from __future__ import annotations

import argparse
import sys

TYPE_CHECKING = False  # typing.TYPE_CHECKING, without importing typing (fast --help)
if TYPE_CHECKING:  # pragma: no cover
    from collections.abc import Callable
    from typing import Any

    from synth.line.jobs import Job

__all__ = ["register", "cmd_check", "cmd_mutate"]


def _positive(text: str) -> int:
    """``--workers N``: an integer of at least 1 (argparse reports anything else, exit 2)."""
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of workers (1 or more)")
    return n


def register(sub: "argparse._SubParsersAction") -> None:
    c = sub.add_parser("check", help="every check of every station of a line (synth.toml), cached, in parallel",
                       description="Run every station's validate, filter check/verify and st --check; exit 0 only "
                                   "when every station meets its expectation, 1 otherwise, 2 for bad input.")
    c.add_argument("project", metavar="synth.toml", nargs="?", default="synth.toml",
                   help="the line's project file (default: synth.toml)")
    c.add_argument("--cache", metavar="DIR", help="the result cache (default: $XDG_CACHE_HOME/synth/line, "
                                                  "~/.cache/synth/line)")
    c.add_argument("--no-cache", action="store_true", help="run every job, read and write no cache")
    c.add_argument("--mutate", action="store_true",
                   help="also validate the mutants of every station's passing Grafcets (and filter equations)")
    c.add_argument("--cluster", metavar="tcp://HOST:8786", help="run the jobs on this Dask distributed scheduler")
    c.add_argument("--workers", metavar="N", type=_positive, help="local worker processes (default: one per core; 1: serial)")
    c.add_argument("--report", metavar="DIR", help="where index.html, the station pages, junit.xml and line.sarif go "
                                                   "(default: reports/<the project's folder name>)")
    c.add_argument("--junit", metavar="FILE", help="write the line's JUnit XML here instead")
    c.add_argument("--sarif", metavar="FILE", help="write the line's SARIF here instead")
    c.add_argument("--validation-reports", action="store_true",
                   help="also write each validation's full report (synth validate --report: traces, drawings), "
                        "linked from its station's page (explicit engine)")
    c.add_argument("--quiet", action="store_true", help="no progress on stderr")
    c.set_defaults(handler=cmd_check)

    m = sub.add_parser("mutate", help="mutation score of a plant model: mutants of a Grafcet (and filter), "
                                      "caught / changing behaviour, survivors listed",
                       description="Exit 0 when no mutant survives outside --allow, 1 otherwise, 2 for bad input.")
    m.add_argument("grafcet", metavar="G.g7", help="the Grafcet to mutate (it must pass validation)")
    m.add_argument("--plant", metavar="P.rules", required=True, help="the plant whose strength is measured")
    m.add_argument("--filter", metavar="F.filter", help="also mutate this filter's equations (judged by filter check)")
    m.add_argument("--semantics", choices=("grafcet", "sfc"), default="grafcet", help="how the Grafcet evolves")
    m.add_argument("--engine", choices=("auto", "explicit", "symbolic"), default="auto", help="the validation engine")
    m.add_argument("--home", metavar="EXPR", action="append", default=[], help="a home state, as for validate")
    m.add_argument("--allow", metavar="ID", action="append", default=[],
                   help="a known survivor (its mutant id; repeatable): it does not fail the run")
    m.add_argument("--workers", metavar="N", type=_positive, help="local worker processes (default: one per core; 1: serial)")
    m.add_argument("--json", action="store_true", help="print the mutants, the score and the survivors as JSON")
    m.set_defaults(handler=cmd_mutate)


def _progress(quiet: bool) -> Callable[[Job, dict[str, Any], bool], None] | None:
    """A progress function for stderr: one counted line per finished job (cached or run)."""
    if quiet:
        return None
    done = [0]

    def show(job: Job, result: dict[str, Any], cached: bool) -> None:
        done[0] += 1
        sys.stderr.write(f"[{done[0]}] {job.id}: {result['verdict']} ({'cache' if cached else 'run'})\n")
        sys.stderr.flush()

    return show


def cmd_check(args: argparse.Namespace) -> int:
    from pathlib import Path

    from synth.line.cache import Cache
    from synth.line.project import load_line
    from synth.line.report import summary_table, write_line_reports
    from synth.line.run import check_line

    line = load_line(args.project)
    cache = None if args.no_cache else Cache(args.cache)
    run = check_line(line, cache, mutate=args.mutate, workers=args.workers, cluster=args.cluster,
                     progress=_progress(args.quiet), reports=args.validation_reports)
    folder = args.report or str(Path("reports") / (line.folder.resolve().name or "line"))
    written = write_line_reports(run, folder, args.junit, args.sarif)
    sys.stdout.write(summary_table(run))
    print(f"report: {written['index']}; JUnit: {written['junit']}; SARIF: {written['sarif']}")
    return run.exit_code


def cmd_mutate(args: argparse.Namespace) -> int:
    from synth.line.campaign import mutation_json, mutation_text, run_mutation

    m = run_mutation(args.grafcet, args.plant, args.filter, semantics=args.semantics, engine=args.engine,
                     homes=tuple(args.home), allow=tuple(args.allow), workers=args.workers)
    if args.json:
        from synth.output.summary import print_json

        print_json(mutation_json(m))
    else:
        sys.stdout.write(mutation_text(m))
    return m.exit_code
