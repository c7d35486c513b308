"""``synth filter check|solve|st|run|verify|from-rules``: each handler parses its arguments,
calls one library function and prints (the texts and JSON of :mod:`synth.output.filter_text`).

Exit codes: 0 every property holds / the synthesis is functional and consistent / the
trace or the closed loop is coherent (and safe), 1 it does not, 2 bad input (or
``verify`` stopped at ``--max-states``).
"""

from __future__ import annotations

import argparse
import sys

TYPE_CHECKING = False  # typing.TYPE_CHECKING, without importing typing (fast --help)

if TYPE_CHECKING:
    from synth.filter.language import Filter
    from synth.filter.loop.verification import Verification

__all__ = ["register", "register_run", "register_verify", "register_from_rules"]


def register(sub: "argparse._SubParsersAction") -> None:
    p = sub.add_parser("filter", help="safety logic filter: coherence checks and algebraic synthesis")
    commands = p.add_subparsers(dest="filter_command", metavar="SUBCOMMAND", parser_class=type(p))
    commands.required = True

    c = commands.add_parser("check", help="P1-P4, GO cycles, pair conditions, global consistency, equations")
    c.add_argument("filter", metavar="F.filter", help="the .filter file")
    c.add_argument("--json", action="store_true", help="print JSON instead of text")
    c.add_argument("--plant", metavar="P.rules",
                   help="judge on the valuations this plant can reach under any control (printed as assume lines)")
    c.add_argument("--all-spellings", action="store_true",
                   help="compare the keep/force spellings of every relief on every input, past the work "
                        "limit, naming every output each drives differently (no witness points)")
    c.add_argument("--quiet", action="store_true", help="no live progress line on a terminal")
    ci_options(c)
    c.set_defaults(handler=cmd_check)

    s = commands.add_parser("solve", help="algebraic synthesis: one equation per output")
    s.add_argument("filter", metavar="F.filter", help="the .filter file")
    s.add_argument("--json", action="store_true", help="print JSON instead of text")
    s.add_argument("--order", metavar="O1,O2,...", help="the order of the Sim criteria (default: the file's)")
    s.add_argument("--flat", action="store_true",
                   help="print every equation over Y only (flat ISOP; refused past a size limit) instead of chained")
    s.add_argument("--quiet", action="store_true", help="no live progress line on a terminal")
    s.set_defaults(handler=cmd_solve)
    register_st(commands)


def register_st(commands: "argparse._SubParsersAction") -> None:
    t = commands.add_parser("st", help="the filter as an IEC 61131-3 FUNCTION_BLOCK (Structured Text)")
    t.add_argument("filter", metavar="F.filter", help="the .filter file")
    _algorithm_mode(t)
    t.add_argument("-o", "--output", metavar="FB.st", help="write the block to this file (default: standard output)")
    t.add_argument("--xml", action="store_true", help="write PLCopen TC6 XML instead of Structured Text (--target plcopen)")
    t.add_argument("--target", choices=("iec", "plcopen", "codesys", "twincat"),
                   help="iec: ST text (default); plcopen: TC6 XML; codesys: TC6 XML with CODESYS's project structure; "
                        "twincat: one .TcPOU per block (several: -o DIR)")
    t.add_argument("--name", metavar="NAME", help="the block is FB_NAME_Filter (default: the file's stem)")
    t.add_argument("--order", metavar="O1,O2,...", help="the order of the Sim criteria (algebraic)")
    t.add_argument("--split", action="store_true",
                   help="one FUNCTION_BLOCK per independent cluster of outputs (FB_NAME_<k>_Filter)")
    t.add_argument("--json", action="store_true", help="print JSON: the files generated (their text without -o)")
    t.set_defaults(handler=cmd_st)

    register_run(commands)
    register_verify(commands)
    register_from_rules(commands)


def ci_options(p: argparse.ArgumentParser) -> None:
    """``--junit FILE`` and ``--sarif FILE``: the findings for a CI server (synth.output.ci)."""
    p.add_argument("--junit", metavar="FILE", help="also write the findings as JUnit XML (one test case per finding)")
    p.add_argument("--sarif", metavar="FILE", help="also write the findings as SARIF 2.1.0 (one result per finding)")


