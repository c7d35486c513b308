"""CLI commands of the code-generation stage: ``synth st``, ``synth sfc``, ``synth import``.

``synth st G.g7 [--plant P.rules] [--filter F.filter] [--name NAME] [-o prog.st] [--xml]``
writes the Grafcet as one IEC 61131-3 ``PROGRAM`` (with the filter's ``FUNCTION_BLOCK`` run
last); ``synth st --check G.g7 [--plant P.rules] [--depth N]`` reruns the proof that the
program equals ``synth run`` (exit 1 on a mismatch); ``synth sfc G.g7 -o G.xml`` exports the
Grafcet as a PLCopen SFC; ``synth import G.xml -o G.g7`` reads a PLCopen SFC back.

Example::

    $ synth st --check grafcets/timers.g7 --depth 3
    grafcets/timers.g7: the ST program equals synth run on 13 event sequences (21 PLC cycles, depth 3): 0 mismatches
"""

from __future__ import annotations

import argparse
import sys

TYPE_CHECKING = False  # typing.TYPE_CHECKING, without importing typing (fast --help)

if TYPE_CHECKING:  # pragma: no cover - the library is imported by the commands only (fast --help)
    from synth.codegen.program import StProgram
    from synth.codegen.targets import Target
    from synth.grafcet.language import Grafcet

__all__ = ["register", "cmd_st", "cmd_sfc", "cmd_import", "print_files", "write_target", "target_of"]


def _load(args: argparse.Namespace) -> tuple["Grafcet", dict[str, bool], list[str]]:
    """The Grafcet (checked against the plant if given), the initial inputs, the source files."""
    from synth.grafcet.language_check import load_grafcet

    sources = [args.file]
    initial: dict[str, bool] = {}
    if args.plant:
        from synth.plant.rules_check import load_rules

        rs = load_rules(args.plant)
        grafcet = load_grafcet(args.file, inputs=rs.inputs, outputs=rs.outputs,
                               semantics=getattr(args, "semantics", "grafcet"))
        initial = {v.name: v.initial for v in rs.variables if v.is_input}
        sources.append(args.plant)
    else:
        grafcet = load_grafcet(args.file, semantics=getattr(args, "semantics", "grafcet"))
    return grafcet, {n: initial.get(n, False) for n in grafcet.inputs}, sources


def _write(args: argparse.Namespace, data: str | bytes) -> None:
    """To ``-o`` or standard output; with ``--json`` and no ``-o`` the JSON carries it instead."""
    from synth.output.files import write_or_print

    if args.output or not getattr(args, "json", False):
        write_or_print(args.output, data)


def target_of(args: argparse.Namespace) -> "Target":
    """``--target``, with ``--xml`` as the short form of ``--target plcopen``."""
    from synth.codegen.targets import Target
    from synth.errors import InputError

    if args.xml and args.target not in (None, Target.PLCOPEN):
        raise InputError(f"--xml is --target plcopen; it cannot go with --target {args.target}", None)
    return Target(args.target or (Target.PLCOPEN if args.xml else Target.IEC))


def write_target(args: argparse.Namespace, files: list[tuple[str, bytes]]) -> list[str | None]:
    """One file to ``-o`` (or standard output); several (TwinCAT: one per POU) into ``-o DIR``,
    as is one into an existing folder or a path ending with ``/``. The paths written (None:
    printed, or carried by ``--json``)."""
    import os

    from synth.output.files import write_files

    folder = args.output is not None and (args.output.endswith(("/", os.sep)) or os.path.isdir(args.output))
    if len(files) == 1 and not folder:
        _write(args, files[0][1])
        return [args.output]
    write_files(args.output, files)
    return [os.path.join(args.output, name) for name, _ in files]


def print_files(args: argparse.Namespace, command: str, pou: str, target: str, sources: list[str],
                 files: list[tuple[str, bytes]], written: list[str | None]) -> None:
    if getattr(args, "json", False):
        from synth.output.codegen_json import files_json
        from synth.output.summary import print_json

        print_json(files_json(command, pou, target, sources, files, written))


