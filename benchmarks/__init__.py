"""Throughput benchmarks of Horde Lab: `horde bench` runs them (see docs/performance.md).

`run.py` runs every workload and prints the table (`--json PATH` also writes it); `sensors.py` is the
robot-like sensor stream and its tile coder; `scale_workloads.py` the nexting, off-policy and control
workloads; `thesis.py` the thesis-scale whole loop; `measure.py` the timing and memory-bandwidth helpers.
"""
