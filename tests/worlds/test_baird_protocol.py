"""`horde run scenarios/baird.toml`: the diverged TD demon is reported as diverged, not compared with the returns."""

from __future__ import annotations

from horde.scenarios import load_scenario, scenario_dir
from horde.worlds.protocol import format_gym_results, run_gym_protocol


def test_horde_run_reports_the_frozen_td_demon_as_diverged() -> None:
    spec = load_scenario(scenario_dir() / "baird.toml")  # 12 episodes of 1000 steps: TD is frozen near step 10,000
    result = run_gym_protocol(spec)
    rows = {row.name: row for row in result.demons}
    assert rows["td"].diverged and rows["td"].error is None and rows["td"].as_dict()["diverged"] is True
    for name in ("gtd", "gq", "etd"):  # bounded: compared with the realised returns (all 0: every reward is 0)
        assert not rows[name].diverged and rows[name].truth == 0.0 and abs(rows[name].prediction) < 100
    table = format_gym_results(spec, result)
    assert table.splitlines()[2].split()[:2] == ["td", "diverged"]
    assert "of 3 demons" in table  # the diverged one is not counted among those judged
