"""07 · Replay a recorded sensor log to a live stream run, in real time, and watch the predictions come back.

A robot pushes one record per time step to the server and reads the Horde's predictions on the same
WebSocket. This script plays the robot with a recorded log (examples/06_record_a_log.py wrote one):

1. it starts a stream run from a scenario whose world is of kind "stream" (POST /api/streams with the
   scenario's spec, read from GET /api/scenarios/{name}), or joins the run given by --stream;
2. it sends the log's records over WS /api/streams/{id}/records, --hz records a second (0: as fast as the
   server learns; the server's bounded queue then holds the sender back), --batch records per message;
3. a second thread reads what comes back: "learned" messages with every demon's prediction, "error"
   messages naming the field of a refused record; every second the script prints a few predictions;
4. at the end it waits until the server has learned every record and prints (or writes, --out) the
   final predictions; a stream run it started is then deleted (`--keep` leaves it on the server).

Start a server first (`horde serve`), then:
    python examples/07_stream_replay.py examples/data/mountaincar-pump.csv --hz 50
Set HORDE_URL for another server and HORDE_TOKEN if the server requires one.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import sys
import threading
import time
from pathlib import Path
from typing import Any

import httpx
from websockets.sync.client import connect as ws_connect


def read_records(path: Path, sensors: list[str], actions: int) -> list[dict[str, Any]]:
    """The log's records, in order: observation (the scenario's sensors), action, behaviour probabilities."""
    with path.open(newline="") as handle:
        reader = csv.DictReader(handle)
        with_probs = reader.fieldnames is not None and "b0" in reader.fieldnames
        records = []
        for row in reader:
            record: dict[str, Any] = {"observation": [float(row[s]) for s in sensors], "action": int(row["action"])}
            if with_probs:
                record["behaviour_probabilities"] = [float(row[f"b{a}"]) for a in range(actions)]
            records.append(record)
    return records


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log", type=Path, help="a CSV log: the sensors' columns, action, optionally b0..")
    parser.add_argument("--url", default=os.environ.get("HORDE_URL", "http://127.0.0.1:8000"))
    parser.add_argument("--scenario", default="mountaincar-log", help="a stream scenario the server knows")
    parser.add_argument("--stream", help="push to this stream run instead of starting one")
    parser.add_argument("--hz", type=float, default=50.0, help="records a second (0: full speed)")
    parser.add_argument("--batch", type=int, default=1, help="records per message")
    parser.add_argument("--out", type=Path, help="write the final counts and predictions here as JSON")
    parser.add_argument("--timeout", type=float, default=600.0, help="give up waiting for the server after this")
    parser.add_argument("--keep", action="store_true", help="leave the stream run it started on the server")
    args = parser.parse_args(argv)
    token = os.environ.get("HORDE_TOKEN")
    headers = {"Authorization": f"Bearer {token}"} if token else {}
    with httpx.Client(base_url=args.url, headers=headers, timeout=60.0) as client:
        if args.stream is None:
            spec = client.get(f"/api/scenarios/{args.scenario}").raise_for_status().json()
            run = client.post("/api/streams", json=spec).raise_for_status().json()
        else:
            run = client.get(f"/api/streams/{args.stream}").raise_for_status().json()
    try:
        return replay(args, run, headers)
    finally:  # a stream run it started is deleted, even when the replay failed, unless --keep
        if args.stream is None and not args.keep:
            httpx.delete(f"{args.url}/api/streams/{run['id']}", headers=headers, timeout=60.0)


def replay(args: argparse.Namespace, run: dict[str, Any], headers: dict[str, str]) -> int:
    """Steps 2 to 4: send the log's records to stream run `run`, read the predictions, print the final ones."""
    print(f"stream run {run['id']}: sensors {', '.join(run['sensors'])}; {len(run['demons'])} demons")
    records = read_records(args.log, run["sensors"], run["actions"])
    base = int(run["received"])  # records the run had before this replay
    ws_url = args.url.replace("http", "ws", 1) + f"/api/streams/{run['id']}/records"
    last: dict[str, Any] = {"learned": 0, "received": 0, "predictions": None}
    errors: list[dict[str, Any]] = []
    done = threading.Event()

    with ws_connect(ws_url, additional_headers=headers, max_size=2**24) as socket:
        hello = json.loads(socket.recv(timeout=30))
        demons: list[str] = hello["demons"]

        def receive() -> None:
            while not done.is_set():
                try:
                    message = json.loads(socket.recv(timeout=1))
                except TimeoutError:
                    continue
                except Exception:
                    return
                if message["type"] == "learned":
                    last.update(message)
                    if last["received"] >= base + len(records):
                        done.set()
                elif message["type"] == "error":
                    errors.append(message)
                    print(f"refused record {message['index']}: {message['field']}: {message['message']}")

        reader = threading.Thread(target=receive, daemon=True)
        reader.start()
        began = time.monotonic()
        shown = began
        for start in range(0, len(records), args.batch):
            batch = records[start : start + args.batch]
            socket.send(json.dumps({"records": batch}))
            if args.hz > 0:  # real time: the next record leaves at its own time
                time.sleep(max(0.0, began + (start + len(batch)) / args.hz - time.monotonic()))
            if time.monotonic() - shown >= 1.0 and last["predictions"] is not None:
                shown = time.monotonic()
                preview = ", ".join(f"{n} {p:.3f}" for n, p in list(zip(demons, last["predictions"], strict=True))[:4])
                print(f"{last['learned']} learned: {preview}")
        if not done.wait(args.timeout):
            print(f"the server learned {last['learned']} of {len(records)} records in time", file=sys.stderr)
            return 1
        done.set()
        seconds = time.monotonic() - began
    sent = last["received"] - base
    print(f"{sent} records sent, {last['learned']} learned in all, {len(errors)} refused, "
          f"in {seconds:.1f} s ({sent / seconds:,.0f} records/s)")  # fmt: skip
    predictions = dict(zip(demons, last["predictions"] or [], strict=False))
    for name, value in list(predictions.items())[:12]:
        print(f"  {name:24s} {value: .4f}")
    if args.out:
        args.out.write_text(json.dumps({"received": last["received"], "learned": last["learned"], "errors": errors,
                                        "seconds": seconds, "predictions": predictions}))  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main())
