"""synth against libFAUDES on the line of N double-acting cylinders (bench/gen_line.py).

    python bench/compare.py [--min-n 1] [--max-n 7] [--timeout 60] [--mem-limit 8G]
                            [--repeat 3] [--json FILE] [--dir DIR]

For each N, each tool runs in a fresh Python subprocess (``--worker``) under
``RLIMIT_AS`` = ``--mem-limit`` and is killed after ``--timeout`` seconds:

- synth: ``load_rules`` + ``plant`` + ``supremal_controllable`` + counting SUP's states
  and transitions (timed end to end, imports excluded);
- libFAUDES: ``Parallel`` of the element Systems (the plant), ``Parallel`` of elements
  and constraint observers (the specification), ``SupConClosed`` (see
  bench/faudes_route.py). Writing and reading the small input files is timed apart.

Peak memory is the child's ``ru_maxrss`` (from ``os.wait4``): the whole process,
interpreter and libraries included (``base`` = the same after imports only).
Both tools' plant and SUP state/transition counts must agree; for N <= --check-max a
third subprocess also checks ``faudes.LanguageEquality`` of the two SUPs.
A tool that fails (timeout, memory, error) at some N is not run for larger N.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
for _p in (str(ROOT), str(HERE)):
    if _p not in sys.path:
        sys.path.insert(0, _p)

TOOLS = ("synth", "faudes")


# ---------------------------------------------------------------------------- workers
def _maxrss_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _worker_synth(rules: Path, out: dict) -> None:
    t0 = time.perf_counter()
    from synth.plant.composition import plant
    from synth.syntax import parser
    from synth.plant.rules_check import load_rules
    from synth.sup.supervisor import supremal_controllable

    parser("rules")  # one-time start-up: lark builds the LALR tables (about 0.1 s)
    import numpy

    numpy.unique(numpy.zeros(2))  # one-time start-up: numpy imports its set routines lazily (about 0.03 s)
    out["import_s"] = time.perf_counter() - t0
    out["base_mib"] = _maxrss_mib()
    t0 = time.perf_counter()
    rs = load_rules(rules)
    t1 = time.perf_counter()
    p = plant(rs)
    t2 = time.perf_counter()
    sup = supremal_controllable(p, rs.constraints)
    t3 = time.perf_counter()
    states, transitions = sup.size, sup.count_transitions()
    t4 = time.perf_counter()
    out.update(
        parse_s=t1 - t0,
        plant_s=t2 - t1,
        sup_s=t3 - t2,
        count_s=t4 - t3,
        total_s=t4 - t0,
        plant_states=p.size,
        plant_transitions=p.count_transitions(),
        sup_states=states,
        sup_transitions=transitions,
    )


def _worker_faudes(rules: Path, workdir: Path, out: dict) -> None:
    t0 = time.perf_counter()
    import faudes  # prints two harmless WARNING lines (no matplotlib/pillow)

    from faudes_route import run_faudes, write_inputs
    from synth.plant.rules_check import load_rules

    out["import_s"] = time.perf_counter() - t0
    out["base_mib"] = _maxrss_mib()
    inputs = write_inputs(load_rules(rules), workdir)
    r = run_faudes(inputs, faudes)
    out.update(
        files_s=inputs.seconds + r["read_s"],
        plant_s=r["plant_s"],
        spec_s=r["spec_s"],
        sup_s=r["sup_s"],
        total_s=r["total_s"],
        plant_states=r["plant"].Size(),
        plant_transitions=r["plant"].TransRelSize(),
        spec_states=r["spec"].Size(),
        sup_states=r["sup"].Size(),
        sup_transitions=r["sup"].TransRelSize(),
    )


def _worker_check(rules: Path, workdir: Path, out: dict) -> None:
    import faudes

    from faudes_route import run_faudes, write_inputs
    from synth.plant.composition import plant
    from synth.output.faudes import supervisor_generator
    from synth.plant.rules_check import load_rules
    from synth.sup.supervisor import supremal_controllable

    rs = load_rules(rules)
    sup = supremal_controllable(plant(rs), rs.constraints)
    workdir.mkdir(parents=True, exist_ok=True)
    ours = workdir / "synth_sup.gen"
    ours.write_text(supervisor_generator(sup), encoding="utf-8")
    theirs = run_faudes(write_inputs(rs, workdir), faudes)["sup"]
    out["language_equal"] = bool(faudes.LanguageEquality(theirs, faudes.System(str(ours))))


def worker(kind: str, n: int, directory: Path) -> int:
    from gen_line import write_line

    rules, _, _ = write_line(n, directory)
    out: dict = {"tool": kind, "n": n}
    try:
        if kind == "synth":
            _worker_synth(rules, out)
        elif kind == "faudes":
            _worker_faudes(rules, directory / f"faudes_{n}", out)
        else:
            _worker_check(rules, directory / f"check_{n}", out)
    except MemoryError:
        out["status"] = "memory"
        print(json.dumps(out), flush=True)
        return 3
    out["status"] = "ok"
    out["peak_mib"] = _maxrss_mib()
    print(json.dumps(out), flush=True)
    return 0


# ---------------------------------------------------------------------------- parent
def _run_child(kind: str, n: int, directory: Path, timeout: float, mem_bytes: int) -> dict:
    """One measurement in a fresh subprocess; status ok | timeout | memory | error."""

    def limit() -> None:  # in the child, before exec
        resource.setrlimit(resource.RLIMIT_AS, (mem_bytes, mem_bytes))

    with tempfile.TemporaryFile() as fout, tempfile.TemporaryFile() as ferr:
        cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", kind, str(n), str(directory)]
        start = time.perf_counter()
        proc = subprocess.Popen(cmd, stdout=fout, stderr=ferr, preexec_fn=limit, cwd=str(ROOT))
        killed = threading.Event()

        def kill() -> None:
            killed.set()
            proc.kill()

        timer = threading.Timer(timeout, kill)
        timer.start()
        _, status, usage = os.wait4(proc.pid, 0)
        timer.cancel()
        proc.returncode = os.waitstatus_to_exitcode(status)
        wall = time.perf_counter() - start
        fout.seek(0)
        ferr.seek(0)
        text, err = fout.read().decode(errors="replace"), ferr.read().decode(errors="replace")
    rec: dict = {"tool": kind, "n": n}
    for line in reversed(text.splitlines()):
        if line.startswith("{"):
            rec = json.loads(line)
            break
    rec["process_wall_s"] = wall
    rec["process_peak_mib"] = usage.ru_maxrss / 1024.0
    if killed.is_set():
        rec["status"] = "timeout"
    elif rec.get("status") not in ("ok", "memory"):
        low = err.lower()
        if "memoryerror" in low or "bad_alloc" in low or "cannot allocate" in low or proc.returncode == -signal.SIGABRT:
            rec["status"] = "memory"
        else:
            rec["status"] = "error"
            rec["stderr"] = "\n".join(err.strip().splitlines()[-8:])
    return rec


def machine() -> dict:
    info: dict = {
        "nproc": os.cpu_count(),
        "python": platform.python_version(),
        "platform": platform.platform(),
    }
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                info["cpu"] = line.split(":", 1)[1].strip()
                break
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal"):
                info["mem_total_gib"] = round(int(line.split()[1]) / 2**20, 1)
                break
    except OSError:
        pass
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True)
        dirty = subprocess.run(["git", "status", "--porcelain", "--", "synth"], cwd=ROOT, capture_output=True, text=True)
        info["commit"] = head.stdout.strip() + (" (synth/ modified)" if dirty.stdout.strip() else "")
    except OSError:
        pass
    info["loadavg"] = os.getloadavg()
    try:
        import numpy

        info["numpy"] = numpy.__version__
    except ImportError:
        pass
    try:
        from importlib.metadata import version

        info["faudes"] = version("faudes")
        info["lark"] = version("lark")
    except Exception:
        pass
    return info


def _parse_size(text: str) -> int:
    t = text.strip().upper().removesuffix("B").removesuffix("I")
    mult = {"K": 2**10, "M": 2**20, "G": 2**30, "T": 2**40}
    if t and t[-1] in mult:
        return int(float(t[:-1]) * mult[t[-1]])
    return int(t)


def _fmt_s(rec: dict | None) -> str:
    if rec is None:
        return "-"
    if rec["status"] != "ok":
        return rec["status"]
    s = rec["total_s"]
    return f"{s:.4f}" if s < 1 else f"{s:.2f}"


def _fmt_mib(rec: dict | None) -> str:
    if rec is None or "process_peak_mib" not in rec:
        return "-"
    return f"{rec['process_peak_mib']:.0f}"


def table(rows: list[dict]) -> str:
    head = ("N", "plant states", "plant trans.", "SUP states", "SUP trans.", "synth s", "synth MiB",
            "libFAUDES s", "libFAUDES MiB", "speed-up", "counts", "language")
    lines = ["| " + " | ".join(head) + " |", "|" + "|".join("---:" for _ in head) + "|"]
    for r in rows:
        s, f = r.get("synth"), r.get("faudes")
        ok = [x for x in (s, f) if x and x["status"] == "ok"]
        ref = ok[0] if ok else {}
        ratio = "-"
        if s and f and s["status"] == f["status"] == "ok":
            x = f["total_s"] / s["total_s"]
            ratio = f"{x:.1f}×" if x < 10 else f"{x:.0f}×"
        cells = (
            str(r["n"]),
            str(ref.get("plant_states", "-")),
            str(ref.get("plant_transitions", "-")),
            str(ref.get("sup_states", "-")),
            str(ref.get("sup_transitions", "-")),
            _fmt_s(s), _fmt_mib(s), _fmt_s(f), _fmt_mib(f), ratio,
            {True: "equal", False: "DIFFER", None: "-"}[r.get("counts_equal")],
            {True: "equal", False: "DIFFER", None: "-"}[r.get("language_equal")],
        )
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _measure(kind: str, n: int, args, directory: Path, progress) -> dict:
    runs = []
    for k in range(args.repeat):
        progress(f"N={n} {kind} run {k + 1}/{args.repeat} ...")
        rec = _run_child(kind, n, directory, args.timeout, args.mem_limit)
        runs.append(rec)
        if rec["status"] != "ok" or rec["total_s"] > args.repeat_below:
            break
    ok = [r for r in runs if r["status"] == "ok"]
    if not ok:
        return runs[-1]
    best = dict(sorted(ok, key=lambda r: r["total_s"])[len(ok) // 2])  # the median run
    best["runs_total_s"] = [r["total_s"] for r in ok]
    best["process_peak_mib"] = max(r["process_peak_mib"] for r in ok)
    best["median_total_s"] = statistics.median(best["runs_total_s"])
    return best


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--min-n", type=int, default=1)
    ap.add_argument("--max-n", type=int, default=7)
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds per tool and N (default 60)")
    ap.add_argument("--mem-limit", type=_parse_size, default=8 * 2**30, help="address space per tool run (default 8G)")
    ap.add_argument("--repeat", type=int, default=5, help="runs per tool and N, median kept (default 5)")
    ap.add_argument("--repeat-below", type=float, default=5.0, help="repeat only runs shorter than this (s)")
    ap.add_argument("--check-max", type=int, default=4, help="check LanguageEquality up to this N (default 4)")
    ap.add_argument("--tools", default="synth,faudes", help="comma-separated: synth,faudes")
    ap.add_argument("--json", metavar="FILE", help="write the measurements as JSON")
    ap.add_argument("--dir", metavar="DIR", help="where to write generated files (default: a temporary folder)")
    ap.add_argument("--worker", nargs=3, metavar=("KIND", "N", "DIR"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        kind, n, d = args.worker
        return worker(kind, int(n), Path(d))

    tools = [t for t in args.tools.split(",") if t]
    for t in tools:
        if t not in TOOLS:
            ap.error(f"unknown tool {t!r} (choose from {', '.join(TOOLS)})")
    tty = sys.stderr.isatty()

    def progress(msg: str) -> None:
        if tty:
            print(f"\r\033[K{msg}", end="", file=sys.stderr, flush=True)

    tmp = None
    if args.dir:
        directory = Path(args.dir)
        directory.mkdir(parents=True, exist_ok=True)
    else:
        tmp = tempfile.TemporaryDirectory(prefix="synth-bench-")
        directory = Path(tmp.name)
    rows: list[dict] = []
    failed: set[str] = set()
    start_machine = machine()
    try:
        for n in range(args.min_n, args.max_n + 1):
            row: dict = {"n": n}
            for t in tools:
                row[t] = None if t in failed else _measure(t, n, args, directory, progress)
                if row[t] is not None and row[t]["status"] != "ok":
                    failed.add(t)
            ok = [row[t] for t in tools if row.get(t) and row[t]["status"] == "ok"]
            keys = ("plant_states", "plant_transitions", "sup_states", "sup_transitions")
            row["counts_equal"] = (all(ok[0][k] == ok[1][k] for k in keys)) if len(ok) == 2 else None
            row["language_equal"] = None
            if len(ok) == 2 and n <= args.check_max:
                progress(f"N={n} LanguageEquality ...")
                chk = _run_child("check", n, directory, args.timeout * 4, args.mem_limit)
                row["language_equal"] = chk.get("language_equal") if chk["status"] == "ok" else None
            rows.append(row)
            if set(tools) <= failed:
                break
    finally:
        progress("")
        if tmp is not None:
            tmp.cleanup()

    largest = {t: max((r["n"] for r in rows if r.get(t) and r[t]["status"] == "ok"), default=None) for t in tools}
    ratio5 = None
    r5 = next((r for r in rows if r["n"] == 5), None)
    if r5 and r5.get("synth") and r5.get("faudes") and r5["synth"]["status"] == r5["faudes"]["status"] == "ok":
        ratio5 = r5["faudes"]["total_s"] / r5["synth"]["total_s"]
    print(table(rows))
    print()
    limit = f"{args.timeout:g} s and {args.mem_limit / 2**30:g} GiB"
    for t in tools:
        name = "libFAUDES" if t == "faudes" else t
        print(f"largest N within {limit}: {name} {largest[t] if largest[t] is not None else 'none'}")
    if ratio5 is not None:
        print(f"N=5: libFAUDES time / synth time = {ratio5:.1f}")
    mismatch = [r["n"] for r in rows if r.get("counts_equal") is False or r.get("language_equal") is False]
    if mismatch:
        print(f"MISMATCH between synth and libFAUDES at N = {mismatch}")
    if args.json:
        data = {
            "machine_at_start": start_machine,
            "machine": machine(),
            "settings": {k: getattr(args, k) for k in ("min_n", "max_n", "timeout", "mem_limit", "repeat", "repeat_below", "check_max")},
            "rows": rows,
            "largest_n": largest,
            "ratio_n5": ratio5,
        }
        Path(args.json).write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")
    return 1 if mismatch else 0


if __name__ == "__main__":
    sys.exit(main())