def _load(path: str) -> "Filter":
    """The filter of ``path``; its warnings (a relief on a simple constraint) on stderr."""
    from synth.filter.language_check import load_filter

    f = load_filter(path)
    for w in f.warnings:
        print(w.render(), file=sys.stderr)
    return f


def _order(text: str | None) -> list[str] | None:
    """``--order O1,O2,...`` as a list of names (None when not given)."""
    return [o.strip() for o in text.split(",") if o.strip()] if text else None


def cmd_check(args: argparse.Namespace) -> int:
    from synth.output.summary import print_json
    from synth.filter.coherence import check
    from synth.output.filter_text import check_json, check_text

    from synth.output.progress import clear_progress, live_line, tty_progress

    show = tty_progress(live_line(not args.quiet))
    show(f"reading {args.filter}")
    f = _load(args.filter)
    inv = None
    if args.plant:
        from synth.filter.invariants import assumed, invariants

        show(f"the valuations {args.plant} can reach")
        inv = invariants(f, args.plant)
        f = assumed(f, inv)
    show("coherence: P1-P4, GO, pair conditions, global consistency")
    c = check(f)
    from synth.filter.reliefs import SPELLING_SIZE, spelling_warnings

    show("the keep/force spellings of the reliefs")
    warnings = spelling_warnings(f, limit=None if args.all_spellings else SPELLING_SIZE).reports()
    clear_progress(show)
    for w in warnings:
        print(w.render(), file=sys.stderr)
    if args.junit or args.sarif:
        from synth.output.ci import filter_check_report, write_ci

        write_ci([filter_check_report(f, c)], args.junit, args.sarif)
    if args.json:
        out = check_json(args.filter, c)
        if inv is not None:
            out["invariants"] = {"rules": inv.rules, "states": inv.states, "variables": list(inv.variables),
                                 "valuations": inv.valuations, "assume": list(inv.lines)}
        print_json(out)
    else:
        if inv is not None:
            sys.stdout.write(inv.text())
        sys.stdout.write(check_text(c))
    return 0 if c.holds else 1


def cmd_solve(args: argparse.Namespace) -> int:
    from synth.output.summary import print_json
    from synth.filter.solve import synthesis
    from synth.output.filter_text import synthesis_json, synthesis_text

    from synth.output.progress import clear_progress, live_line, tty_progress

    show = tty_progress(live_line(not args.quiet))
    show(f"algebraic synthesis of {args.filter}")
    s = synthesis(_load(args.filter), _order(args.order), flat=args.flat)
    clear_progress(show)
    if args.json:
        print_json(synthesis_json(args.filter, s))
    else:
        sys.stdout.write(synthesis_text(s, flat=args.flat))
        print(f"note: BDD variable order: {', '.join(s.variable_order)}", file=sys.stderr)
        for n in s.notes:
            print(f"note: {n}", file=sys.stderr)
        for w in s.warnings:
            print(f"warning: {w}", file=sys.stderr)
    return 0 if s.functional and s.consistent else 1


def cmd_st(args: argparse.Namespace) -> int:
    from synth.cli.codegen import target_of, write_target
    from synth.codegen.filter_st import filter_block, split_blocks
    from synth.codegen.provenance import provenance_lines
    from synth.codegen.targets import Target, render

    target = target_of(args)
    f = _load(args.filter)
    if args.split:
        blocks = split_blocks(f, args.algorithm, args.mode, args.name, _order(args.order))
        what = "Safety logic filter"
    else:
        blocks = [filter_block(f, args.algorithm, args.mode, args.name, _order(args.order))]
        what = f"Safety logic filter {blocks[0].name}"
    for n in (n for b in blocks for n in b.notes):
        print(f"note: {n}", file=sys.stderr)
    text = "\n".join(b.text for b in blocks)
    files = render(target, [b.pou for b in blocks], text=text, name=blocks[0].name,
                   header=provenance_lines(what, [args.filter]))
    if args.json:
        from synth.cli.codegen import print_files

        print_files(args, "filter st", blocks[0].name, str(target), [args.filter], files, write_target(args, files))
        return 0
    if target is Target.IEC and args.output is None:
        sys.stdout.write(text)
        return 0
    write_target(args, files)
    return 0


# --------------------------------------------------------------------------- run / verify / from-rules


