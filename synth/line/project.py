"""The project file of a production line, ``synth.toml``: its stations, each with its plant,
Grafcets and variants, filter, semantics, engine and expected verdict (docs/line.md).

The file is read with :mod:`tomllib` (Python's own TOML reader); its syntax errors keep
tomllib's line and column, and every mistake in what it says (an unknown key, with the
close valid names; a missing file; a wrong value) is located at the key or value that
makes it, found by :class:`Locator` in the text. Paths are relative to the file.

Example
-------
>>> import tempfile, pathlib
>>> d = pathlib.Path(tempfile.mkdtemp())
>>> _ = (d / "p.rules").write_text("x"), (d / "g.g7").write_text("x")
>>> _ = (d / "synth.toml").write_text('[[station]]\\nname = "a"\\nplant = "p.rules"\\ngrafcets = ["g.g7"]\\n')
>>> s = load_line(d / "synth.toml").stations[0]
>>> s.name, s.plant.name, [g.name for g in s.grafcets], s.expect, s.checks
('a', 'p.rules', ['g.g7'], <Expect.PASS: 'pass'>, (<Check.VALIDATE: 'validate'>, <Check.ST_CHECK: 'st-check'>))
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path
from typing import Any

from synth.errors import InputError, Location, close_names, location_in, source_lines

__all__ = ["Check", "Expect", "Variant", "Station", "Line", "load_line", "parse_line", "Locator"]


class Check(StrEnum):
    """A check a station runs (``checks = [...]``)."""

    VALIDATE = "validate"
    FILTER_CHECK = "filter-check"
    FILTER_VERIFY = "filter-verify"
    ST_CHECK = "st-check"


class Expect(StrEnum):
    """The verdict a station (or a variant) must reach: a station built to fail says ``fail``."""

    PASS = "pass"
    FAIL = "fail"


@dataclass(frozen=True)
class Variant:
    """``[[station.variant]]``: the station with another Grafcet and/or plant, its own
    expectation and, when it says so, its own home states."""

    name: str
    grafcet: Path
    plant: Path
    expect: Expect
    homes: tuple[str, ...] | None
    loc: Location


@dataclass(frozen=True)
class Station:
    """``[[station]]``: one machine of the line and what is checked on it."""

    name: str
    plant: Path
    grafcets: tuple[Path, ...]
    filter: Path | None
    checks: tuple[Check, ...]
    semantics: str
    engine: str
    homes: tuple[str, ...]
    expert: bool
    depth: int
    expect: Expect
    variants: tuple[Variant, ...]
    allow_survivors: tuple[str, ...]
    loc: Location
    max_states: int | None = None  # a validation's budget: more aggregated states is an error result


@dataclass(frozen=True)
class Line:
    """The whole project file: its path, folder, name and stations in file order."""

    path: Path
    name: str
    stations: tuple[Station, ...]

    @property
    def folder(self) -> Path:
        return self.path.parent


STATION_KEYS = ("name", "plant", "grafcets", "filter", "checks", "semantics", "engine", "homes", "expert", "depth",
                "expect", "variant", "allow_survivors", "max_states")
VARIANT_KEYS = ("name", "grafcet", "plant", "expect", "homes")
LINE_KEYS = ("name",)
TOP_KEYS = ("line", "station")
_HEADER = re.compile(r"^\s*(\[\[?)\s*([A-Za-z0-9_.\- ]+?)\s*\]\]?\s*(?:#.*)?$")
_TOML_AT = re.compile(r"\(at line (\d+), column (\d+)\)")


class Locator:
    """Where a key of a table stands in the text: each line is given the table it belongs to
    (``("station", 2)``, ``("station", 2, "variant", 0)``, ``("line",)``, ``()`` at the top),
    so a semantic mistake points at its key (or value) with a caret."""

    def __init__(self, file: str, text: str) -> None:
        self.file, self.text = file, text
        self.lines = source_lines(text)
        self.tables: list[tuple[Any, ...]] = []
        stations = variants = -1
        current: tuple[Any, ...] = ()
        for line in self.lines:
            m = _HEADER.match(line)
            if m:
                name = m.group(2).replace(" ", "")
                if m.group(1) == "[[" and name == "station":
                    stations, variants = stations + 1, -1
                    current = ("station", stations)
                elif m.group(1) == "[[" and name == "station.variant":
                    variants += 1
                    current = ("station", stations, "variant", variants)
                else:
                    current = tuple(name.split("."))
            self.tables.append(current)

    def at(self, table: tuple[Any, ...], key: str | None = None, *, value: bool = False) -> Location:
        """The key ``key`` of ``table`` (its value with ``value``); the table's header, or the
        file's first line, when the key is not written as ``key = ...``."""
        header = None
        for i, (line, t) in enumerate(zip(self.lines, self.tables), 1):
            if t != table:
                continue
            if header is None:
                header = i
            if key is None:
                break
            m = re.match(rf'^(\s*)("?){re.escape(key)}\2\s*=\s*', line)
            if m:
                if not value:
                    return location_in(self.file, self.text, i, len(m.group(1)) + 1, len(key) + 2 * len(m.group(2)))
                rest = line[m.end():].split(" #")[0].rstrip()
                return location_in(self.file, self.text, i, m.end() + 1, max(1, len(rest)))
        if header is not None:
            line = self.lines[header - 1]
            return location_in(self.file, self.text, header, len(line) - len(line.lstrip()) + 1, max(1, len(line.strip())))
        return location_in(self.file, self.text, 1, 1)


