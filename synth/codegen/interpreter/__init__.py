"""synth's IEC 61131-3 ST interpreter: runs generated (or the user's) ST on blark's parse tree, one scan at a time; :mod:`synth.codegen.interpreter.machine` is its entry point."""
