"""The study file the study tests share: learning.alpha x the learner on classroom-offpolicy (four configurations)."""

from __future__ import annotations


def alpha_by_learner(runs: int, episodes: int, checkpoints: int, learners: tuple[str, str], name: str = "") -> str:
    """A study file's text: alpha in {0.03, 0.1} x `learners`, `runs` runs of `episodes` episodes each."""
    first, second = learners
    header = f'name = "{name}"\n' if name else ""
    return f"""{header}scenario = "classroom-offpolicy"
runs = {runs}

[measure]
episodes = {episodes}
checkpoints = {checkpoints}

[[axes]]
path = "learning.alpha"
values = [0.03, 0.1]

[[axes]]
path = "demons.*.learner"
values = ["{first}", "{second}"]
"""