def load_line(path: str | Path) -> Line:
    """Read and check ``synth.toml``."""
    from synth.syntax import read_source

    return parse_line(read_source(path), Path(path))


def parse_line(text: str, path: Path) -> Line:
    """Check the project file's text; ``path`` locates it and the files it names."""
    import tomllib

    file = str(path)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        message = str(err)
        m = _TOML_AT.search(message)
        lines = source_lines(text)
        line, col = (int(m.group(1)), int(m.group(2))) if m else (len(lines), max(1, len(lines[-1]) + 1))
        raise InputError(_TOML_AT.sub("", message).strip(), location_in(file, text, line, col)) from None
    loc = Locator(file, text)
    reader = _Reader(path.parent, loc)
    reader.keys(data, TOP_KEYS, ())
    head = data.get("line", {})
    if not isinstance(head, dict):
        raise InputError("line must be a table: [line]", loc.at((), "line"))
    reader.keys(head, LINE_KEYS, ("line",))
    stations_data = data.get("station", [])
    if not isinstance(stations_data, list) or not stations_data:
        raise InputError("the line has no station: add [[station]] tables", loc.at((), "station") if "station" in data
                         else location_in(file, text, 1, 1), notes=("docs/line.md describes a station",))
    stations = []
    seen: dict[str, Location] = {}
    for i, s in enumerate(stations_data):
        station = reader.station(s, i)
        if station.name in seen:
            raise InputError(f"station {station.name!r} is declared twice", loc.at(("station", i), "name", value=True),
                             notes=(f"first declared at {seen[station.name]}",))
        seen[station.name] = station.loc
        stations.append(station)
    name = reader.string(head, "name", ("line",), default=path.parent.name or "line")
    return Line(path, name, tuple(stations))


