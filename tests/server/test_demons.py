"""A run's demons: list, add to a live run, remove, values, history, evaluate; with their errors."""

from __future__ import annotations

from collections.abc import Callable

import pytest
from fastapi.testclient import TestClient

from horde.runs import readout
from horde.runs.errors import SpecError
from horde.runs.readout import evaluation_support
from horde.runs.run_setup import new_simulation
from horde.runs.weights import Readable
from horde.server import Settings, create_app
from horde.spec import RunSpec
from polling import wait_until
from stream_specs import nexting, robot

from .helpers import locs, make_spec, messages, wait_for

BUMP = {"name": "bump", "policy": "uniform", "cumulant": {"sensor": "bump"}, "learner": "gtd"}


def test_list_and_get(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run()
    demons = client.get(f"/api/runs/{run_id}/demons").json()
    assert [d["name"] for d in demons] == ["base", "steps"]
    assert [d["control"] for d in demons] == [True, False]
    one = client.get(f"/api/runs/{run_id}/demons/steps").json()
    assert one["spec"]["policy"]["kind"] == "of" and one["metrics"]["diverged"] is False
    assert client.get(f"/api/runs/{run_id}/demons/ghost").status_code == 404
    assert client.get("/api/runs/nope/demons").status_code == 404


def test_a_demon_joins_without_disturbing_the_others(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run()
    client.post(f"/api/runs/{run_id}/step", json={"steps": 500})
    before = {
        n: client.get(f"/api/runs/{run_id}/demons/{n}/values?resolution=6").json()["values"] for n in ("base", "steps")
    }
    response = client.post(f"/api/runs/{run_id}/demons", json=BUMP)
    assert response.status_code == 201 and response.json()["name"] == "bump"
    after = {
        n: client.get(f"/api/runs/{run_id}/demons/{n}/values?resolution=6").json()["values"] for n in ("base", "steps")
    }
    assert after == before  # weights carried over exactly
    assert client.get(f"/api/runs/{run_id}").json()["demons"] == ["base", "steps", "bump"]
    state = client.post(f"/api/runs/{run_id}/step", json={"steps": 200}).json()
    assert state["step"] == 700 and "bump" in state["predictions"]


def test_a_demon_joins_a_running_run(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run(make_spec(), start="true")
    wait_until(lambda: client.get(f"/api/runs/{run_id}").json()["step"] > 0, "the running run's first steps")
    assert client.post(f"/api/runs/{run_id}/demons", json=BUMP).status_code == 201
    joined = client.get(f"/api/runs/{run_id}").json()["step"]
    state = wait_until(
        lambda: (b := client.get(f"/api/runs/{run_id}/state").json())["step"] > joined and b, "steps after the join"
    )
    assert state["status"] == "running" and "bump" in state["predictions"]
    assert client.delete(f"/api/runs/{run_id}/demons/bump").status_code == 204
    assert "bump" not in client.get(f"/api/runs/{run_id}/state").json()["predictions"]
    client.post(f"/api/runs/{run_id}/pause")


def test_add_errors(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run()
    duplicate = client.post(f"/api/runs/{run_id}/demons", json={**BUMP, "name": "steps"})
    assert duplicate.status_code == 409 and "already" in duplicate.json()["detail"]
    assert ["body", "lambda"] in locs(client.post(f"/api/runs/{run_id}/demons", json={**BUMP, "lambda": 2}))
    ghost = {**BUMP, "cumulant": {"prediction": "ghost"}}
    assert "unknown demon 'ghost'" in messages(client.post(f"/api/runs/{run_id}/demons", json=ghost))
    sensor = {**BUMP, "cumulant": {"sensor": "in:nowhere"}}
    assert "unknown sensor 'in:nowhere'" in messages(client.post(f"/api/runs/{run_id}/demons", json=sensor))
    assert client.post("/api/runs/nope/demons", json=BUMP).status_code == 404
    assert [d["name"] for d in client.get(f"/api/runs/{run_id}/demons").json()] == ["base", "steps"]


def test_finished_runs_take_no_new_demons(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run(make_spec(episodes=1), start="true")
    wait_for(client, run_id, "finished")
    assert client.post(f"/api/runs/{run_id}/demons", json=BUMP).status_code == 409
    assert client.delete(f"/api/runs/{run_id}/demons/steps").status_code == 409


def test_remove_errors(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run()
    followed = client.delete(f"/api/runs/{run_id}/demons/base")
    assert followed.status_code == 409
    detail = followed.json()["detail"]
    assert "cannot remove demon 'base'" in detail and "'steps' read its prediction or policy" in detail
    assert client.delete(f"/api/runs/{run_id}/demons/ghost").status_code == 404
    assert client.delete("/api/runs/nope/demons/base").status_code == 404
    assert client.delete(f"/api/runs/{run_id}/demons/steps").status_code == 204


def test_values(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run()
    client.post(f"/api/runs/{run_id}/step", json={"steps": 300})
    body = client.get(f"/api/runs/{run_id}/demons/steps/values", params={"resolution": 5}).json()
    assert body["resolution"] == 5 and body["x"] == [50, 150, 250, 350, 450] and body["y"] == body["x"]
    assert len(body["values"]) == 5 and all(len(row) == 5 for row in body["values"])
    assert body["min"] <= body["values"][0][0] <= body["max"]
    prediction = client.get(f"/api/runs/{run_id}/state").json()
    assert prediction["step"] == 300


def test_values_errors(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run()
    assert ["query", "resolution"] in locs(client.get(f"/api/runs/{run_id}/demons/steps/values?resolution=1"))
    assert ["query", "resolution"] in locs(client.get(f"/api/runs/{run_id}/demons/steps/values?resolution=100000"))
    assert client.get(f"/api/runs/{run_id}/demons/ghost/values").status_code == 404
    assert client.get("/api/runs/nope/demons/steps/values").status_code == 404


def test_history(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run(make_spec(), start="true", hz=100)
    wait_until(lambda: client.get(f"/api/runs/{run_id}").json()["step"] >= 20, "20 paced steps")
    steps = client.post(f"/api/runs/{run_id}/pause").json()["step"]
    body = client.get(f"/api/runs/{run_id}/demons/steps/history").json()
    assert body["every"] == 1 and body["capacity"] == 2000
    assert len(body["step"]) >= steps // 2 and body["step"][-1] == steps  # paced: about a row a step
    assert body["step"] == sorted(set(body["step"]))
    assert len(body["prediction"]) == len(body["rupee"]) == len(body["ude"]) == len(body["step"])
    assert set(body["cumulant"]) == {1.0}
    last = client.get(f"/api/runs/{run_id}/demons/steps/history", params={"limit": 2}).json()
    assert last["step"] == body["step"][-2:]
    assert client.get(f"/api/runs/{run_id}/demons/ghost/history").status_code == 404
    assert ["query", "limit"] in locs(client.get(f"/api/runs/{run_id}/demons/steps/history?limit=0"))


def test_history_is_a_bounded_ring(settings: Settings) -> None:
    settings = settings.model_copy(update={"history": 50, "history_interval": 0.0})
    with TestClient(create_app(settings)) as client:
        run_id = client.post("/api/runs", json=make_spec()).json()["id"]
        for _ in range(5):
            client.post(f"/api/runs/{run_id}/step", json={"steps": 2000})
        body = client.get(f"/api/runs/{run_id}/demons/base/history").json()
        assert len(body["step"]) == 50 and body["step"][-1] == 10_000
        assert body["step"] == sorted(body["step"])


def test_evaluate(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run()
    client.post(f"/api/runs/{run_id}/step", json={"steps": 2000})
    request = {"demon": "steps", "from": [0, 0], "episodes": 50, "cap": 2000, "seed": 1}
    body = client.post(f"/api/runs/{run_id}/evaluate", json=request).json()
    assert body["episodes"] == 50 and body["cap"] == 2000 and body["from"] == [0, 0]
    assert body["step"] == 2000  # the step whose weights were evaluated: the dashboard marks it there
    assert body["truth"] > 0 and body["stderr"] > 0
    assert abs(body["error"] - (body["prediction"] - body["truth"])) < 1e-9
    assert client.post(f"/api/runs/{run_id}/evaluate", json=request).json() == body  # seeded: repeatable
    assert client.get(f"/api/runs/{run_id}/state").json()["step"] == 2000  # the run did not move


def test_evaluate_errors(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run()
    url = f"/api/runs/{run_id}/evaluate"
    assert client.post(url, json={"demon": "ghost", "from": [0, 0]}).status_code == 404
    assert client.post("/api/runs/nope/evaluate", json={"demon": "steps", "from": [0, 0]}).status_code == 404
    assert ["body", "from"] in locs(client.post(url, json={"demon": "steps", "from": [900, 0]}))
    assert "obstacle 'wall'" in messages(client.post(url, json={"demon": "steps", "from": [150, 250]}))
    assert ["body", "episodes"] in locs(client.post(url, json={"demon": "steps", "from": [0, 0], "episodes": 10**6}))
    assert ["body", "from"] in locs(client.post(url, json={"demon": "steps", "from": [0]}))


def test_a_grid_run_is_evaluated_from_a_point_by_default_its_start(
    client: TestClient, create_run: Callable[..., str]
) -> None:
    run_id = create_run(make_spec(world={**make_spec()["world"], "start": [100, 0, 300, 200]}))
    assert client.get(f"/api/runs/{run_id}").json()["evaluation"]["kind"] == "grid"
    client.post(f"/api/runs/{run_id}/step", json={"steps": 300})
    body = client.post(f"/api/runs/{run_id}/evaluate", json={"demon": "steps", "episodes": 5, "seed": 1}).json()
    assert body["from"] == [200, 100]  # the centre of the start rectangle, as the dashboard evaluates from
    given = {"demon": "steps", "from": [200, 100], "episodes": 5, "seed": 1}
    assert client.post(f"/api/runs/{run_id}/evaluate", json=given).json() == body


def test_a_stream_world_offers_no_evaluation_and_says_why() -> None:
    stream = RunSpec.model_validate(robot({"kind": "constant"}, nexting("light", 0.5)))
    support = evaluation_support(stream)
    assert support.kind == "none" and "stream" in support.note
    sim = new_simulation(RunSpec.model_validate(make_spec()))
    weights = Readable("r", stream, sim.horde, sim.horde_state, sim.world_state, 0)  # a grid run's, a stream's spec
    with pytest.raises(SpecError, match="no Monte-Carlo evaluation here: a stream") as refused:
        readout.evaluate(weights, "steps", None, 3, 10)
    assert refused.value.problems[0].loc == ("path", "run_id")


FAMILY = {
    "name": "{s}_g{gamma}",
    "over": {"s": ["bump", "in:goal"], "gamma": [0.5, 0.9]},
    "demon": {"learner": "td", "policy": "uniform", "cumulant": {"sensor": "{s}"}, "discount": "{gamma}"},
}


def test_a_family_is_listed_expanded(client: TestClient, create_run: Callable[..., str]) -> None:
    run_id = create_run(make_spec(families=[FAMILY]))
    demons = client.get(f"/api/runs/{run_id}/demons").json()
    assert [d["name"] for d in demons] == ["base", "steps", "bump_g0.5", "bump_g0.9", "in_goal_g0.5", "in_goal_g0.9"]
    assert demons[3]["spec"]["discount"] == 0.9 and demons[3]["spec"]["cumulant"] == {"sensor": "bump"}
    client.post(f"/api/runs/{run_id}/step", json={"steps": 50})
    assert client.get(f"/api/runs/{run_id}/demons/in_goal_g0.9").json()["metrics"]["diverged"] is False


def test_a_family_past_the_limit_is_refused_before_anything_is_built(client: TestClient) -> None:
    huge = {**FAMILY, "over": {"s": ["bump"] * 200, "gamma": [0.5] * 100}}  # 20,000 demons
    response = client.post("/api/runs", json=make_spec(families=[huge]))
    assert response.status_code == 422
    assert ["body", "RunSpec", "families", 0, "over"] in locs(response)
    # a range left out is the world's (x: [0, 500]); one that leaves nothing of it is refused, naming the end
    tiled = {"kind": "sensors", "tilings": 2, "tiles": 2, "size": 8, "sensors": [{"sensor": "x", "low": 600}]}
    response = client.post("/api/runs", json=make_spec(features=tiled))
    assert response.status_code == 422 and ["body", "RunSpec", "features", "sensors", 0, "high"] in locs(response)
    assert "its range [600, 500] is empty" in messages(response)


def test_each_demon_has_its_colour_and_the_live_view_charts_it_in_that_colour(
    client: TestClient, create_run: Callable[..., str]
) -> None:
    from horde.view.gui import _series

    run_id = create_run()
    client.post(f"/api/runs/{run_id}/demons", json=BUMP)
    demons = client.get(f"/api/runs/{run_id}/demons").json()
    colours = {d["name"]: d["colour"] for d in demons}
    assert len(set(colours.values())) == 3, "three demons, three colours"
    # The view charts a subset of the demons, in another order: each keeps its colour.
    series = _series(["bump", "steps"], [d["name"] for d in demons])
    strokes = [(s["label"], s.get("stroke")) for s in series[1:]]
    assert strokes == [("bump", colours["bump"]), ("steps", colours["steps"])]


def test_evaluate_gives_the_exact_answer_on_a_lattice_world(client: TestClient) -> None:
    # A corridor of three cells; always right: two steps to the end from (0, 0), one from (100, 0).
    world = {
        "width": 300,
        "height": 100,
        "step": 100,
        "start": [0, 0],
        "max_steps": 50,
        "regions": [{"name": "end", "kind": "terminal", "rect": [200, 0, 300, 100], "reward": 0}],
    }
    right = {"name": "right", "policy": {"kind": "fixed", "probabilities": [0, 0, 0, 1]}, "cumulant": 1}
    spec = {"name": "corridor", "seed": 1, "world": world, "behaviour": "uniform", "demons": [right]}
    run_id = client.post("/api/runs", json=spec).json()["id"]
    for start, steps in (([0, 0], 2.0), ([100, 0], 1.0)):
        body = client.post(f"/api/runs/{run_id}/evaluate", json={"demon": "right", "from": start, "episodes": 5}).json()
        assert body["exact"] == pytest.approx(steps) and body["truth"] == pytest.approx(steps)
    # A noisy world has no lattice: Monte-Carlo only.
    noisy = {**spec, "world": {**world, "noise": 5.0}}
    run_id = client.post("/api/runs", json=noisy).json()["id"]
    body = client.post(f"/api/runs/{run_id}/evaluate", json={"demon": "right", "from": [0, 0], "episodes": 5}).json()
    assert body["exact"] is None and body["truth"] > 0
