"""03 · Experiment 1 against the truth: the steps-to-end prediction vs Monte-Carlo rollouts.

The thesis predicted 30.7 steps where simulation gave 39.0. This script runs `experiment1` over REST
(one trial, `--episodes` episodes), then asks the server for the Monte-Carlo truth of the demon
`steps_to_end` from the start point, following the base demon's frozen policy, and prints the
prediction, the truth with its standard error, and the relative error.
When it ends it deletes the runs it made, so they do not pile up in the server's run list
(`--keep` leaves them there).
"""

from __future__ import annotations

import argparse
import os
import time

import httpx


def connect(url: str) -> httpx.Client:
    token = os.environ.get("HORDE_TOKEN")
    headers = {"Authorization": f"Bearer {token}"} if token else {}
    return httpx.Client(base_url=url, headers=headers, timeout=300.0)


def main(argv: list[str] | None = None, client: httpx.Client | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--url", default=os.environ.get("HORDE_URL", "http://127.0.0.1:8000"))
    parser.add_argument("--episodes", type=int, default=2000)
    parser.add_argument("--rollouts", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--keep", action="store_true", help="leave the runs it made on the server")
    args = parser.parse_args(argv)
    client = client or connect(args.url)
    created: list[str] = []  # the runs it makes: deleted when it ends (in a finally), unless --keep
    try:
        body = {"scenario": "experiment1", "seed": args.seed, "protocol": {"episodes": args.episodes}}
        response = client.post("/api/runs", json=body, params={"start": "true"})
        response.raise_for_status()
        run_id = response.json()["id"]
        created.append(run_id)
        while (run := client.get(f"/api/runs/{run_id}").json())["status"] == "running":
            time.sleep(0.2)
        if run["status"] != "finished":
            print(f"the run is {run['status']}: {run['message']}")
            return 1
        start = run["spec"]["world"]["start"][:2]
        request = {"demon": "steps_to_end", "from": start, "episodes": args.rollouts, "seed": args.seed}
        result = client.post(f"/api/runs/{run_id}/evaluate", json=request).json()
        relative = 100 * result["error"] / result["truth"]
        print(f"after {run['episode']} episodes ({run['step']} steps):")
        print(f"  predicted steps to the end: {result['prediction']:.2f}")
        print(
            f"  Monte-Carlo truth:          {result['truth']:.2f} ± {result['stderr']:.2f} "
            f"({result['episodes']} rollouts)"
        )
        print(f"  error:                      {result['error']:+.2f} ({relative:+.1f} %)")
        print("  the thesis:                 30.7 predicted, 39.0 simulated")
        return 0
    finally:
        if not args.keep:
            for made in created:
                client.delete(f"/api/runs/{made}")


if __name__ == "__main__":
    raise SystemExit(main())