class _Reader:
    """The checks of one file's tables, each mistake located by ``loc``."""

    def __init__(self, folder: Path, loc: Locator) -> None:
        self.folder, self.loc = folder, loc

    def keys(self, data: dict[str, Any], valid: tuple[str, ...], table: tuple[Any, ...]) -> None:
        for key in data:
            if key not in valid:
                where = ".".join(str(t) for t in table if isinstance(t, str)) or "the file"
                raise InputError(f"unknown key {key!r} in {where}", self.loc.at(table, key),
                                 suggestions=close_names(key, valid), expected=valid)

    def string(self, data: dict[str, Any], key: str, table: tuple[Any, ...], *, default: str | None = None,
               choices: tuple[str, ...] = ()) -> str:
        value = data.get(key, default)
        if value is None:
            raise InputError(f"missing key {key!r}", self.loc.at(table), notes=(f"add {key} = \"...\"",))
        if not isinstance(value, str) or not value:
            raise InputError(f"{key} must be a non-empty string", self.loc.at(table, key, value=True))
        if choices and value not in choices:
            raise InputError(f"{key} = {value!r} is not one of {', '.join(choices)}", self.loc.at(table, key, value=True),
                             suggestions=close_names(value, choices))
        return value

    def strings(self, data: dict[str, Any], key: str, table: tuple[Any, ...], default: tuple[str, ...] = ()) -> tuple[str, ...]:
        value = data.get(key, list(default))
        if not isinstance(value, list) or not all(isinstance(v, str) and v for v in value):
            raise InputError(f"{key} must be a list of strings: {key} = [\"...\"]", self.loc.at(table, key, value=True))
        return tuple(value)

    def file(self, text: str, key: str, table: tuple[Any, ...]) -> Path:
        path = Path(os.path.normpath(self.folder / text))
        if not path.is_file():
            raise InputError(f"{key}: no file {text!r} (paths are relative to {self.loc.file})",
                             self.loc.at(table, key, value=True))
        return path

    def station(self, s: Any, i: int) -> Station:
        table = ("station", i)
        if not isinstance(s, dict):
            raise InputError("a station must be a table: [[station]]", self.loc.at((), "station"))
        self.keys(s, STATION_KEYS, table)
        name = self.string(s, "name", table)
        plant = self.file(self.string(s, "plant", table), "plant", table)
        grafcet_names = self.strings(s, "grafcets", table)
        grafcets = tuple(self.file(g, "grafcets", table) for g in grafcet_names)
        filter_ = self.file(self.string(s, "filter", table), "filter", table) if "filter" in s else None
        default_checks = [Check.VALIDATE] + ([Check.FILTER_CHECK] if filter_ else []) + [Check.ST_CHECK]
        checks = self.strings(s, "checks", table, tuple(default_checks))
        for c in checks:
            if c not in tuple(Check):
                raise InputError(f"unknown check {c!r}", self.loc.at(table, "checks", value=True),
                                 suggestions=close_names(c, tuple(Check)), expected=tuple(Check))
        if filter_ is None and any(c in (Check.FILTER_CHECK, Check.FILTER_VERIFY) for c in checks):
            raise InputError("a filter check needs filter = \"F.filter\"", self.loc.at(table, "checks", value=True))
        depth = s.get("depth", 2)
        if not isinstance(depth, int) or isinstance(depth, bool) or not 1 <= depth <= 6:
            raise InputError("depth must be an integer from 1 to 6", self.loc.at(table, "depth", value=True))
        max_states = s.get("max_states")
        if max_states is not None and (not isinstance(max_states, int) or isinstance(max_states, bool) or max_states < 1):
            raise InputError("max_states must be a positive integer", self.loc.at(table, "max_states", value=True))
        expert = s.get("expert", False)
        if not isinstance(expert, bool):
            raise InputError("expert must be true or false", self.loc.at(table, "expert", value=True))
        expect = Expect(self.string(s, "expect", table, default="pass", choices=tuple(Expect)))
        variants_data = s.get("variant", [])
        if not isinstance(variants_data, list):
            raise InputError("variants are [[station.variant]] tables", self.loc.at(table, "variant"))
        variants = []
        for j, v in enumerate(variants_data):
            vt = ("station", i, "variant", j)
            self.keys(v, VARIANT_KEYS, vt)
            if not {"grafcet", "plant", "homes"} & set(v):
                raise InputError("a variant changes the grafcet, the plant or the homes", self.loc.at(vt))
            if not grafcets and "grafcet" not in v:
                raise InputError("a variant of a station without grafcets needs its grafcet", self.loc.at(vt))
            variants.append(Variant(
                self.string(v, "name", vt),
                self.file(v["grafcet"], "grafcet", vt) if "grafcet" in v else grafcets[0],
                self.file(v["plant"], "plant", vt) if "plant" in v else plant,
                Expect(self.string(v, "expect", vt, default=str(expect), choices=tuple(Expect))),
                self.strings(v, "homes", vt) if "homes" in v else None, self.loc.at(vt)))
        if not grafcets and Check.VALIDATE in checks and not variants:
            raise InputError("a station needs grafcets = [\"G.g7\", ...] to validate", self.loc.at(table, "grafcets"))
        return Station(name, plant, grafcets, filter_, tuple(Check(c) for c in checks),
                       self.string(s, "semantics", table, default="grafcet", choices=("grafcet", "sfc")),
                       self.string(s, "engine", table, default="auto", choices=("auto", "explicit", "symbolic")),
                       self.strings(s, "homes", table), expert, depth, expect, tuple(variants),
                       self.strings(s, "allow_survivors", table), self.loc.at(table), max_states)
