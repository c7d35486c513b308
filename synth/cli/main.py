"""Command line: ``synth plant``, ``synth sup``, ``synth ass``, ``synth run``, ``synth validate``,
``synth filter``, ``synth check``, ``synth mutate``, ``synth lib``.

Exit codes: 0 pass, 1 the model fails validation, 2 bad input (reported as
``file:line:col: message`` with a caret, never a traceback), 3 a bug in synth (an unexpected
exception: one line saying so, the traceback only with ``SYNTH_TRACEBACK=1``), 130
interrupted (Ctrl-C: what was reached is printed).
"""

from __future__ import annotations

import argparse
import sys

from synth.version import version

# Only argparse and sys at the top: ``synth --help`` and ``synth COMMAND --help`` import
# nothing else (tests/test_startup.py); each command imports its library in its handler.
TYPE_CHECKING = False  # typing.TYPE_CHECKING, without importing typing
if TYPE_CHECKING:
    from collections.abc import Callable, Sequence
    from typing import Any, NoReturn

__all__ = ["main", "entry", "build_parser", "version", "one_blas_thread", "BLAS_THREADS_ENV"]

EXIT_INPUT = 2  # bad input or a limit reached (0: a pass, 1: a model that fails)
EXIT_BUG = 3  # an unexpected exception: never 1, which a CI job would read as a finding
EXIT_INTERRUPTED = 130  # Ctrl-C, as a shell reports SIGINT
TRACEBACK_ENV = "SYNTH_TRACEBACK"  # set to 1: a crash also prints its traceback
EPILOG = ("exit codes: 0 pass, 1 the model fails (problems found), 2 bad input or a limit reached, "
          f"3 a bug in synth ({TRACEBACK_ENV}=1 shows its traceback), 130 interrupted")


def did_you_mean(word: str, valid: Sequence[str]) -> str:
    """``; did you mean 'x'?`` (or ``'x' or 'y'``: the closest by difflib, best first), empty
    when nothing is close."""
    import difflib

    close = difflib.get_close_matches(word, list(valid), n=3, cutoff=0.6)
    return f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""


class _Parser(argparse.ArgumentParser):
    commands: argparse.Action | None = None  # the subcommands' action, once added

    def error(self, message: str) -> NoReturn:  # argparse's own errors: exit 2 as for bad input
        self.print_usage(sys.stderr)
        self.exit(EXIT_INPUT, f"{self.prog}: error: {message}\n")

    def add_subparsers(self, **kwargs: Any) -> Any:
        """argparse's, kept as :attr:`commands` (the subcommand a command line names)."""
        self.commands = super().add_subparsers(**kwargs)
        return self.commands

    def long_options(self) -> list[str]:
        """Every long option of this (sub)command, as its help lists them."""
        import re

        return sorted(set(re.findall(r"(?<![\w-])--[A-Za-z][\w-]*", self.format_help())))

    def _check_value(self, action: argparse.Action, value: object) -> None:
        """A value outside the choices, named with the closest valid ones."""
        choices = action.choices
        if choices is None or value in choices:
            return
        names = [str(c) for c in choices]
        hint = did_you_mean(str(value), names)
        if action is self.commands:
            kind = "subcommand" if " " in self.prog else "command"
            raise argparse.ArgumentError(None, f"unknown {kind} '{value}'{hint} ({kind}s: {', '.join(names)})")
        raise argparse.ArgumentError(action, f"invalid choice '{value}'{hint} (choose from {', '.join(names)})")


class _Version(argparse.Action):
    """``--version``, the version read only when asked (``--help`` stays fast)."""

    def __call__(self, parser: argparse.ArgumentParser, *args: object) -> None:
        sys.stdout.write(f"synth {version()}\n")
        parser.exit(0)


# The commands each module of ``synth/cli/`` registers, in ``synth --help``'s order
# (tests/test_cli_main.py checks it against what they register).
COMMANDS = {"plant": ("plant", "sup"), "grafcet": ("ass", "run"), "validate": ("validate",), "filter": ("filter",),
            "codegen": ("st", "sfc", "import"), "commission": ("commission",), "line": ("check", "mutate"),
            "lib": ("lib",), "completion": ("completion",)}


def build_parser(command: str | None = None) -> _Parser:
    """The parser of every command, or with ``command`` (a command line's first word, when it
    names a command) of that one alone: the arguments of the others are not declared (about
    7 ms of every run), since argparse reads only the chosen command's. ``synth completion``
    describes every command: it gets them all."""
    from importlib import import_module

    p = _Parser(prog="synth", description="Validate a Grafcet against a rule-based plant model and its safety constraints.",
                epilog=EPILOG)
    p.add_argument("--version", action=_Version, nargs=0, help="print synth's version and exit")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for module, names in COMMANDS.items():
        if command is None or command == "completion" or command in names:
            import_module(f"synth.cli.{module}").register(sub)
    return p


def _deepest(parser: _Parser, args: argparse.Namespace) -> _Parser:
    """The (sub)parser of the command the arguments name: ``synth filter verify``'s for
    ``synth filter verify …``."""
    while (action := parser.commands) is not None and isinstance(action.choices, dict):
        chosen = getattr(args, action.dest, None)
        if chosen not in action.choices:
            break
        parser = action.choices[chosen]
    return parser


