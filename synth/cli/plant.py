"""``synth plant`` and ``synth sup``: parse arguments, call the library, print."""

from __future__ import annotations

import argparse
import sys

TYPE_CHECKING = False  # typing.TYPE_CHECKING, without importing typing (fast --help)
if TYPE_CHECKING:
    from typing import Any

__all__ = ["register", "print_warnings"]

MAX_DRAWN_STATES = 400
DEFAULT_MAX_STATES = 2**36


def register(sub: "argparse._SubParsersAction") -> None:
    p = sub.add_parser("plant", help="build the plant automaton from a .rules file")
    p.add_argument("rules", metavar="RULES", help="the .rules file")
    p.add_argument("--element", metavar="NAME", help="only this element's automaton")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--dot", metavar="FILE", help="write the automaton as Graphviz DOT")
    g.add_argument("--svg", metavar="FILE", help="draw the automaton as SVG (needs Graphviz's dot)")
    p.add_argument("--export", metavar="FILE.gen", help="write a libFAUDES System (.gen)")
    p.set_defaults(handler=cmd_plant)

    s = sub.add_parser("sup", help="synthesise SUP, the maximal admissible plant behaviour")
    s.add_argument("rules", metavar="RULES", help="the .rules file (elements and constraints)")
    s.add_argument("--json", action="store_true", help="print JSON instead of text")
    s.add_argument("--export", metavar="FILE.gen", help="write SUP as a libFAUDES System (.gen)")
    s.add_argument("--why", metavar="STATE", help="explain one state, written as its true variables, e.g. 'TAPIS,v10,v20,v30,v40'")
    s.add_argument("--max-states", metavar="N", type=int, default=DEFAULT_MAX_STATES,
                   help=f"refuse plants larger than N states (default {DEFAULT_MAX_STATES}); synth validate needs no such limit")
    s.add_argument("--quiet", action="store_true", help="no progress on stderr")
    s.add_argument("--engine", choices=("auto", "explicit", "symbolic"), default="auto",
                   help="explicit exploration, or counts on BDDs for plants of any size; auto: symbolic above "
                        "10^6 plant states unless --export or --why lists states (docs/symbolic.md)")
    s.add_argument("--max-nodes", metavar="N", type=int, help="stop when the symbolic engine needs more than N BDD nodes")
    s.set_defaults(handler=cmd_sup)


def print_warnings(p: Any) -> None:
    """Warnings about the plant model (rules that never apply), on stderr."""
    for w in p.warnings:
        print(w.render(), file=sys.stderr)


def _written(*outputs: tuple[str, str | None]) -> None:
    for what, path in outputs:
        if path:
            print(f"{what} written to {path}", file=sys.stderr)


def cmd_plant(args: argparse.Namespace) -> int:
    from synth.errors import SynthError
    from synth.output import dot, faudes, summary
    from synth.output.files import write_atomic
    from synth.output.html import write_svg
    from synth.plant.composition import plant
    from synth.plant.rules_check import load_rules

    rs = load_rules(args.rules)
    p = plant(rs)
    print_warnings(p)
    drawn = bool(args.dot or args.svg)
    if args.element:
        a = p.element(args.element)
        data = summary.element_summary(a, detail=True)
        text = summary.element_text(data)
        graph = dot.element_dot(a) if drawn else ""
        gen = faudes.element_generator(a) if args.export else ""
    else:
        if drawn and p.size > MAX_DRAWN_STATES:
            raise SynthError(
                f"the plant has {p.size} states, too many to draw (limit {MAX_DRAWN_STATES}); draw one element with --element NAME"
            )
        data = summary.plant_summary(p, args.rules)
        text = summary.plant_text(data)
        graph = dot.plant_dot(p) if drawn else ""
        gen = faudes.plant_generator(p, "plant") if args.export else ""
    if args.dot:
        write_atomic(args.dot, graph)
    if args.svg:
        write_svg(args.svg, graph)
    if args.export:
        write_atomic(args.export, gen)
    if args.json:
        summary.print_json(data)
        return 0
    sys.stdout.write(text)
    _written(("DOT", args.dot), ("SVG", args.svg), ("libFAUDES", args.export))
    return 0


def cmd_sup(args: argparse.Namespace) -> int:
    from synth.engines import supervisor
    from synth.output.faudes import supervisor_generator
    from synth.output.files import write_atomic
    from synth.output.progress import clear_progress, tty_progress
    from synth.output.summary import print_json, sup_run_summary, sup_run_text

    show = tty_progress(not args.quiet and sys.stderr.isatty())
    run = supervisor(args.rules, engine=args.engine, needs_listing=bool(args.export or args.why),
                     max_states=args.max_states, max_nodes=args.max_nodes, progress=show, loaded=print_warnings)
    clear_progress(show)
    if args.why:
        ex = run.why(args.why)
        if args.json:
            print_json(ex.as_dict())
        else:
            print(ex.text(run.labels))
        return 0
    if args.export:
        write_atomic(args.export, supervisor_generator(run.listed(), "sup"))
    if args.json:
        print_json(sup_run_summary(run))
    else:
        sys.stdout.write(sup_run_text(run))
        if run.bdd_nodes is not None and not args.quiet:
            print(f"symbolic engine: {run.bdd_nodes} BDD nodes", file=sys.stderr)
    _written(("libFAUDES", args.export))
    return 0
