"""CLI commands of the Grafcet stage: ``synth ass`` and ``synth run``.

``synth ass FILE.g7 [--plant RULES] [--json] [--dot FILE] [--svg FILE]`` prints the
automaton of the stable situations; ``synth run FILE.g7 [--plant RULES] --events
"↑dcy,↑cp12,2s/X101,↓v10"`` simulates the Grafcet event by event and prints each
stable situation with its orders (the initial one first).

Example (text output of ``synth run``)::

    0  initial   {X0, X100, X200, X300}   orders: -
    1  ↑dcy      {X1, X100, X200, X300}   orders: TAPIS   fired: 0->1
"""

from __future__ import annotations

import argparse
import sys

TYPE_CHECKING = False  # typing.TYPE_CHECKING, without importing typing (fast --help)
if TYPE_CHECKING:  # pragma: no cover - the library is imported by the commands only (fast --help)
    from collections.abc import Callable, Mapping

    from synth.grafcet.language import Grafcet

__all__ = ["register", "cmd_ass", "cmd_run"]


# --------------------------------------------------------------------------- loading


def _load(args: argparse.Namespace) -> tuple[Grafcet, dict[str, bool], Callable[[Mapping[str, bool]], bool] | None]:
    """The Grafcet (checked against the plant if given), the initial input values, and
    the plant's test of admissible input vectors (None without a plant)."""
    from synth.grafcet.language_check import load_grafcet

    initial: dict[str, bool] = {}
    admissible = None
    if args.plant:
        from synth.plant.composition import plant
        from synth.plant.rules_check import load_rules

        rs = load_rules(args.plant)
        grafcet = load_grafcet(args.file, inputs=rs.inputs, outputs=rs.outputs, semantics=args.semantics)
        initial = {v.name: v.initial for v in rs.variables if v.is_input}
        admissible = plant(rs).admissible_inputs()
    else:
        grafcet = load_grafcet(args.file, semantics=args.semantics)
    initial = {n: initial.get(n, False) for n in grafcet.inputs}
    if args.initial:
        from synth.grafcet.simulation import parse_initial

        initial.update(parse_initial(args.initial, grafcet.inputs))
    return grafcet, initial, admissible


# --------------------------------------------------------------------------- commands


def cmd_ass(args: argparse.Namespace) -> int:
    from synth.grafcet.ass import stable_situation_automaton
    from synth.grafcet.machine import GrafcetMachine
    from synth.output.dot import ass_dot
    from synth.output.files import write_atomic
    from synth.output.html import write_svg
    from synth.output.summary import ass_json, ass_text

    grafcet, initial, admissible = _load(args)
    machine = GrafcetMachine(grafcet)
    ass = stable_situation_automaton(machine, initial_inputs=initial, admissible=admissible)
    dot = ass_dot(ass, grafcet.path)
    if args.dot:
        write_atomic(args.dot, dot)
    if args.svg:
        write_svg(args.svg, dot)
    if args.json:
        import json

        sys.stdout.write(json.dumps(ass_json(ass), indent=2, ensure_ascii=False) + "\n")
    else:
        sys.stdout.write(ass_text(ass, grafcet.path))
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    from synth.grafcet.simulation import parse_events, simulate
    from synth.output.summary import run_text

    grafcet, inputs, _ = _load(args)
    rows = simulate(grafcet, inputs, parse_events(args.events or "", grafcet))
    if args.json:
        from synth.output.codegen_json import run_json
        from synth.output.summary import print_json

        print_json(run_json(grafcet.path, rows))
    else:
        sys.stdout.write(run_text(rows))
    return 0


SEMANTICS_HELP = ("how the Grafcet evolves: grafcet (IEC 60848, search for stability; default) or sfc "
                  "(IEC 61131-3 SFC, one evolution per PLC scan: the meaning of an imported PLC program)")


def _common(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", metavar="FILE.g7", help="the Grafcet")
    p.add_argument("--plant", metavar="RULES", help="plant .rules file: its inputs/outputs and initial input values")
    p.add_argument("--initial", metavar="X=1,...", help="initial input values (default: the plant's, else all 0)")
    p.add_argument("--semantics", choices=("grafcet", "sfc"), default="grafcet", help=SEMANTICS_HELP)


def register(sub: "argparse._SubParsersAction") -> None:
    """Add this stage's sub-commands to the ``synth`` parser."""
    p = sub.add_parser("ass", help="automaton of the stable situations of a Grafcet",
                       description="Build the automaton of the stable situations (ASS) of a Grafcet.")
    _common(p)
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.add_argument("--dot", metavar="FILE", help="write the Graphviz DOT text")
    p.add_argument("--svg", metavar="FILE", help="write an SVG drawing (Graphviz)")
    p.set_defaults(handler=cmd_ass)
    p = sub.add_parser("run", help="simulate a Grafcet event by event",
                       description="Simulate a Grafcet: print each stable situation and its orders.")
    _common(p)
    p.add_argument("--events", metavar="EVENTS", default="",
                   help='comma-separated events: "↑dcy,^cp12,2s/X101,↓v10,_v11"')
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(handler=cmd_run)