def cmd_st(args: argparse.Namespace) -> int:
    from synth.codegen.grafcet_st import generate_program
    from synth.codegen.program import filter_call
    from synth.codegen.provenance import provenance_lines
    from synth.codegen.targets import render

    grafcet, initial, sources = _load(args)
    target = target_of(args)
    if args.check:
        if args.filter or args.output:
            from synth.errors import InputError

            raise InputError("--check proves the Grafcet's program and writes nothing: drop --filter and -o", None)
        import dataclasses

        from synth.codegen.check import differential_check
        from synth.codegen.targets import st_of

        program = generate_program(grafcet, name=args.name, sources=sources)
        if args.io:
            program = _located(args, program, grafcet)
        header = provenance_lines(f"PROGRAM {program.program}", sources)
        files = render(target, program.pous, text=program.text, name=program.program, header=header)
        text = st_of(target, files, args.file)
        from synth.output.progress import clear_progress, live_line, tty_progress

        show = tty_progress(live_line(not args.quiet))
        report = differential_check(grafcet, initial, depth=args.depth, program=dataclasses.replace(program, text=text),
                                    report=show)
        clear_progress(show)
        if args.junit or args.sarif:
            from synth.output.ci import st_check_report, write_ci

            write_ci([st_check_report(grafcet, report)], args.junit, args.sarif)
        if args.json:
            from synth.output.codegen_json import st_check_json
            from synth.output.summary import print_json

            print_json(st_check_json(report))
        else:
            sys.stdout.write(report.text())
        return 0 if report.ok else 1
    call = None
    if args.filter:
        from synth.codegen.filter_st import filter_block
        from synth.filter.language_check import load_filter

        call = filter_call(filter_block(load_filter(args.filter)))
        sources.append(args.filter)
    program = generate_program(grafcet, name=args.name, sources=sources, filter_call=call)
    if args.io:
        program = _located(args, program, grafcet)
    config = None
    if args.task:
        from synth.codegen.program import configuration

        config = configuration(program.program, args.task)
    header = provenance_lines(f"PROGRAM {program.program}", sources)
    files = render(target, program.pous, text=program.text, name=program.program, header=header, config=config)
    print_files(args, "st", program.program, str(target), sources, files, write_target(args, files))
    return 0


def _located(args: argparse.Namespace, program: "StProgram", grafcet: "Grafcet") -> "StProgram":
    """``--io``: the program's plant inputs and outputs located by the layout or map; its
    address table (JSON and CSV) beside ``-o`` (``tri.st`` → ``tri.io.json``, ``tri.io.csv``)."""
    import json
    import os

    from synth.codegen.program import with_locations
    from synth.commission.iomap import io_map
    from synth.output.files import write_atomic

    m = io_map(args.io, grafcet.inputs, grafcet.outputs)
    note = f"I/O: --io {m.layout.value if m.layout.value != 'map' else os.path.basename(args.io)}, located variables"
    located = with_locations(program, m.locations, note)
    if args.output and not args.check and not args.output.endswith(("/", os.sep)) and not os.path.isdir(args.output):
        stem = os.path.splitext(args.output)[0]
        write_atomic(stem + ".io.json", json.dumps(m.table_json(), indent=2) + "\n")
        write_atomic(stem + ".io.csv", m.table_csv())
    return located


def cmd_sfc(args: argparse.Namespace) -> int:
    from synth.codegen.plcopen.export import sfc_project_xml
    from synth.codegen.program import program_name
    from synth.codegen.provenance import provenance_lines

    grafcet, _, sources = _load(args)
    comment = "\n".join(provenance_lines("SFC " + (args.name or program_name(grafcet.path)), sources))
    pou = args.name or program_name(grafcet.path)
    xml = sfc_project_xml(grafcet, name=args.name, comment=comment)
    _write(args, xml)
    print_files(args, "sfc", pou, "plcopen", sources, [(f"{pou}.xml", xml.encode("utf-8") if isinstance(xml, str) else xml)],
                 [args.output])
    return 0


