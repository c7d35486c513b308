"""Code generation: IEC 61131-3 Structured Text and PLCopen TC6 XML from a Grafcet (and its filter), and the ST interpreter that proves them equal to synth's semantics."""
