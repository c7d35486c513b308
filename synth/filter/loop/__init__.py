"""``synth filter verify``: the filter in closed loop with the plant, explored explicitly on arrays (this folder) or on BDDs (:mod:`synth.filter.loop.symbolic`), with one verdict and one report."""
