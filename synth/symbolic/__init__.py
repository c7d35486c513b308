"""The symbolic engine: SUP and validation on BDDs, for machines where many actuators move at once."""
