"""Ports for a Ray node's components: distinct, and outside Ray's worker range."""

from __future__ import annotations

import pytest

from horde.studies.local_ray import RAY_WORKER_PORTS, free_ports


@pytest.mark.timeout(30)
def test_ports_chosen_together_are_distinct_and_outside_the_worker_range() -> None:
    # Ray's head refused to start when two of its components were handed one port (seen in make test: the GCS
    # and the runtime-env agent on 54519); many ports at once make a repeat likely if sockets were let go early.
    for _ in range(50):
        ports = free_ports(64)
        assert len(set(ports)) == 64, ports
        assert not [p for p in ports if p in RAY_WORKER_PORTS]
