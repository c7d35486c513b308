"""CLI command ``synth validate GRAFCET.g7 --plant RULES``."""

from __future__ import annotations

import argparse
import sys

__all__ = ["register", "cmd_validate"]


def register(sub: "argparse._SubParsersAction") -> None:
    from synth.output.glossary import GLOSSARY  # text only: no import behind it

    v = sub.add_parser(
        "validate",
        help="validate a Grafcet against a plant: blocking situations, prohibited orders, diagnoses",
        description="Exit 0 when nothing is found, 1 when problems are found, 2 for bad input.",
        epilog="A state of the results (text, JSON, report) is written in these words:\n" + GLOSSARY,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    v.add_argument("grafcet", metavar="GRAFCET.g7", help="the control program")
    v.add_argument("--plant", metavar="RULES", required=True, help="the plant (.rules, with its constraints)")
    v.add_argument("--home", metavar="EXPR", action="append", default=[],
                   help='a home state: a condition on step variables and E/Z names, e.g. "X1" or "X0 & v10" '
                        "(repeatable; the initial state is always a home)")
    v.add_argument("--expert", action="store_true", help="the Grafcet is trusted: blame element models and constraints")
    v.add_argument("--report", metavar="DIR", nargs="?", const="", default=None,
                   help="write DIR/index.html (default reports/<grafcet name>)")
    v.add_argument("--json", action="store_true", help="print the result as JSON (docs/validate-json.md)")
    v.add_argument("--cor", metavar="FILE", help="write the reduced controller as JSON to FILE and DOT beside it")
    v.add_argument("--max-states", metavar="N", type=int, help="stop after N aggregated states (explicit engine)")
    v.add_argument("--semantics", choices=("grafcet", "sfc"), default="grafcet", help=SEMANTICS_HELP)
    v.add_argument("--engine", choices=("auto", "explicit", "symbolic"), default="auto",
                   help="explicit exploration, BDDs (for many actuators moving at once), or chosen by "
                        "size and by watching how the explicit exploration grows (default; docs/symbolic.md)")
    v.add_argument("--max-nodes", metavar="N", type=int, help="stop when the symbolic engine needs more than N BDD nodes")
    v.add_argument("--quiet", action="store_true", help="no progress on stderr")
    v.add_argument("--junit", metavar="FILE", help="also write the findings as JUnit XML (one test case per finding)")
    v.add_argument("--sarif", metavar="FILE", help="also write the findings as SARIF 2.1.0 (one result per finding)")
    v.set_defaults(handler=cmd_validate)


SEMANTICS_HELP = ("how the Grafcet evolves: grafcet (IEC 60848, search for stability; default) or sfc "
                  "(IEC 61131-3 SFC, one evolution per PLC scan: the meaning of an imported PLC program)")


def cmd_validate(args: argparse.Namespace) -> int:
    from pathlib import Path

    from synth.cli.plant import print_warnings
    from synth.engines import Decision, EngineChoice, validate
    from synth.errors import SynthError
    from synth.output.files import write_atomic
    from synth.output.html import write_report
    from synth.output.progress import clear_progress, tty_progress
    from synth.output.result import cor_dot, cor_json, validation_json, validation_text
    from synth.output.summary import json_text, print_json
    from synth.validation.result import reduced_controller

    if args.cor and Path(args.cor).suffix == ".dot":
        raise SynthError(f"--cor {args.cor}: the JSON file must not end in .dot, the DOT file is written beside it")
    show = tty_progress(not args.quiet and sys.stderr.isatty())

    def decided(chosen: Decision) -> None:  # auto chose the symbolic engine on the counts it read
        if chosen.measured and chosen.engine is EngineChoice.SYMBOLIC and not args.quiet:
            print(chosen.reason, file=sys.stderr)

    result = validate(
        args.grafcet,
        args.plant,
        engine=args.engine,
        needs_listing=args.report is not None or bool(args.cor),
        expert=args.expert,
        homes=args.home,
        max_states=args.max_states,
        max_nodes=args.max_nodes,
        progress=show,
        semantics=args.semantics,
        decided=decided,
    )
    clear_progress(show)
    if result.engine_stats is not None and not args.quiet:
        print(f"symbolic engine: {result.engine_stats['bdd_nodes']} BDD nodes, "
              f"{result.engine_stats['situations']} stable situations", file=sys.stderr)
    print_warnings(result.plant)
    if args.cor:
        cor = cor_json(result, reduced_controller(result))
        path = Path(args.cor)
        write_atomic(path, json_text(cor))
        write_atomic(path.with_suffix(".dot"), cor_dot(cor))
    if args.junit or args.sarif:
        from synth.output.ci import validation_report, write_ci

        write_ci([validation_report(result)], args.junit, args.sarif)
    report_path = None
    if args.report is not None:
        directory = args.report or str(Path("reports") / Path(args.grafcet).stem)
        report_path = write_report(directory, result)
    if args.json:
        data = validation_json(result)
        if report_path is not None:
            data["report"] = str(report_path)
        if result.engine_stats is not None:
            data["symbolic"] = dict(result.engine_stats)
        print_json(data)
    else:
        print(validation_text(result))
        if report_path is not None:
            print(f"\nreport: {report_path}")
        if args.cor:
            print(f"reduced controller: {args.cor} and {Path(args.cor).with_suffix('.dot')}")
    return 0 if result.passed else 1
