"""Command line: ``synth plant``, ``synth sup``, ``synth ass``, ``synth run``, ``synth validate``,
``synth filter``, ``synth check``, ``synth mutate``, ``synth lib``.

Exit codes: 0 pass, 1 the model fails validation, 2 bad input (reported as
``file:line:col: message`` with a caret, never a traceback).
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
    from typing import NoReturn

__all__ = ["main", "entry", "build_parser", "version"]

EXIT_INPUT = 2  # bad input or a limit reached (0: a pass, 1: a model that fails)


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:  # argparse's own errors: exit 2 as for bad input
        self.print_usage(sys.stderr)
        self.exit(EXIT_INPUT, f"{self.prog}: error: {message}\n")


class _Version(argparse.Action):
    """``--version``, the version read only when asked (``--help`` stays fast)."""

    def __call__(self, parser: argparse.ArgumentParser, *args: object) -> None:
        sys.stdout.write(f"synth {version()}\n")
        parser.exit(0)


def build_parser() -> argparse.ArgumentParser:
    from synth.cli import codegen as cli_codegen, filter as cli_filter, grafcet as cli_grafcet, commission as cli_commission, lib as cli_lib, line as cli_line, plant as cli_plant, validate as cli_validate

    p = _Parser(prog="synth", description="Validate a Grafcet against a rule-based plant model and its safety constraints.")
    p.add_argument("--version", action=_Version, nargs=0, help="print synth's version and exit")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for module in (cli_plant, cli_grafcet, cli_validate, cli_filter, cli_codegen, cli_commission, cli_line, cli_lib):
        module.register(sub)
    return p




def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    if not (sys.argv[1:] if argv is None else argv):  # ``synth`` alone: the command list
        parser.print_help(sys.stderr)
        return EXIT_INPUT
    args = parser.parse_args(argv)
    handler: Callable[[argparse.Namespace], int] = args.handler
    from synth.errors import InputError, InputErrors, LimitExceeded, ModelError, ModelFailure, SynthError

    try:
        return handler(args)
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
    except OSError as err:  # an output file that cannot be written
        where = f" '{err.filename}'" if getattr(err, "filename", None) else ""
        print(f"error: cannot write{where}: {err.strerror or err}", file=sys.stderr)
        return EXIT_INPUT
    except MemoryError:  # a model larger than this machine: a limit reached, not a verdict
        print("stopped: out of memory; bound the exploration with --max-states (or --max-nodes)", file=sys.stderr)
        return EXIT_INPUT
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130


def entry() -> None:
    """The ``synth`` console script: like other Unix tools, die quietly on a closed pipe
    (``synth validate … | head``) instead of claiming an exit code it did not reach."""
    import signal

    if hasattr(signal, "SIGPIPE"):
        signal.signal(signal.SIGPIPE, signal.SIG_DFL)
    sys.exit(main())


if __name__ == "__main__":  # pragma: no cover
    entry()
