"""CLI commands of the grafcet stage (registered by :mod:`synth.cli`)."""

from __future__ import annotations

import argparse

__all__ = ["register"]


def register(sub: "argparse._SubParsersAction") -> None:
    """Add this stage's sub-commands to the ``synth`` parser."""
