"""A study's axes: expansion into configurations, and every bad axis refused before a task starts."""

from __future__ import annotations

import pytest

from horde.runs.errors import SpecError
from horde.scenarios import find_scenario
from horde.spec import RunSpec
from horde.studies.spec import MAX_CONFIGURATIONS, MAX_TASKS, StudySpec, expand


@pytest.fixture(scope="module")
def classroom() -> RunSpec:
    return find_scenario("classroom-offpolicy")


def study(axes: list[dict[str, object]], **extra: object) -> StudySpec:
    return StudySpec.model_validate({"scenario": "classroom-offpolicy", "axes": axes, **extra})


def test_a_grid_takes_every_combination_and_sets_each_field(classroom: RunSpec) -> None:
    configs = expand(
        study(
            [{"path": "learning.alpha", "values": [0.01, 0.1]}, {"path": "demons.*.learner", "values": ["td", "gq"]}]
        ),
        classroom,
    )
    assert [c.axes for c in configs] == [
        {"learning.alpha": 0.01, "demons.*.learner": "td"},
        {"learning.alpha": 0.01, "demons.*.learner": "gq"},
        {"learning.alpha": 0.1, "demons.*.learner": "td"},
        {"learning.alpha": 0.1, "demons.*.learner": "gq"},
    ]
    last = configs[-1].spec
    assert last.learning.alpha == 0.1
    assert {d.learner for d in last.demons} == {"gq"}
    assert configs[0].spec.demons[0].learner == "td"
    # everything the axes do not name stays as in the base
    assert last.world == classroom.world and last.learning.lambda_ == classroom.learning.lambda_


def test_a_named_demon_and_an_index_select_one_element(classroom: RunSpec) -> None:
    (by_name,) = expand(study([{"path": "demons.goal_random.alpha", "values": [0.5]}]), classroom)
    (by_index,) = expand(study([{"path": "demons.0.lambda", "values": [0.3]}]), classroom)
    assert [d.alpha for d in by_name.spec.demons] == [None] * 5 + [0.5]
    assert by_index.spec.demons[0].lambda_ == 0.3 and by_index.spec.demons[1].lambda_ is None


def test_a_demon_without_own_features_starts_from_the_runs(classroom: RunSpec) -> None:
    (config,) = expand(study([{"path": "demons.goal_random.features.tiles", "values": [4]}]), classroom)
    own = config.spec.demons[-1].features
    assert own is not None and own.kind == classroom.features.kind == "grid" and own.tiles == 4


def test_measure_episodes_sets_the_training_length(classroom: RunSpec) -> None:
    (config,) = expand(study([{"path": "seed", "values": [3]}], measure={"episodes": 77}), classroom)
    assert config.spec.protocol.episodes == 77 and config.spec.seed == 3


def test_a_random_sample_is_seeded_distinct_and_of_its_size(classroom: RunSpec) -> None:
    axes = [
        {"path": "learning.alpha", "values": [0.01, 0.02, 0.03, 0.04]},
        {"path": "learning.lambda", "values": [0, 0.5, 1]},
    ]
    first = expand(study(axes, sample={"kind": "random", "size": 5, "seed": 1}), classroom)
    again = expand(study(axes, sample={"kind": "random", "size": 5, "seed": 1}), classroom)
    assert len(first) == 5 and len({repr(c.axes) for c in first}) == 5
    assert [c.axes for c in first] == [c.axes for c in again]
    other = expand(study(axes, sample={"kind": "random", "size": 5, "seed": 2}), classroom)
    assert [c.axes for c in other] != [c.axes for c in first]


def problems(exc: pytest.ExceptionInfo[SpecError]) -> list[tuple[tuple[str | int, ...], str]]:
    return [(p.loc, p.msg) for p in exc.value.problems]


def test_an_unknown_path_is_refused_naming_the_axis(classroom: RunSpec) -> None:
    with pytest.raises(SpecError) as exc:
        expand(
            study([{"path": "learning.alpha", "values": [0.1]}, {"path": "learning.alfa", "values": [0.1]}]), classroom
        )
    ((loc, msg),) = problems(exc)
    assert loc == ("axes", 1, "path")
    assert "learning.alfa" in msg and "no such field" in msg and "alpha" in msg  # the known fields are listed


def test_an_unknown_demon_is_refused_naming_the_axis(classroom: RunSpec) -> None:
    with pytest.raises(SpecError) as exc:
        expand(study([{"path": "demons.nobody.alpha", "values": [0.1]}]), classroom)
    ((loc, msg),) = problems(exc)
    assert loc == ("axes", 0, "path") and "demons.nobody.alpha" in msg and "goal_random" in msg


def test_a_value_failing_the_fields_validation_is_refused_naming_axis_and_value(classroom: RunSpec) -> None:
    with pytest.raises(SpecError) as exc:
        expand(
            study(
                [
                    {"path": "learning.lambda", "values": [0.5, 1.5]},
                    {"path": "demons.*.learner", "values": ["td", "sarsa"]},
                ]
            ),
            classroom,
        )
    found = problems(exc)
    assert [loc for loc, _ in found] == [("axes", 0, "values", 1), ("axes", 1, "values", 1)]
    assert "learning.lambda = 1.5" in found[0][1] and "less than or equal to 1" in found[0][1]
    assert "demons.*.learner = 'sarsa'" in found[1][1]


def test_a_grid_past_the_bound_is_refused_before_any_configuration_is_built(classroom: RunSpec) -> None:
    values = [0.001 * (i + 1) for i in range(40)]
    axes = [{"path": "learning.alpha", "values": values}, {"path": "learning.alpha_w", "values": values}]
    with pytest.raises(SpecError) as exc:
        expand(study(axes), classroom)
    ((loc, msg),) = problems(exc)
    assert loc == ("axes",) and "1600 configurations" in msg and str(MAX_CONFIGURATIONS) in msg
    assert "learning.alpha x learning.alpha_w" in msg


def test_too_many_tasks_are_refused(classroom: RunSpec) -> None:
    values = [0.001 * (i + 1) for i in range(25)]
    axes = [{"path": "learning.alpha", "values": values}, {"path": "learning.alpha_w", "values": values}]
    with pytest.raises(SpecError) as exc:
        expand(study(axes, runs=40), classroom)
    ((loc, msg),) = problems(exc)
    assert loc == ("runs",) and str(MAX_TASKS) in msg


def test_a_study_names_a_scenario_or_gives_a_base_not_both() -> None:
    with pytest.raises(ValueError, match="exactly one"):
        StudySpec.model_validate({"axes": [{"path": "seed", "values": [1]}]})
    with pytest.raises(ValueError, match="different path"):
        study([{"path": "seed", "values": [1]}, {"path": "seed", "values": [2]}])


def test_measuring_an_unknown_demon_is_refused_before_any_task(classroom: RunSpec) -> None:
    with pytest.raises(SpecError) as exc:
        expand(study([{"path": "seed", "values": [1]}], measure={"demons": ["goal_random", "nobody"]}), classroom)
    ((loc, msg),) = problems(exc)
    assert loc == ("measure", "demons", 1) and "nobody" in msg and "goal_random" in msg
