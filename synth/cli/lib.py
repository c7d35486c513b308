"""CLI command ``synth lib [--json]``: the element library's models, their orders and
sensors (with initial values), and how to use them."""

from __future__ import annotations

import argparse
import sys

__all__ = ["register", "cmd_lib"]


def register(sub: "argparse._SubParsersAction") -> None:
    p = sub.add_parser("lib", help="list the element library's models (use \"lib/NAME.rules\")",
                       description="List the models of the element library shipped with synth.")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(handler=cmd_lib)


def cmd_lib(args: argparse.Namespace) -> int:
    from synth.output.summary import library_json, library_text
    from synth.plant.library import library_dir, library_models

    models = library_models()
    if args.json:
        import json

        sys.stdout.write(json.dumps(library_json(models), indent=2, ensure_ascii=False) + "\n")
    else:
        sys.stdout.write(library_text(models, library_dir()))
    return 0
