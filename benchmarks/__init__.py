"""Throughput benchmarks of Horde Lab: `horde bench` runs them (see docs/performance.md).

`run.py` runs every workload and prints the table (`--json PATH` also writes it); every workload is a
run spec run by `Simulation`: `workloads.py` the nexting, off-policy and control ones (over the world
and sensors of scenarios/nexting.toml), `thesis.py` the thesis-scale whole loop; `measure.py` the timing
and memory-bandwidth helpers.
"""