def cmd_import(args: argparse.Namespace) -> int:
    from synth.codegen.plcopen.importer import checked_pous, import_sfc

    from synth.syntax import read_bytes

    data = read_bytes(args.file)
    if args.list:
        pous = checked_pous(data, args.file)
        if args.json:
            from synth.output.codegen_json import import_list_json
            from synth.output.summary import print_json

            print_json(import_list_json(args.file, pous))
            return 0
        for summary in pous:
            print(summary.text())
        return 0
    notes: list[str] = []
    warnings: list = []
    from synth.output.progress import clear_progress, live_line, tty_progress

    show = tty_progress(live_line(not args.quiet))
    show(f"reading the SFC of {args.file}")
    text = import_sfc(data, args.file, pou=args.pou, notes=notes, warnings=warnings)
    clear_progress(show)
    for n in notes:
        print(f"{args.file}: note: {n}", file=sys.stderr)
    for w in warnings:
        print(w.render(), file=sys.stderr)
    g = _imported_grafcet(text, args)  # the result must be a valid .g7
    from synth.errors import LimitExceeded
    from synth.grafcet.semantics import IMPORT_BUDGET, IMPORT_REACTIONS, scan_only_steps

    show = tty_progress(live_line(not args.quiet))
    show("the steps a PLC scan keeps active (IEC 61131-3 against IEC 60848)")
    over = False
    try:
        steps = scan_only_steps(g)
    except LimitExceeded:
        steps, over = None, True
    finally:
        clear_progress(show)
    if over:
        print(f"{args.file}: note: not checked whether some steps stay active for a PLC scan where IEC 60848 passes "
              f"through them (more than {IMPORT_BUDGET} situations or {IMPORT_REACTIONS} reactions to explore): validate "
              "with --semantics sfc for "
              "the meaning the program has on the PLC", file=sys.stderr)
    if steps:
        print(f"{args.file}: note: step{'s' if len(steps) > 1 else ''} {', '.join(steps)} stay active for a PLC scan "
              "(IEC 61131-3 SFC, their actions run) where IEC 60848 passes through them in one evolution: validate "
              "with --semantics sfc for the meaning the program has on the PLC", file=sys.stderr)
    _write(args, text)
    if args.json:
        from synth.output.codegen_json import import_json
        from synth.output.summary import print_json

        print_json(import_json(args.file, args.output, text, notes, [w.render() for w in warnings], steps or ()))
    return 0


def _imported_grafcet(text: str, args: argparse.Namespace) -> "Grafcet":
    """The Grafcet ``import`` read, checked as a ``.g7``; an error in it says where it came from."""
    from synth.errors import InputError, InputErrors
    from synth.grafcet.language_check import parse_grafcet

    name = args.output or "<imported>"
    try:
        return parse_grafcet(text, name)
    except (InputError, InputErrors) as err:
        note = f"{name} is the Grafcet read from {args.file}: the chart of the XML file does not make a valid Grafcet"
        errors = err.errors if isinstance(err, InputErrors) else (err,)
        raise InputErrors([InputError(e.message, e.location, expected=e.expected, suggestions=e.suggestions,
                                      notes=(*e.notes, note)) for e in errors]) from None


