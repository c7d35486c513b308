"""The element library shipped with synth (``plants/lib`` in the source tree, the
``synth.library`` package once installed): where ``use "lib/NAME.rules"`` resolves,
and what ``synth lib`` lists.

Example
-------
>>> [(m.name, m.orders, m.sensors) for m in library_models()][0]
('conveyor', ('TAPIS',), ('small', 'large'))
"""

from __future__ import annotations

from pathlib import Path

from synth.frozen import frozen

__all__ = ["LIBRARY_PREFIX", "LibraryModel", "library_dir", "library_file", "library_models"]

LIBRARY_PREFIX = "lib/"


def library_file(path: str, base: Path | None) -> Path:
    """Where ``use "path"`` points: beside the including file first; a ``lib/NAME``
    that is not there comes from the element library installed with synth.

    >>> library_file("lib/double_acting.rules", Path("/nowhere")).name
    'double_acting.rules'
    """
    beside = (base / path) if base is not None else Path(path)
    if beside.exists() or not path.startswith(LIBRARY_PREFIX):
        return beside
    installed = library_dir() / path[len(LIBRARY_PREFIX):]
    return installed if installed.exists() else beside


def library_dir() -> Path:
    """The element library (``plants/lib`` in the source tree, ``synth.library`` installed:
    its folder, found without importing ``importlib.resources``: 1 ms of every validation)."""
    from importlib.util import find_spec

    try:
        spec = find_spec("synth.library")
    except ModuleNotFoundError:
        spec = None
    for folder in (spec.submodule_search_locations or []) if spec is not None else []:
        return Path(folder)
    return Path(__file__).resolve().parents[2] / "plants" / "lib"  # a source tree that was not installed


@frozen
class LibraryModel:
    """A model of the library: its file (as ``use`` names it), orders and sensors with
    their initial values, and the file's first comment line."""

    name: str
    use: str
    orders: tuple[str, ...]
    sensors: tuple[str, ...]
    initial: tuple[tuple[str, bool], ...]
    summary: str


def library_models() -> list[LibraryModel]:
    """Every model of the installed library, by file name then model order."""
    from synth.plant.rules import VarKind
    from synth.plant.rules_reader import Model, rules_items
    from synth.syntax import read_source

    out = []
    for f in sorted(library_dir().glob("*.rules")):
        source = read_source(f)
        comments = [line.lstrip("# ").strip() for line in source.splitlines() if line.startswith("#")]
        for item in rules_items(source, str(f)):
            if isinstance(item, Model):
                decls = item.body.decls
                out.append(LibraryModel(
                    item.name,
                    LIBRARY_PREFIX + f.name,
                    tuple(d.name for d in decls if d.kind == VarKind.ORDER),
                    tuple(d.name for d in decls if d.kind == VarKind.SENSOR),
                    tuple((d.name, d.initial) for d in decls),
                    comments[0] if comments else "",
                ))
    return out
