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
    register_st(commands)


def register_st(commands: "argparse._SubParsersAction") -> None:
    t = commands.add_parser("st", help="the filter as an IEC 61131-3 FUNCTION_BLOCK (Structured Text)")
    t.add_argument("filter", metavar="F.filter", help="the .filter file")
    t.add_argument("--algorithm", choices=("algebraic", "loop"), default="algebraic",
                   help="the synthesised equations (default) or the detection/correction loop")
    t.add_argument("--mode", choices=("supervisor", "blocking"), default="supervisor",
                   help="pass the requests on (default), or latch and fold them after a violation until Ack")
    t.add_argument("-o", "--output", metavar="FB.st", help="write the block to this file (default: standard output)")
    t.add_argument("--xml", action="store_true", help="write PLCopen TC6 XML instead of Structured Text")
    t.add_argument("--name", metavar="NAME", help="the block is FB_NAME_Filter (default: the file's stem)")
    t.add_argument("--order", metavar="O1,O2,...", help="the order of the Sim criteria (algebraic)")
    t.set_defaults(handler=cmd_st)


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


def cmd_st(args: argparse.Namespace) -> int:
    from synth.codegen.filter_st import filter_block
    from synth.filter.language_check import load_filter
    from synth.output.files import write_atomic

    f = load_filter(args.filter)
    _warnings(f)
    order = [o.strip() for o in args.order.split(",") if o.strip()] if args.order else None
    block = filter_block(f, args.algorithm, args.mode, args.name, order)
    for n in block.notes:
        print(f"note: {n}", file=sys.stderr)
    text = block.text
    if args.xml:
        from synth.codegen.plcopen import st_project_xml

        text = st_project_xml([(block.name, "functionBlock", block.text)], args.filter)
    if args.output:
        write_atomic(args.output, text)
    else:
        sys.stdout.write(text)
    return 0
