"""The element library shipped with synth: models for ``use "lib/NAME.rules"`` (``synth lib`` lists them)."""
