"""The engine a user asks for (``--engine auto|explicit|symbolic``), shared by every
command that has two engines: ``validate``, ``sup`` and ``filter verify``.

It lives on the ground floor, below every package, so that what an engine returns (the
filter's :class:`~synth.filter.loop.verification.Verification` says which engine ran) can
name it without importing the chooser (:mod:`synth.engines`) that decides.

>>> EngineChoice("symbolic"), str(EngineChoice.AUTO)
(<EngineChoice.SYMBOLIC: 'symbolic'>, 'auto')
"""

from __future__ import annotations

from enum import StrEnum

__all__ = ["EngineChoice"]


class EngineChoice(StrEnum):
    """``auto``: the chooser decides (:func:`synth.engines.decide`); the two others: that engine."""

    AUTO = "auto"
    EXPLICIT = "explicit"
    SYMBOLIC = "symbolic"
