"""Settings -> the run limits: every setting named like a field of `Limits` reaches it (one name, one fact)."""

from __future__ import annotations

import dataclasses

from horde.runs.run_setup import Limits
from horde.server import Settings


def test_every_limit_the_settings_name_reaches_the_run_limits() -> None:
    settings = Settings(max_runs=3, max_demons=7, max_weights=1000, history=64, history_every=5,
                        history_interval=0.5, snapshot_every=9.0)  # fmt: skip
    limits = settings.limits()
    named = [f.name for f in dataclasses.fields(Limits) if f.name in Settings.model_fields]
    assert set(named) >= {"max_runs", "max_demons", "max_weights", "history", "snapshot_every"}
    for name in named:
        assert getattr(limits, name) == getattr(settings, name), name
    assert limits.events == Limits().events  # not a setting: the default
