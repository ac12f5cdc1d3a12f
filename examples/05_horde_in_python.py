"""05 · A Horde in Python, without the server: build, check, run, compare with the exact answers.

Everything comes from `horde`'s public API (backend/horde/__init__.py), nothing from its internals:

1. a 4 x 4 lattice world (cells of 100, a goal and a pit) and two demons, written as a `RunSpec`;
2. `check_world` runs the environment contract on both engines (seeded starts, sensors in range, ...);
3. a `Simulation` acts with the uniform behaviour while both demons learn off-policy about a target
   policy that prefers up and right: "steps" (how many steps until the episode ends?) and "to_goal"
   (will it end in the goal?);
4. `exact` solves each question's Bellman equation on the lattice (the truth the demons should reach),
   and the script prints every cell's prediction beside it.

Run it:  python examples/05_horde_in_python.py [--steps 20000] [--seed 3]
"""

from __future__ import annotations

import argparse

import numpy as np

from horde import GridSimulation, RunSpec, Simulation, check_world, exact

TARGET = [0.4, 0.1, 0.1, 0.4]  # the target policy's probabilities of up, down, left, right

# 1. The spec: the same dictionary a scenario file or POST /api/runs holds.
SPEC = {
    "world": {
        "width": 400,
        "height": 400,
        "step": 100,
        "start": [0, 0],
        "max_steps": 50,
        "regions": [
            {"name": "goal", "kind": "terminal", "rect": [300, 300, 400, 400], "reward": 1},
            {"name": "pit", "kind": "terminal", "rect": [300, 0, 400, 100], "reward": -1},
        ],
    },
    # One feature per cell (tabular): the learned answer can equal the exact one.
    "features": {"kind": "grid", "tiles": 4},
    "behaviour": "uniform",
    # GQ(0) with a constant step size and no gradient correction: fast on a deterministic world.
    "learning": {"lambda": 0.0, "alpha": 0.5, "alpha_w": 0.0},
    "demons": [
        {"name": "steps", "policy": {"kind": "fixed", "probabilities": TARGET}, "cumulant": 1},
        {"name": "to_goal", "policy": {"kind": "fixed", "probabilities": TARGET}, "outcome": {"sensor": "in:goal"}},
    ],
}


def learn(steps: int, seed: int) -> GridSimulation:
    """2-3. Validate the spec, check its world, run the agent `steps` steps."""
    spec = RunSpec.model_validate({**SPEC, "seed": seed})
    check_world(spec)
    sim = Simulation(spec)
    assert isinstance(sim, GridSimulation)  # a grid world's: it reads predictions at any point (`predictions_at`)
    sim.run(steps)
    return sim


def compare(sim: GridSimulation, name: str) -> float:
    """4. Print demon `name`'s prediction in every cell beside the exact answer; return the worst relative error."""
    truth = exact(sim.horde, sim.horde_state, name)
    print(f"\n{name}: prediction vs exact answer, cell by cell (the lattice points the agent visits)")
    print(f"  {'x':>5} {'y':>5} {'predicted':>10} {'exact':>10} {'error':>8}")
    worst = 0.0
    for x, y, value in zip(truth.x, truth.y, truth.value, strict=True):
        predicted = sim.predictions_at(float(x), float(y))[name]
        error = abs(predicted - value) / max(abs(value), 1e-9)
        worst = max(worst, error)
        print(f"  {x:5.0f} {y:5.0f} {predicted:10.3f} {value:10.3f} {100 * error:7.2f}%")
    return worst


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--steps", type=int, default=20_000)
    parser.add_argument("--seed", type=int, default=3)
    args = parser.parse_args(argv)
    sim = learn(args.steps, args.seed)
    print(f"{sim.total_steps} steps, {sim.episode} episodes")
    worst = max(compare(sim, name) for name in ("steps", "to_goal"))
    print(f"\nworst relative error over both demons and every cell: {100 * worst:.2f}%")
    return 0 if np.isfinite(worst) else 1


if __name__ == "__main__":
    raise SystemExit(main())