def _unknown(parser: _Parser, extras: Sequence[str]) -> str:
    """The message for arguments no parser took: each unknown option with the closest valid ones."""
    options = parser.long_options()
    parts, after_option = [], False
    for word in extras:
        if word.startswith("-") and len(word) > 1:
            name = word.split("=", 1)[0]
            parts.append(f"unknown option '{name}'{did_you_mean(name, options)}")
            after_option = "=" not in word
        elif not after_option:  # a word right after an unknown option is taken as its value
            parts.append(f"unexpected argument '{word}'")
        else:
            after_option = False
    return "; ".join(parts)


def parse(parser: _Parser, argv: Sequence[str] | None) -> argparse.Namespace:
    """``parser.parse_args``, with an unknown option reported by the command it was given to."""
    args, extras = parser.parse_known_args(argv)
    if extras:
        _deepest(parser, args).error(_unknown(_deepest(parser, args), extras))
    args.root_parser = parser  # what ``synth completion`` describes
    return args




def main(argv: Sequence[str] | None = None) -> int:
    try:
        return _main(argv)
    except KeyboardInterrupt:  # Ctrl-C anywhere, the parser and the imports included
        return interrupted()


def interrupted() -> int:
    """Ctrl-C: say what the run had reached, exit 130."""
    from synth.output.progress import reached

    print(f"interrupted{reached()}", file=sys.stderr)
    return EXIT_INTERRUPTED


def crashed(err: BaseException) -> int:
    """An unexpected exception: one line naming it as a bug in synth, exit 3 (never 1)."""
    import os

    if os.environ.get(TRACEBACK_ENV, "") not in ("", "0"):
        import traceback

        traceback.print_exception(err, file=sys.stderr)
    text = " ".join(str(err).split())
    text = text if len(text) <= 200 else text[:200] + "…"
    print(f"synth: internal error: {type(err).__name__}{': ' + text if text else ''}\n"
          f"this is a bug in synth: please report it with the command and its input files "
          f"({TRACEBACK_ENV}=1 prints the traceback)", file=sys.stderr)
    return EXIT_BUG


def _main(argv: Sequence[str] | None) -> int:
    words = sys.argv[1:] if argv is None else list(argv)
    known = words[0] if words and any(words[0] in names for names in COMMANDS.values()) else None
    parser = build_parser(known)
    if not words:  # ``synth`` alone: the command list
        parser.print_help(sys.stderr)
        return EXIT_INPUT
    args = parse(parser, argv)
    handler: Callable[[argparse.Namespace], int] = args.handler
    from synth.errors import InputError, InputErrors, LimitExceeded, ModelError, ModelFailure, SynthError
    from synth.output.progress import start_run, stop_progress

    start_run()
    try:
        try:
            return handler(args)
        finally:  # a live line still drawn (an error, Ctrl-C) is erased before any message
            stop_progress()
    except ModelFailure as err:  # located, but a verdict: the model fails
        print(err.render(), file=sys.stderr)
        return 1
    except (InputError, InputErrors) as err:
        print(err.render(), file=sys.stderr)
        return EXIT_INPUT
    except ModelError as err:
        print(f"error: {err}", file=sys.stderr)
        return EXIT_INPUT
    except LimitExceeded as err:
        print(f"stopped: {err}", file=sys.stderr)
        return EXIT_INPUT
    except SynthError as err:
        print(f"error: {err}", file=sys.stderr)
        return EXIT_INPUT
    except OSError as err:  # reads go through read_source, writes through write_atomic: neither
        where = f" '{str(err.filename)[:200]}'" if getattr(err, "filename", None) else ""
        print(f"error: cannot access{where}: {err.strerror or err}", file=sys.stderr)
        return EXIT_INPUT
    except MemoryError:  # a model larger than this machine: a limit reached, not a verdict
        print("stopped: out of memory; bound the exploration with --max-states (or --max-nodes)", file=sys.stderr)
        return EXIT_INPUT
    except KeyboardInterrupt:
        return interrupted()
    except Exception as err:  # noqa: BLE001 - anything else is a bug: exit 3, never 1
        return crashed(err)


BLAS_THREADS_ENV = "OPENBLAS_NUM_THREADS"


def one_blas_thread() -> None:
    """One OpenBLAS thread for numpy, unless the user chose otherwise: numpy's OpenBLAS starts a
    thread per core when numpy is imported, and they spin a while waiting for work that never
    comes — about 130 ms of CPU per process on 2 cores (``import numpy``: 0.22 CPU s, 0.09 with
    one thread), taken from the command's own work on a small machine, for BLAS calls synth does
    not make (its matrix products are on integers, which numpy computes without BLAS). Called
    before numpy is imported; worker processes inherit it."""
    import os

    os.environ.setdefault(BLAS_THREADS_ENV, "1")


def entry() -> None:
    """The ``synth`` console script: like other Unix tools, die quietly on a closed pipe
    (``synth validate … | head``) instead of claiming an exit code it did not reach; a Ctrl-C
    after the run has finished changes nothing (its output is written); one OpenBLAS thread
    (:func:`one_blas_thread`)."""
    import gc
    import signal

    one_blas_thread()
    if hasattr(signal, "SIGPIPE"):
        signal.signal(signal.SIGPIPE, signal.SIG_DFL)
    code = main()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # The interpreter's collections at exit walk every object left (numpy's and lark's
    # included): 30-50 ms of a box-sorting validation, more than its work. Frozen,
    # they are left to the end of the process; exit still flushes the output, runs the
    # atexit handlers and frees what is not in a cycle (synth's files are closed by ``with``).
    gc.freeze()
    sys.exit(code)


if __name__ == "__main__":  # pragma: no cover
    entry()
