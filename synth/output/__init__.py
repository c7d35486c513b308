"""Everything that leaves synth: summaries, DOT text, the HTML report, libFAUDES files, atomic files."""
