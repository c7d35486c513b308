"""The closed loop of ``synth filter verify`` on BDDs: one PLC cycle as relations, the rings of the breadth-first search, the verdict and the traces."""
