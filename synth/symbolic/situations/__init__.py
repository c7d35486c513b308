"""The symbolic per-situation path: the aggregated SYNC as one BDD of plant states per explicit Grafcet situation, for Grafcets with timers, stored actions or internal variables."""
