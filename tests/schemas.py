"""Validate the JSON of a ``--json`` output against its schema shipped in ``synth/output/schemas/``."""

from __future__ import annotations

import json
from functools import lru_cache
from importlib import resources
from typing import Any

import jsonschema

__all__ = ["assert_valid", "schema"]


@lru_cache(maxsize=None)
def schema(name: str) -> dict[str, Any]:
    """The shipped schema ``synth/output/schemas/<name>.json`` (checked as a schema itself)."""
    text = resources.files("synth.output").joinpath("schemas", f"{name}.json").read_text(encoding="utf-8")
    data = json.loads(text)
    jsonschema.Draft202012Validator.check_schema(data)
    return data


def assert_valid(name: str, data: Any) -> None:
    """Raise ``jsonschema.ValidationError`` (with the path) when ``data`` does not match."""
    jsonschema.Draft202012Validator(schema(name)).validate(data)
