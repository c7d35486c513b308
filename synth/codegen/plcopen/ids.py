"""The ``localId`` of the elements of an SFC body (``synth import``): TC6 makes it a number,
and every IDE writes numbers; some hand-written files use names (``localId="s1"``) or leave
it out on elements nothing connects to. :func:`number_ids` renumbers such a body in memory
(names unique, each a fresh number; a missing id a fresh number too) so that the reader
sees numbers; a name used twice is an :class:`~synth.errors.InputError` at its element.

Example
-------
>>> from lxml import etree
>>> sfc = etree.fromstring('<SFC><step localId="a"/><step localId="b"><connection refLocalId="a"/></step></SFC>')
>>> number_ids(sfc, lambda t: t, lambda el: None)
>>> etree.tostring(sfc).decode()
'<SFC><step localId="1"/><step localId="2"><connection refLocalId="1"/></step></SFC>'
"""

from __future__ import annotations

import re
from typing import Any, Callable

from synth.errors import InputError, Location

__all__ = ["number_ids"]


def number_ids(sfc: Any, q: Callable[[str], str], at: Callable[[Any], Location | None]) -> None:
    """Renumber the non-numeric or missing ``localId`` of the children of ``sfc`` (in place)."""
    children = [el for el in sfc if isinstance(el.tag, str) and not re.search(r"(addData|documentation)$", el.tag)]
    ids = [el.get("localId") for el in children]
    if all(i is not None and re.fullmatch(r"[0-9]+", i) for i in ids):
        return
    taken = {int(i) for i in ids if i is not None and re.fullmatch(r"[0-9]+", i)}
    fresh = iter(n for n in range(1, len(children) + len(taken) + 2) if n not in taken)
    mapping: dict[str, str] = {}
    for el, old in zip(children, ids):
        if old is not None and re.fullmatch(r"[0-9]+", old):
            continue
        if old is not None and old in mapping:
            raise InputError(f"<{el.tag.rsplit('}', 1)[-1]}> with localId '{old}', which another element has",
                             at(el))
        new = str(next(fresh))
        el.set("localId", new)
        if old is not None:
            mapping[old] = new
    for c in sfc.iter(q("connection")):
        ref = c.get("refLocalId")
        if ref in mapping:
            c.set("refLocalId", mapping[ref])
