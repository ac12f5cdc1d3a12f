"""Records per second a stream world's Horde learns: from a CSV log (`horde run --log`) and over the WebSocket.

A stream of 10 sensors and 3 actions, 1,000 GTD(lambda) demons (10 sensors x 5 timescales x 20 fixed target
policies), features tiling every sensor (4 tilings of 4 tiles, hashed into 4096 entries: 41 active). The log
path reads and checks the CSV in bulk and learns it chunk by chunk; the WebSocket path runs the real server in
this process and pushes the same records from another process (examples/07_stream_replay.py, --hz 0) in
messages of --batch records. Wall and CPU time are printed for both.

Run it:  python benchmarks/stream_throughput.py [--records 20000] [--batch 500]
"""

from __future__ import annotations

import argparse
import csv
import json
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

import httpx
import numpy as np
import uvicorn

from horde.server import Settings, create_app
from horde.server.cli_serve import UVICORN_OPTIONS
from horde.spec import RunSpec
from horde.worlds.log_run import learn_log

ROOT = Path(__file__).resolve().parents[1]
SENSORS = [f"s{i}" for i in range(10)]


def spec_1000() -> dict[str, Any]:
    rng = np.random.default_rng(0)
    policies = [list(np.round(p / p.sum(), 6)) for p in rng.uniform(0.1, 1.0, size=(20, 3))]
    policies = [[*p[:2], round(1.0 - p[0] - p[1], 6)] for p in policies]
    return {
        "world": {"kind": "stream", "actions": 3, "sensors": [{"name": s, "low": 0, "high": 1} for s in SENSORS]},
        "features": {"kind": "sensors", "tilings": 4, "tiles": 4, "size": 4096,
                     "sensors": [{"sensor": s, "low": 0, "high": 1} for s in SENSORS]},
        "families": [{"name": f"{{s}}_g{{gamma}}_p{k}", "over": {"s": SENSORS, "gamma": [0, 0.5, 0.8, 0.9, 0.95]},
                      "demon": {"learner": "gtd", "cumulant": {"sensor": "{s}"}, "discount": "{gamma}",
                                "policy": {"kind": "fixed", "probabilities": p}}} for k, p in enumerate(policies)],
    }  # fmt: skip


def write_log(path: Path, n: int) -> None:
    rng = np.random.default_rng(1)
    t = np.arange(n)[:, None]
    values = 0.5 + 0.45 * np.sin(t / (10.0 + 7.0 * np.arange(10)[None, :]))  # [n, 10]
    with path.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow([*SENSORS, "action"])
        for i in range(n):
            writer.writerow([*(f"{v:.5f}" for v in values[i]), int(rng.integers(3))])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", type=int, default=20_000)
    parser.add_argument("--batch", type=int, default=500)
    args = parser.parse_args()
    spec = RunSpec.model_validate(spec_1000())
    assert len(spec.demons) == 1000
    with tempfile.TemporaryDirectory() as tmp:
        log = Path(tmp) / "log.csv"
        write_log(log, args.records)
        learn_log(spec, log)  # compile (or load) the kernels first
        wall, cpu = time.perf_counter(), time.process_time()
        result = learn_log(spec, log)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        print(f"CSV log: {result.learned} records, 1000 demons: {wall:.2f} s wall, {cpu:.2f} s CPU, "
              f"{result.learned / wall:,.0f} records/s")  # fmt: skip
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = int(s.getsockname()[1])
        app = create_app(Settings(data=Path(tmp) / "data", token=None, snapshot_every=3600.0))
        config = uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning", **UVICORN_OPTIONS)
        server = uvicorn.Server(config)
        thread = threading.Thread(target=server.run, daemon=True)
        thread.start()
        while not server.started:
            time.sleep(0.05)
        url = f"http://127.0.0.1:{port}"
        run = httpx.post(f"{url}/api/streams", json=spec_1000(), timeout=60).json()
        out = Path(tmp) / "out.json"
        cpu = time.process_time()
        subprocess.run([sys.executable, str(ROOT / "examples" / "07_stream_replay.py"), str(log), "--url", url,
                        "--stream", run["id"], "--hz", "0", "--batch", str(args.batch), "--out", str(out)],
                       check=True, capture_output=True, timeout=3600)  # fmt: skip
        cpu = time.process_time() - cpu
        pushed = json.loads(out.read_text())
        print(f"WebSocket: {pushed['learned']} records in messages of {args.batch}, 1000 demons: "
              f"{pushed['seconds']:.2f} s wall, {cpu:.2f} s CPU in the server process, "
              f"{pushed['learned'] / pushed['seconds']:,.0f} records/s")  # fmt: skip
        server.should_exit = True
        thread.join(timeout=20)


if __name__ == "__main__":
    main()
