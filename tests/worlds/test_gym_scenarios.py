"""What must hold of the Gymnasium scenarios: predictions beside realised returns of the target policies.

These run the scenarios' full protocols (a minute or more each on a busy machine).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from benchmarks.float32_scenarios import representable

from horde.scenarios import load_scenario
from horde.worlds.protocol import run_gym_protocol

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


@pytest.mark.slow
def test_mountaincar_nexting_predictions_are_within_10_percent_of_the_realised_returns() -> None:
    spec = load_scenario(SCENARIOS / "mountaincar-nexting.toml")
    result = run_gym_protocol(spec)
    claimed = [d for d in result.demons if representable(d.name)]
    assert len(claimed) >= 90
    misses = [(d.name, d.prediction, d.truth) for d in claimed if not (d.relative is not None and d.relative <= 0.10)]
    assert not misses, misses


@pytest.mark.slow
def test_acrobot_offpolicy_answers_match_rollouts_of_the_target_policy() -> None:
    spec = load_scenario(SCENARIOS / "acrobot-offpolicy.toml")
    result = run_gym_protocol(spec)
    assert len(result.demons) == 24
    misses = [(d.name, d.prediction, d.truth) for d in result.demons
              if d.error is None or d.truth is None or abs(d.error) > max(0.05, 0.05 * abs(d.truth))]  # fmt: skip
    assert not misses, misses
