"""01 · A first run over REST: start the thesis's Experiment 1 and read what the demons learned.

Start a server first (`horde serve`, or `make serve`), then run `python examples/01_first_run.py`.
The script lists the scenarios, creates a run of `experiment1` with fewer episodes than the thesis
used (overrides are merged into the scenario), starts it, waits until its protocol is done and prints
each demon's prediction at the start point. Set HORDE_URL for another server and HORDE_TOKEN if the
server requires one.
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
    return httpx.Client(base_url=url, headers=headers, timeout=60.0)


def main(argv: list[str] | None = None, client: httpx.Client | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--url", default=os.environ.get("HORDE_URL", "http://127.0.0.1:8000"))
    parser.add_argument("--episodes", type=int, default=300)
    parser.add_argument("--keep", action="store_true", help="leave the runs it made on the server")
    args = parser.parse_args(argv)
    client = client or connect(args.url)
    created: list[str] = []  # the runs it makes: deleted when it ends (in a finally), unless --keep
    try:
        print("scenarios:", ", ".join(s["name"] for s in client.get("/api/scenarios").json()))
        response = client.post(
            "/api/runs",
            json={"scenario": "experiment1", "protocol": {"episodes": args.episodes}},
            params={"start": "true"},
        )
        response.raise_for_status()
        run = response.json()
        created.append(run["id"])
        print(f"run {run['id']}: {run['spec']['description']}")

        while run["status"] == "running":
            time.sleep(0.2)
            run = client.get(f"/api/runs/{run['id']}").json()
            print(f"\r  episode {run['episode']:>5} / {args.episodes}, step {run['step']:>7}", end="", flush=True)
        print()
        if run["status"] != "finished":
            print(f"the run is {run['status']}: {run['message']}")
            return 1
        for name, prediction in run["summary"]["predictions"].items():
            print(f"  {name:>14}: {prediction:8.3f} at the start point")
        return 0
    finally:
        if not args.keep:
            for made in created:
                client.delete(f"/api/runs/{made}")


if __name__ == "__main__":
    raise SystemExit(main())
