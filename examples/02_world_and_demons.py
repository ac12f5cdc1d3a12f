"""02 · Define a world, add demons to a live run, and check them against Monte-Carlo truth.

Everything goes through REST: the script stores a world (PUT /api/worlds/{name}), creates a run on it
with one control demon, starts it, lets two prediction demons join while it learns (their weights
start at zero, the control demon keeps its own), pauses it, evaluates each prediction demon against
the Monte-Carlo truth of its question, and prints a value map of one demon as text.
When it ends it deletes the runs it made, so they do not pile up in the server's run list
(`--keep` leaves them there).
"""

from __future__ import annotations

import argparse
import os
import time

import httpx

WORLD = {
    "width": 400,
    "height": 400,
    "step": 100,
    "start": [0, 0],
    "max_steps": 200,
    "regions": [
        {"name": "goal", "kind": "terminal", "rect": [300, 300, 400, 400], "reward": 1},
        {"name": "wall", "kind": "obstacle", "rect": [100, 100, 300, 200]},
        {"name": "lane", "kind": "zone", "rect": [0, 200, 100, 400]},
    ],
}
CONTROL = {
    "name": "seek",
    "policy": {"kind": "softmax", "temperature": 0.5},
    "cumulant": -0.01,
    "outcome": {"if": {"sensor": "in:goal"}, "then": 1, "else": 0},
}
JOINERS = [
    # How many steps until the episode ends, following the control demon's policy?
    {"name": "steps_left", "policy": {"of": "seek"}, "cumulant": 1, "alpha": 0.05},
    # Will the agent pass through the lane before the end? (1 there and stop, 0 otherwise)
    {
        "name": "via_lane",
        "policy": {"of": "seek"},
        "cumulant": 0,
        "outcome": {"sensor": "in:lane"},
        "continuation": {"if": {"sensor": "in:lane"}, "then": 0, "else": 1},
    },
]


def connect(url: str) -> httpx.Client:
    token = os.environ.get("HORDE_TOKEN")
    headers = {"Authorization": f"Bearer {token}"} if token else {}
    return httpx.Client(base_url=url, headers=headers, timeout=120.0)


def shade(values: list[list[float | None]]) -> str:
    """Rows from the top (largest y) down, each cell a character from light to dark."""
    cells = [v for row in values for v in row if v is not None]
    low, high = min(cells), max(cells)
    ramp = " .:-=+*#%@"
    lines = []
    for row in reversed(values):
        chars = ["?" if v is None else ramp[int((v - low) / (high - low + 1e-12) * (len(ramp) - 1))] for v in row]
        lines.append(" ".join(chars))
    return "\n".join(lines)


def main(argv: list[str] | None = None, client: httpx.Client | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--url", default=os.environ.get("HORDE_URL", "http://127.0.0.1:8000"))
    parser.add_argument("--seconds", type=float, default=5.0, help="how long the run learns")
    parser.add_argument("--rollouts", type=int, default=500)
    parser.add_argument("--keep", action="store_true", help="leave the runs it made on the server")
    args = parser.parse_args(argv)
    client = client or connect(args.url)
    created: list[str] = []  # the runs it makes: deleted when it ends (in a finally), unless --keep
    try:
        client.put("/api/worlds/lane-room", json=WORLD).raise_for_status()
        body = {
            "world": "lane-room",
            "seed": 7,
            "behaviour": {"kind": "softmax", "demon": "seek", "temperature": 0.5},
            "demons": [CONTROL],
            "protocol": {"episodes": 0},  # run until paused
        }
        response = client.post("/api/runs", json=body, params={"start": "true"})
        response.raise_for_status()
        run_id = response.json()["id"]
        created.append(run_id)
        print(f"run {run_id} on world lane-room, learning with demon 'seek'")
        time.sleep(args.seconds / 2)
        for demon in JOINERS:
            client.post(f"/api/runs/{run_id}/demons", json=demon).raise_for_status()
            print(f"  demon {demon['name']!r} joined the live run")
        time.sleep(args.seconds / 2)
        run = client.post(f"/api/runs/{run_id}/pause").json()
        print(f"paused after {run['episode']} episodes, {run['step']} steps")

        for demon in JOINERS:
            request = {"demon": demon["name"], "from": [0, 0], "episodes": args.rollouts, "seed": 1}
            result = client.post(f"/api/runs/{run_id}/evaluate", json=request).json()
            print(
                f"  {result['demon']:>10}: prediction {result['prediction']:7.3f}, "
                f"Monte-Carlo truth {result['truth']:7.3f} ± {result['stderr']:.3f}"
            )
        values = client.get(f"/api/runs/{run_id}/demons/steps_left/values", params={"resolution": 8}).json()
        print(f"steps_left over the world (dark = more steps, {values['min']:.1f} .. {values['max']:.1f}):")
        print(shade(values["values"]))
        return 0
    finally:
        if not args.keep:
            for made in created:
                client.delete(f"/api/runs/{made}")


if __name__ == "__main__":
    raise SystemExit(main())
