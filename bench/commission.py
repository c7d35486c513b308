"""Closed-loop throughput of ``synth commission`` on 127.0.0.1.

    python bench/commission.py [--grafcet grafcets/tri.g7] [--plant plants/tri.rules]
                               [--walks 5] [--steps 1000] [--realtime-steps 300] [--period 10]
                               [--modbus HOST:PORT --io LAYOUT --timing lock-step|real-time] [--json FILE]

Without ``--modbus`` the device under test is synth's own program in its ST interpreter
(``synth.commission.device``) on a free local port, once per layout (``openplc-server``: the
runtime serves; ``openplc-device``: the runtime polls synth) and per timing: lock-step (walks of
``--steps`` events, seeds 1..walks) and real time (one walk of ``--realtime-steps`` events at a
``--period`` ms task). With ``--modbus`` it drives that runtime instead (an OpenPLC v3 built
with the handshake of docs/commissioning.md, say) in the ``--timing`` it was started in.

Per run: closed-loop steps per second (wall time of the walks, the initial steps included; in
real time the timers' waits are in it), PLC scans per second (lock-step: the timers' scans
granted in one request are counted), in real time the latency of one exchange (write the
sensors, wait a whole scan, read the orders: 200 of them after the walk), and the verdict (a
mismatch would show there).
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def step_latency(link: object, sensors: tuple[str, ...], n: int = 200) -> dict[str, float]:
    """One closed-loop exchange without the plant model: write the sensors, wait a whole scan,
    read the orders; ``n`` times after a reset (mean, median, 95th percentile, in ms)."""
    import statistics

    values = {s: False for s in sensors}
    link.reset(values)  # type: ignore[attr-defined]
    times = []
    for k in range(n):
        values[sensors[k % len(sensors)]] = not values[sensors[k % len(sensors)]]
        t = time.perf_counter()
        link.write_sensors(values)  # type: ignore[attr-defined]
        link.scans(1)  # type: ignore[attr-defined]
        link.read_orders()  # type: ignore[attr-defined]
        times.append(1000 * (time.perf_counter() - t))
    times.sort()
    return {"mean": round(statistics.fmean(times), 2), "median": round(statistics.median(times), 2),
            "p95": round(times[int(0.95 * (n - 1))], 2)}


def one_run(args: argparse.Namespace, layout: str, lockstep: bool, port: int, host: str = "127.0.0.1") -> dict:
    from synth.commission.device import Timing
    from synth.commission.run import Commissioning, run_commission
    from synth.commission.setup import open_link, prepare

    setup, rules, io, _ = prepare(args.grafcet, args.plant, layout, [], 50)
    timing = Timing.LOCKSTEP if lockstep else Timing.REALTIME
    link = open_link(io, f"{host}:{port}", None, timing=timing, period=args.period, timeout=10.0)
    try:
        c = Commissioning(setup, link, rules)
        walks, steps = (args.walks, args.steps) if lockstep else (1, args.realtime_steps)
        res = run_commission(c, target=args.grafcet, protocol="Modbus TCP", events=None, walks=walks, steps=steps,
                             seed=1, faults=(), cover=False)
        latency = step_latency(link, setup.sensors) if not lockstep else None
    finally:
        link.close()
    scans = sum(w.steps[-1].scans for r in res.runs for w in r.walks)
    return {"layout": layout, "timing": str(timing), "walks": walks, "steps": res.steps, "seconds": round(res.seconds, 3),
            "steps_per_s": round(res.steps / res.seconds, 1), "scans": scans,
            "scans_per_s": round(scans / res.seconds, 1), "ms_per_step": round(1000 * res.seconds / res.steps, 2),
            "verdict": "pass" if res.ok else "fail", "step_latency_ms": latency,
            "outcomes": [w.outcome.value for r in res.runs for w in r.walks]}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--grafcet", default=str(ROOT / "grafcets" / "tri.g7"))
    ap.add_argument("--plant", default=str(ROOT / "plants" / "tri.rules"))
    ap.add_argument("--walks", type=int, default=5)
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--realtime-steps", type=int, default=300)
    ap.add_argument("--period", type=int, default=10, help="task period, ms")
    ap.add_argument("--modbus", help="drive this runtime instead of the interpreted device")
    ap.add_argument("--io", default="openplc-server", help="with --modbus: the layout its program was built with")
    ap.add_argument("--timing", choices=("lock-step", "real-time"), default="lock-step",
                    help="with --modbus: how that runtime was started")
    ap.add_argument("--json", help="write the rows to FILE")
    args = ap.parse_args()
    rows = []
    if args.modbus:
        host, _, port = args.modbus.rpartition(":")
        rows.append(one_run(args, args.io, args.timing == "lock-step", int(port), host))
        print(json.dumps(rows[-1]), flush=True)
    else:
        from synth.commission.device import InterpretedPlc, Timing, located_program
        from synth.commission.iomap import Layout, Role, layout_map
        from synth.commission.modbus import free_port

        t = time.monotonic()
        parsed, pou, io = located_program(args.grafcet, args.plant, "openplc-server")
        print(f"parsed the program in {time.monotonic() - t:.1f} s", file=sys.stderr)
        names = ([e.name for e in io.of(Role.SENSOR)], [e.name for e in io.of(Role.ORDER)])
        for layout in ("openplc-server", "openplc-device"):
            for lockstep in (True, False):
                port = free_port()
                timing = Timing.LOCKSTEP if lockstep else Timing.REALTIME
                with InterpretedPlc(parsed, pou, layout_map(Layout(layout), *names), "127.0.0.1", port,
                                    period_ms=args.period, timing=timing):
                    rows.append(one_run(args, layout, lockstep, port))
                print(json.dumps(rows[-1]), flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps({"machine": platform.platform(), "python": platform.python_version(),
                                               "grafcet": args.grafcet, "rows": rows}, indent=2) + "\n")
    return 0 if all(r["verdict"] == "pass" for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
