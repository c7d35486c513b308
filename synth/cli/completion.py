"""CLI command ``synth completion {bash,zsh,tcsh}``: a shell completion script generated from
the argument parser itself (shtab), so it names every command and option there is.

    $ eval "$(synth completion bash)"       # or save it in ~/.local/share/bash-completion/completions/synth
"""

from __future__ import annotations

import argparse
import sys

__all__ = ["register", "cmd_completion"]


def register(sub: "argparse._SubParsersAction") -> None:
    p = sub.add_parser("completion", help="print a shell completion script (bash, zsh, tcsh)",
                       description="Print the completion script of SHELL for synth, generated from its argument "
                                   "parser: eval \"$(synth completion bash)\", or save it where your shell reads "
                                   "completions (bash: ~/.local/share/bash-completion/completions/synth).")
    p.add_argument("shell", choices=("bash", "zsh", "tcsh"), help="the shell")
    p.set_defaults(handler=cmd_completion)


def cmd_completion(args: argparse.Namespace) -> int:
    import shtab

    sys.stdout.write(shtab.complete(args.root_parser, shell=args.shell))
    return 0
