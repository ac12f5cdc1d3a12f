"""A standalone demo of the live view: `python -m horde.view [scenario ...] [--port 8081] [--hz 10]`.

Runs the scenarios in this process, as the server's runs (a `RunManager` with no store; created, so
press Play in the GUI), and serves the view on loopback until Ctrl-C.
"""

from __future__ import annotations

import argparse
import time

from horde.runs.manager import RunManager
from horde.scenarios import find_scenario
from horde.view.live import LiveView
from horde.view.manager_source import ManagerSource


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m horde.view", description=__doc__)
    parser.add_argument("scenarios", nargs="*", default=["experiment1", "experiment3"], help="scenario names")
    parser.add_argument("--host", default="127.0.0.1")
    parser.add_argument("--port", type=int, default=8081)
    parser.add_argument("--hz", type=float, default=10.0, help="steps per second while playing")
    args = parser.parse_args(argv)
    manager = RunManager()
    for name in args.scenarios:
        manager.create(find_scenario(name), hz=args.hz)
    view = LiveView(ManagerSource(manager), host=args.host, port=args.port)
    view.start()
    print(f"Horde Lab live view: {view.url}  (Ctrl-C stops)")
    try:
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        pass
    finally:
        view.stop()
        manager.stop()


if __name__ == "__main__":
    main()