def _algorithm_mode(p: argparse.ArgumentParser) -> None:
    p.add_argument("--algorithm", choices=("algebraic", "loop"), default="algebraic",
                   help="the solve equations (default) or the correction loop (docs/filter.md)")
    p.add_argument("--mode", choices=("supervisor", "blocking"), default="supervisor",
                   help="supervisor (default): g1 = R; blocking: g1 = 0 after a violation until Ack")


def register_run(commands: "argparse._SubParsersAction") -> None:
    r = commands.add_parser("run", help="evaluate the filter cycle by cycle on a CSV trace")
    r.add_argument("filter", metavar="F.filter", help="the .filter file")
    r.add_argument("--trace", metavar="CYCLES.csv", required=True,
                   help="header: the inputs, observers and requests R_o (and Ack); one line of 0/1 per cycle")
    _algorithm_mode(r)
    r.add_argument("--json", action="store_true", help="print JSON instead of text")
    r.set_defaults(handler=cmd_run)


def cmd_run(args: argparse.Namespace) -> int:
    from synth.output.summary import print_json
    from synth.filter.cycle import Algorithm, Mode
    from synth.filter.run import run_trace
    from synth.output.filter_text import run_json, run_text

    r = run_trace(_load(args.filter), args.trace, Algorithm(args.algorithm), Mode(args.mode))
    if args.json:
        print_json(run_json(args.filter, r))
    else:
        sys.stdout.write(run_text(r))
    return 0 if r.coherent else 1


def register_from_rules(commands: "argparse._SubParsersAction") -> None:
    g = commands.add_parser("from-rules", help="write a .filter skeleton from a rules file's constraints")
    g.add_argument("rules", metavar="P.rules", help="the plant's rules file")
    g.add_argument("-o", "--output", metavar="F.filter", required=True, help="the filter file to write")
    g.add_argument("--json", action="store_true", help="print JSON: the constraints as the skeleton takes them")
    g.set_defaults(handler=cmd_from_rules)


def cmd_from_rules(args: argparse.Namespace) -> int:
    from synth.filter.from_rules import skeleton
    from synth.output.files import write_atomic
    from synth.output.filter_text import skeleton_text

    sk = skeleton(args.rules, args.output)
    write_atomic(args.output, sk.text)
    if args.json:
        from synth.output.summary import print_json

        print_json({"rules": args.rules, "output": args.output,
                    "constraints": [{"id": c.id, "kind": str(c.kind), "outputs": list(c.outputs),
                                     "expression": c.expression} for c in sk.constraints]})
        return 0
    sys.stdout.write(skeleton_text(sk))
    print(f"wrote {args.output}")
    return 0


def register_verify(commands: "argparse._SubParsersAction") -> None:
    v = commands.add_parser("verify", help="explore the filter in closed loop with the plant (docs/filter.md)")
    v.add_argument("filter", metavar="F.filter", help="the .filter file")
    v.add_argument("--plant", metavar="P.rules", required=True, help="the plant's rules file")
    source = v.add_mutually_exclusive_group(required=True)
    source.add_argument("--grafcet", metavar="G.g7", help="the requests are this Grafcet's orders")
    source.add_argument("--control", metavar="PROG.st[:NAME]",
                        help="the requests are the VAR_OUTPUTs of this cyclic ST PROGRAM, run each scan")
    source.add_argument("--any-control", action="store_true", help="the requests are any vector, every cycle")
    _algorithm_mode(v)
    v.add_argument("--atomic-outputs", action="store_true",
                   help="write the changed outputs in one plant step (default: falls, then rises, in output order)")
    v.add_argument("--strict", action="store_true",
                   help="a violation before the PLC writes its outputs also makes the loop unsafe")
    v.add_argument("--require-sup", action="store_true",
                   help="a state outside SUP (uncontrollable events alone lead to a violation) makes the loop unsafe")
    v.add_argument("--max-states", type=int, default=None, metavar="N",
                   help="stop the exploration after N states (explicit engine: default 1000000; symbolic: after "
                        "the first level past N, default no limit)")
    v.add_argument("--engine", choices=("auto", "explicit", "symbolic"), default="auto",
                   help="explicit: node by node; symbolic: BDDs, level by level (--any-control only, without "
                        "--eventually); auto (default): symbolic there on a plant of more than 2000000 states")
    v.add_argument("--events-per-cycle", type=int, default=1, metavar="K",
                   help="the plant makes 0..K events between two PLC scans (default 1)")
    v.add_argument("--eventually", "--progress", dest="progress", metavar="GOAL",
                   help="a liveness goal: GOAL (a condition on the plant's variables, or ↑x / ↓x) stays reachable "
                        "from every state and no fair cycle avoids it (--progress: the same, its former name)")
    v.add_argument("--json", action="store_true", help="print JSON instead of text")
    v.add_argument("--quiet", action="store_true", help="no live progress line on a terminal")
    ci_options(v)
    v.set_defaults(handler=cmd_verify)


