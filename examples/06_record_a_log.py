"""06 · Record a sensor log: MountainCar driven by an energy-pumping behaviour, written as a stream log.

A robot's log is a CSV with one line per time step: what each sensor read, the action then taken, and the
behaviour's probabilities of every action (so that off-policy demons get exact importance ratios). This
script makes one from Gymnasium's MountainCar: the behaviour pushes in the direction of the car's velocity
with probability 1 - epsilon + epsilon / 3 (epsilon = 0.5), any action otherwise; episodes follow one
another, as a robot's life would (the log is one continuing stream).

Learn it at full speed:       horde run scenarios/mountaincar-log.toml --log examples/data/mountaincar-pump.csv
Replay it live to a server:   python examples/07_stream_replay.py examples/data/mountaincar-pump.csv --hz 50

Run it:  python examples/06_record_a_log.py [--records 10000] [--seed 0] [--out examples/data/mountaincar-pump.csv]
"""

from __future__ import annotations

import argparse
import csv
from pathlib import Path

import gymnasium as gym
import numpy as np

EPSILON = 0.5


def pump_probabilities(velocity: float) -> list[float]:
    """b(. | s): push left (0) while moving left, right (2) otherwise; epsilon spread over all three."""
    probs = [EPSILON / 3] * 3
    probs[2 if velocity >= 0 else 0] += 1 - EPSILON
    return probs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", type=int, default=10_000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default=str(Path(__file__).parent / "data" / "mountaincar-pump.csv"))
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    env = gym.make("MountainCar-v0")
    obs, _ = env.reset(seed=args.seed)
    with open(args.out, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["position", "velocity", "action", "b0", "b1", "b2"])
        for _ in range(args.records):
            probs = pump_probabilities(float(obs[1]))
            action = int(rng.choice(3, p=probs))
            writer.writerow([f"{obs[0]:.6f}", f"{obs[1]:.6f}", action, *(f"{p:.6f}" for p in probs)])
            obs, _, terminated, truncated, _ = env.step(action)
            if terminated or truncated:
                obs, _ = env.reset()
    print(f"wrote {args.records} records to {args.out}")


if __name__ == "__main__":
    main()
