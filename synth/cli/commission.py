"""CLI command ``synth commission [G.g7] --plant P.rules (--modbus HOST:PORT --io MAP | --opcua URL)``:
synth's plant automaton drives a PLC runtime, step by step (docs/commissioning.md).

Example::

    $ synth commission grafcets/tri.g7 --plant plants/tri.rules --modbus 127.0.0.1:5020 --io openplc-server \\
          --lock-step --walks 5 --steps 1000 --seed 1
"""

from __future__ import annotations

import argparse
import sys

__all__ = ["register", "cmd_commission"]


def register(sub: "argparse._SubParsersAction") -> None:
    """Add ``commission`` to the ``synth`` parser."""
    p = sub.add_parser("commission", help="virtual commissioning: the plant model drives a PLC runtime over Modbus TCP or OPC UA",
                       description="Each step fires one plant event, writes the sensors, waits whole PLC scans, reads "
                                   "the orders and applies them to the plant: an order the rules refuse or that leaves "
                                   "SUP is unsafe, orders that differ from the Grafcet's (synth run) a mismatch, no "
                                   "change for N steps blocked. Exit 0 pass, 1 found, 2 bad input or a PLC that fails.")
    p.add_argument("grafcet", metavar="GRAFCET.g7", nargs="?",
                   help="the reference Grafcet (without it: safety and blocking only, for any PLC program)")
    p.add_argument("--plant", metavar="RULES", required=True, help="the plant (.rules, with its constraints)")
    p.add_argument("--modbus", metavar="HOST:PORT", help="Modbus TCP: the runtime's server, or where synth serves "
                   "the runtime that polls it (--io openplc-device)")
    p.add_argument("--opcua", metavar="URL", help="OPC UA: the runtime's server, variables by name (opc.tcp://HOST:PORT)")
    p.add_argument("--node-prefix", metavar="PREFIX",
                   help="OPC UA: a variable's node id is PREFIX + its name (default ns=2;s=)")
    p.add_argument("--io", metavar="MAP", help="Modbus: the layout the program was generated with (openplc-server, "
                   "openplc-device) or its address table / map (.csv)")
    p.add_argument("--lock-step", action="store_true",
                   help="the runtime runs the scans synth grants (deterministic; default: real time)")
    p.add_argument("--period", metavar="PERIOD", default="10ms", help="the PLC task period (default 10ms)")
    p.add_argument("--timeout", metavar="SECONDS", type=float, default=5.0,
                   help="longest wait for the runtime's answer (default 5)")
    p.add_argument("--events", metavar="E1,E2,…", help="one scripted walk: ↑dcy,↑cp12,2s/X101,… (^ and _ for ↑ and ↓)")
    p.add_argument("--walks", metavar="N", type=int, default=1, help="seeded random walks (default 1)")
    p.add_argument("--steps", metavar="M", type=int, default=100, help="events per walk (default 100)")
    p.add_argument("--seed", metavar="S", type=int, default=0, help="seed of the walks (default 0)")
    p.add_argument("--cover", action="store_true",
                   help="aim the walks at plant transitions not seen yet; report the coverage of the plant "
                        "transitions and Grafcet steps reachable under the Grafcet")
    p.add_argument("--fault", metavar="FAULT", action="append", default=[],
                   help="also run the walks under a fault: stuck sensor v11=0, lost order AVANCER2, late sensor "
                        "↑v21+500ms (repeatable: each on its own)")
    p.add_argument("--blocked-after", metavar="N", type=int, default=50,
                   help="blocked when no event changes the situation for N steps (default 50)")
    p.add_argument("--keep-going", action="store_true",
                   help="refuse an unsafe move (the plant stays, as validate keeps a prohibited order unapplied), "
                        "count it and go on: the walk ends unsafe, with every step it refused")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--report", metavar="DIR", help="also write DIR/index.html: each walk, the closed-loop trace of "
                   "every walk that did not pass (PLC's and Grafcet's orders, steps, plant state, scans), the coverage")
    p.add_argument("--junit", metavar="FILE", help="also write the findings as JUnit XML")
    p.add_argument("--sarif", metavar="FILE", help="also write the findings as SARIF 2.1.0")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.set_defaults(handler=cmd_commission)


def cmd_commission(args: argparse.Namespace) -> int:
    from synth.commission.device import Timing
    from synth.commission.report import ci_report, result_json, result_text
    from synth.commission.run import Commissioning, run_commission
    from synth.commission.setup import open_link, period_ms, prepare
    from synth.output.summary import print_json

    setup, rules, io, faults = prepare(args.grafcet, args.plant, args.io, args.fault, args.blocked_after, args.keep_going)
    timing = Timing.LOCKSTEP if args.lock_step else Timing.REALTIME
    link = open_link(io, args.modbus, args.opcua, timing=timing, period=period_ms(args.period), timeout=args.timeout,
                     names=(setup.sensors, setup.orders), prefix=args.node_prefix)
    progress = None if args.quiet else (lambda text: print(f"commission: {text}", file=sys.stderr, flush=True))
    try:
        c = Commissioning(setup, link, rules, progress)
        protocol = f"Modbus TCP {args.modbus}" if args.modbus else f"OPC UA {args.opcua}"
        result = run_commission(c, target=args.grafcet or args.plant, protocol=protocol, events=args.events,
                                walks=args.walks, steps=args.steps, seed=args.seed, faults=faults, cover=args.cover)
    finally:
        link.close()
    if args.junit or args.sarif:
        from synth.output.ci import write_ci

        write_ci([ci_report(result)], args.junit, args.sarif)
    if args.report:
        from pathlib import Path

        from synth.output.files import write_atomic
        from synth.output.html import commission_html

        write_atomic(Path(args.report) / "index.html", commission_html(result_json(result)))
    if args.json:
        print_json(result_json(result))
    else:
        sys.stdout.write(result_text(result))
    return 0 if result.ok else 1
