"""The ``synth`` command line: one thin module per command group."""
