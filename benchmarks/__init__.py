"""Throughput benchmarks of Horde Lab: `horde bench` runs them (see docs/performance.md).

`run.py` runs every workload and prints the table (`--json PATH` also writes it); every workload is a
run spec run by `Simulation`: `workloads.py` the nexting, off-policy and control ones (over the world
and sensors of scenarios/nexting.toml), `thesis.py` the thesis-scale whole loop; `measure.py` the timing
and memory-bandwidth helpers. `float32_scenarios.py` runs every shipped scenario in float64 and float32 and
judges each by its own criterion; `rllib/` times Horde Lab beside RLLib on one dumped nexting stream.
"""
