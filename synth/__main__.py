from synth.cli.main import entry

entry()