def register(sub: "argparse._SubParsersAction") -> None:
    """Add ``st``, ``sfc`` and ``import`` to the ``synth`` parser."""
    p = sub.add_parser("st", help="IEC 61131-3 Structured Text of a Grafcet (and its safety filter)",
                       description="Write the Grafcet as one IEC 61131-3 PROGRAM with synth's IEC 60848 semantics "
                                   "(docs/codegen.md), or --check that it equals synth run.")
    p.add_argument("file", metavar="FILE.g7", help="the Grafcet")
    p.add_argument("--plant", metavar="RULES", help="plant .rules file: its inputs/outputs (and initial inputs)")
    p.add_argument("--filter", metavar="FILTER", help="a .filter file: its FUNCTION_BLOCK runs after the Grafcet")
    p.add_argument("--semantics", choices=("grafcet", "sfc"), default="grafcet",
                   help="grafcet: evolve to stability in every PLC cycle (IEC 60848; default); sfc: one evolution "
                        "per cycle (IEC 61131-3 SFC), as the PLC runs an imported SFC")
    p.add_argument("--name", metavar="NAME", help="the PROGRAM's name (default: the file's stem)")
    p.add_argument("-o", "--output", metavar="FILE", help="write to FILE (default: standard output)")
    p.add_argument("--xml", action="store_true", help="PLCopen TC6 XML instead of ST text (--target plcopen)")
    p.add_argument("--target", choices=("iec", "plcopen", "codesys", "twincat"),
                   help="iec: ST text (default); plcopen: TC6 XML; codesys: TC6 XML with CODESYS's project structure; "
                        "twincat: one .TcPOU per POU (several: -o DIR)")
    p.add_argument("--task", metavar="PERIOD",
                   help="also write a CONFIGURATION running the PROGRAM every PERIOD (e.g. 10ms): builds as is in "
                        "Beremiz and OpenPLC")
    p.add_argument("--io", metavar="LAYOUT",
                   help="located variables (AT %%IX0.0/%%QX0.0) by layout plain, openplc-server (sensors on coils) or "
                        "openplc-device (sensors on %%IX100.x, the runtime polls synth), or by a map file name,address "
                        "(docs/commissioning.md); with -o FILE, the address table beside it as FILE.io.json and .io.csv")
    p.add_argument("--check", action="store_true",
                   help="run the program in the ST interpreter against synth run on every event sequence")
    p.add_argument("--depth", type=int, default=3, metavar="N", help="--check: events per sequence (default 3)")
    p.add_argument("--junit", metavar="FILE", help="--check: also write the result as JUnit XML (one test case per mismatch)")
    p.add_argument("--sarif", metavar="FILE", help="--check: also write the result as SARIF 2.1.0 (one result per mismatch)")
    p.add_argument("--json", action="store_true", help="print JSON: the files generated (their text without -o), or --check's result")
    p.add_argument("--quiet", action="store_true", help="--check: no live progress line on a terminal")
    p.set_defaults(handler=cmd_st)
    p = sub.add_parser("sfc", help="a Grafcet as a PLCopen XML SFC",
                       description="Export the Grafcet as a PLCopen TC6 XML SFC program.")
    p.add_argument("file", metavar="FILE.g7", help="the Grafcet")
    p.add_argument("--plant", metavar="RULES", help="plant .rules file: its inputs and outputs")
    p.add_argument("--name", metavar="NAME", help="the POU's name (default: the file's stem)")
    p.add_argument("-o", "--output", metavar="FILE", help="write to FILE (default: standard output)")
    p.add_argument("--json", action="store_true", help="print JSON: the file generated (its text without -o)")
    p.set_defaults(handler=cmd_sfc)
    p = sub.add_parser("import", help="a PLCopen XML SFC as a .g7 Grafcet",
                       description="Read the SFC of a PLCopen TC6 XML file into the .g7 language.")
    p.add_argument("file", metavar="FILE.xml", help="PLCopen TC6 XML (2.01, 2.00 as CODESYS writes it, or 1.0)")
    p.add_argument("-o", "--output", metavar="FILE", help="write to FILE (default: standard output)")
    p.add_argument("--pou", metavar="NAME", help="import this SFC POU only (default: every SFC POU)")
    p.add_argument("--list", action="store_true", help="list the POUs, their languages and what an import reads")
    p.add_argument("--json", action="store_true", help="print JSON: the Grafcet read (its text without -o), notes and warnings")
    p.add_argument("--quiet", action="store_true", help="no live progress line on a terminal")
    p.set_defaults(handler=cmd_import)
