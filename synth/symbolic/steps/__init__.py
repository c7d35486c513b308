"""The symbolic step path: Grafcet steps as BDD variables, whole levels of the SYNC over (steps, plant state), for Grafcets without timers, stored actions or internal variables."""