def cmd_verify(args: argparse.Namespace) -> int:
    from synth.output.summary import print_json
    from synth.choices import EngineChoice
    from synth.filter.loop.verify import DEFAULT_MAX_STATES, verify
    from synth.filter.cycle import Algorithm, Mode
    from synth.output.filter_text import verification_json, verification_text

    f = _load(args.filter)
    control = None
    if args.control is not None:
        from synth.codegen.check import require_blark

        require_blark("synth filter verify --control")  # before the interpreter, which imports blark
        from synth.codegen.interpreter.machine import load_st
        from synth.filter.loop.control_st import StSource

        control = StSource(args.control, load_st)
    from synth.output.progress import clear_progress, live_line, tty_progress

    show = tty_progress(live_line(not args.quiet))
    v = verify(f, args.plant, args.grafcet, any_control=args.any_control, algorithm=Algorithm(args.algorithm),
               mode=Mode(args.mode), atomic=args.atomic_outputs, strict=args.strict, require_sup=args.require_sup,
               max_states=args.max_states, events_per_cycle=args.events_per_cycle, progress=args.progress,
               control=control, engine=EngineChoice(args.engine), report=show)
    clear_progress(show)
    if args.junit or args.sarif:
        from synth.output.ci import filter_verify_report, write_ci

        write_ci([filter_verify_report(f, v)], args.junit, args.sarif)
    if args.json:
        out = verification_json(v)
        out["events_per_cycle"] = v.events_per_cycle
        out["control"] = v.control.json()
        out["engine"] = str(v.engine)
        if args.progress is not None:
            out["progress"] = _progress_json(v)
        print_json(out)
    else:
        text = verification_text(v)
        if v.events_per_cycle != 1:
            head, _, rest = text.partition("\n")
            text = f"{head}\nup to {v.events_per_cycle} plant events between two scans\n{rest}"
        sys.stdout.write(text + (_progress_text(v, args.progress) if args.progress is not None else ""))
    if not (v.safe and v.coherent) or (v.progress is not None and not v.progress.holds):
        return 1
    if not v.complete:
        print(f"stopped: the exploration reached --max-states {args.max_states or DEFAULT_MAX_STATES} before covering every "
              "reachable state; nothing wrong was found in the explored part"
              + (" (progress needs every state: not checked)" if args.progress is not None else ""), file=sys.stderr)
        return 2
    return 0


def _progress_text(v: "Verification", goal: str) -> str:
    """The lines of ``--progress GOAL``, after the verification's text."""
    from synth.filter.loop.verification import ProgressFailure
    from synth.output.filter_text import trace_text

    p = v.progress
    if p is None:
        return f"progress {goal}: not checked (the exploration stopped at the state limit)\n"
    if p.holds:
        return f"progress {goal}: holds: GOAL stays reachable from every state and no fair cycle avoids it\n"
    if p.failure is ProgressFailure.UNREACHABLE:
        head = f"progress {goal}: fails: GOAL cannot be reached from {p.unreachable} states"
    else:
        head = f"progress {goal}: fails: {p.avoiding} states lie on fair cycles that avoid GOAL"
    return f"{head}\n\nshortest trace (progress):\n{trace_text(p.trace)}"


def _progress_json(v: "Verification") -> dict | None:
    p = v.progress
    if p is None:
        return None
    return {"goal": p.goal, "holds": p.holds, "failure": None if p.failure is None else str(p.failure),
            "unreachable": p.unreachable, "avoiding": p.avoiding,
            "trace": [{"event": r.event, "state": r.state, "situation": r.situation, "requests": list(r.requests),
                       "orders": list(r.orders), "note": r.note, "plc_ran": r.ran} for r in p.trace]}
