"""``synth filter check`` and ``synth filter solve``: parse arguments, call the library, print.

Exit codes: 0 every property holds / the synthesis is functional and consistent,
1 it does not, 2 bad input.
"""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from synth.filter.language import Filter

__all__ = ["register"]


def register(sub: "argparse._SubParsersAction") -> None:
    p = sub.add_parser("filter", help="safety logic filter: coherence checks and algebraic synthesis")
    commands = p.add_subparsers(dest="filter_command", metavar="SUBCOMMAND", parser_class=type(p))
    commands.required = True

    c = commands.add_parser("check", help="P1-P4, GO cycles, pair conditions, global consistency, equations")
    c.add_argument("filter", metavar="F.filter", help="the .filter file")
    c.add_argument("--json", action="store_true", help="print JSON instead of text")
    c.set_defaults(handler=cmd_check)

    s = commands.add_parser("solve", help="algebraic synthesis: one equation per output")
    s.add_argument("filter", metavar="F.filter", help="the .filter file")
    s.add_argument("--json", action="store_true", help="print JSON instead of text")
    s.add_argument("--order", metavar="O1,O2,...", help="the order of the Sim criteria (default: the file's)")
    s.set_defaults(handler=cmd_solve)


def _warnings(f: "Filter") -> None:
    """The file's warnings (a relief on a simple constraint), on stderr."""
    for w in f.warnings:
        print(w.render(), file=sys.stderr)


def cmd_check(args: argparse.Namespace) -> int:
    from synth.cli.plant import print_json
    from synth.filter.coherence import coherence
    from synth.filter.language_check import load_filter
    from synth.filter.model import functions
    from synth.filter.solve import differences, synthesis

    f = load_filter(args.filter)
    _warnings(f)
    m = functions(f)
    report = coherence(m)
    diffs = differences(synthesis(m)) if f.equations else []
    if args.json:
        data = {"file": args.filter, **report.as_dict(), "differences": diffs}
        print_json(data)
    else:
        sys.stdout.write(report.text())
        for d in diffs:
            print(f"differs: {d}")
    return 0 if report.holds else 1


def cmd_solve(args: argparse.Namespace) -> int:
    from synth.cli.plant import print_json
    from synth.filter.language_check import load_filter
    from synth.filter.solve import synthesis

    f = load_filter(args.filter)
    _warnings(f)
    order = [o.strip() for o in args.order.split(",") if o.strip()] if args.order else None
    s = synthesis(f, order)
    if args.json:
        print_json({"file": args.filter, **s.as_dict()})
    else:
        sys.stdout.write(s.text())
        for n in s.notes:
            print(f"note: {n}", file=sys.stderr)
        for w in s.warnings:
            print(f"warning: {w}", file=sys.stderr)
    return 0 if s.functional and s.consistent else 1
