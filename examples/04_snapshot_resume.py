"""04 · Snapshots: export a run, import it as a new run, and see both continue identically.

A snapshot holds the weights, traces, generator state, counters and the world's state. The script
steps a run, exports its snapshot (GET /api/runs/{id}/snapshot), steps the original further, imports
the snapshot (POST /api/runs/import) and steps the copy as far: the predictions agree to the last bit.
Save the snapshot's JSON to a file to carry a run to another server.
When it ends it deletes the runs it made, so they do not pile up in the server's run list
(`--keep` leaves them there).
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

import httpx


def connect(url: str) -> httpx.Client:
    token = os.environ.get("HORDE_TOKEN")
    headers = {"Authorization": f"Bearer {token}"} if token else {}
    return httpx.Client(base_url=url, headers=headers, timeout=120.0)


def main(argv: list[str] | None = None, client: httpx.Client | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--url", default=os.environ.get("HORDE_URL", "http://127.0.0.1:8000"))
    parser.add_argument("--steps", type=int, default=5000)
    parser.add_argument("--save", type=Path, help="also write the snapshot to this file")
    parser.add_argument("--keep", action="store_true", help="leave the runs it made on the server")
    args = parser.parse_args(argv)
    client = client or connect(args.url)
    created: list[str] = []  # the runs it makes: deleted when it ends (in a finally), unless --keep
    try:
        response = client.post("/api/runs", json={"scenario": "experiment1", "protocol": {"episodes": 0}})
        response.raise_for_status()
        original = response.json()["id"]
        created.append(original)
        client.post(f"/api/runs/{original}/step", json={"steps": args.steps}).raise_for_status()
        snapshot = client.get(f"/api/runs/{original}/snapshot").json()
        print(f"snapshot of run {original} at step {snapshot['total_steps']}")
        if args.save:
            args.save.write_text(json.dumps(snapshot))
            print(f"  written to {args.save}")

        later = client.post(f"/api/runs/{original}/step", json={"steps": args.steps}).json()
        response = client.post("/api/runs/import", json=snapshot)
        response.raise_for_status()
        copy = response.json()["id"]
        created.append(copy)
        print(f"imported as run {copy} ({response.json()['status']} at step {response.json()['step']})")
        resumed = client.post(f"/api/runs/{copy}/step", json={"steps": args.steps}).json()

        for name, value in later["predictions"].items():
            print(f"  {name:>14}: original {value:.12f}, resumed copy {resumed['predictions'][name]:.12f}")
        same = later["predictions"] == resumed["predictions"]
        print("identical" if same else "DIFFERENT")
        return 0 if same else 1
    finally:
        if not args.keep:
            for made in created:
                client.delete(f"/api/runs/{made}")


if __name__ == "__main__":
    raise SystemExit(main())
