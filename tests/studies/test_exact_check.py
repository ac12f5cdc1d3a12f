"""What must hold 1 of the learners issue: predictions at the start against exact answers after the protocol
(`horde.studies.exact_check`; the measured table is docs/autostep-exact.md)."""

from __future__ import annotations

import numpy as np
import pytest

from horde.scenarios import find_scenario
from horde.studies.exact_check import DemonCheck, check, lattice_scenarios, table, with_step_size


def test_the_lattice_scenarios_are_the_grid_ones_without_indicators() -> None:
    names = [name for name, _ in lattice_scenarios()]
    assert names == [
        "classroom-offpolicy",
        "experiment1",
        "experiment2-large",
        "experiment2-none",
        "experiment2-small",
        "experiment2-start",
        "experiment2-whole",
    ]  # experiment3 has an indicator (hidden state), the others are Gymnasium worlds or noisy


def test_with_step_size_changes_that_field_and_nothing_else() -> None:
    spec = find_scenario("experiment1")
    changed = with_step_size(spec, "autostep")
    assert changed.learning.step_size == "autostep"
    body, other = spec.model_dump(), changed.model_dump()
    body["learning"].pop("step_size"), other["learning"].pop("step_size")
    assert body == other


def test_the_bounds_by_hand() -> None:
    probability = DemonCheck("s", "p", "td", "autostep", True, np.array([0.5, 0.2]), np.array([0.54, 0.26]))
    np.testing.assert_allclose(probability.errors, [0.04, 0.06])
    assert not probability.holds  # the second trial is 0.06 off, above 0.05
    steps = DemonCheck("s", "n", "td", "autostep", False, np.array([40.0, -20.0]), np.array([41.9, -20.9]))
    np.testing.assert_allclose(steps.errors, [0.0475, 0.045])
    assert steps.holds
    assert "| s | n | td | autostep | 10 | 10.5 | 4.62 % | 4.75 % | 5 % | yes |" in table([steps])


@pytest.mark.slow
def test_autostep_td_demons_meet_the_bound_on_the_classroom_scenario() -> None:
    """One trial of the classroom scenario's protocol (40,000 episodes) with [learning] step_size = "autostep"
    and nothing else changed: every demon (all TD(lambda), so all adaptive) within 5 % (0.05) of the exact
    answer under its target policy."""
    rows = check("classroom-offpolicy", with_step_size(find_scenario("classroom-offpolicy"), "autostep"), trials=1)
    assert {r.step_size for r in rows} == {"autostep"}
    assert [r.probability for r in rows] == [False, True] * 3
    assert all(r.holds for r in rows), table(rows)
