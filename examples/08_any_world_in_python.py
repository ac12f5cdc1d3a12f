"""08 · Any world in Python: the grid, a Gymnasium environment, Baird's star, and a recorded log.

`horde.Simulation(spec)` is the one way to run a simulated world of any kind: the grid world (the compiled
loop), a Gymnasium environment such as MountainCar, or Baird's seven-state star (both stepped in Python).
Each runs `n` steps with `.run(n)` and answers every demon's prediction at the agent's state with
`.predictions()`. A stream world has no simulation (its records come from outside); `horde.learn_log(spec,
path)` learns a recorded log in order and compares each prediction with the return the log realised.

Run it:  python examples/08_any_world_in_python.py [--steps 1000]
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from horde import Simulation, learn_log, load_scenario

ROOT = Path(__file__).resolve().parents[1]
SIMULATED = ("experiment1", "mountaincar-nexting", "baird")  # a grid, a Gymnasium and Baird's world
LOG = ROOT / "examples" / "data" / "mountaincar-pump.csv"


def simulate(name: str, steps: int) -> dict[str, float]:
    """Run scenario `name` for `steps` steps; print and return its demons' predictions."""
    spec = load_scenario(ROOT / "scenarios" / f"{name}.toml")
    sim = Simulation(spec)
    sim.run(steps)
    predictions = sim.predictions()
    first = ", ".join(f"{demon} {value:.3f}" for demon, value in list(predictions.items())[:3])
    print(f"{name} ({spec.world.kind}): {sim.total_steps} steps, {sim.episode} episodes, "
          f"{len(predictions)} predictions: {first}, ...")  # fmt: skip
    return predictions


def replay_log() -> int:
    """Learn the recorded MountainCar log; print each demon's mean prediction beside the mean realised return."""
    spec = load_scenario(ROOT / "scenarios" / "mountaincar-log.toml")
    result = learn_log(spec, LOG)
    print(f"\n{LOG.name}: {result.learned} of {result.records} records learned in {result.seconds:.2f} s")
    for demon in result.demons[:4]:
        if demon.mean_prediction is not None and demon.mean_return is not None:
            print(f"  {demon.name}: mean prediction {demon.mean_prediction:.3f}, "
                  f"mean realised return {demon.mean_return:.3f}")  # fmt: skip
    return result.learned


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--steps", type=int, default=1000)
    args = parser.parse_args(argv)
    finite = all(math.isfinite(v) for name in SIMULATED for v in simulate(name, args.steps).values())
    learned = replay_log()
    return 0 if learned > 0 and finite else 1


if __name__ == "__main__":
    raise SystemExit(main())
