"""A viser view of a stream run's phase plane: `python -m horde.view.stream_view --stream ID --demon D`.

It polls GET /api/streams/{id}/phase-plane twice a second and draws what it answers (the demon's value map
over two sensors, the trail of recent readings, the agent) with the scene builders of `phase_plane.py`,
sending only what changed. A stream run has no agent the live view steps, so this view only reads.
"""

from __future__ import annotations

import argparse
import os
import time
from typing import Any

import numpy as np

from horde.view.nodes import Node
from horde.view.phase_plane import phase_plane_nodes
from horde.worlds.phase_plane import Axis


def nodes_from(body: dict[str, Any]) -> list[Node]:
    """The scene of a phase-plane response (GET /api/streams/{id}/phase-plane)."""
    x, y = Axis(**body["x"]), Axis(**body["y"])
    values = np.array([[np.nan if v is None else v for v in row] for row in body["values"]], dtype=float)
    trail = np.array(body["trail"], dtype=float).reshape(-1, 2)
    return phase_plane_nodes(x, y, body["demon"], values, trail)


def main(argv: list[str] | None = None) -> int:
    import httpx
    import viser

    from horde.view.apply import SceneApplier

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--url", default=os.environ.get("HORDE_URL", "http://127.0.0.1:8000"))
    parser.add_argument("--stream", required=True, help="the stream run's id")
    parser.add_argument("--demon", required=True)
    parser.add_argument("--x", default="position", help="the sensor along x")
    parser.add_argument("--y", default="velocity", help="the sensor along y")
    parser.add_argument("--resolution", type=int, default=48)
    parser.add_argument("--port", type=int, default=8090)
    args = parser.parse_args(argv)
    server = viser.ViserServer(host="127.0.0.1", port=args.port, verbose=False)
    server.scene.world_axes.visible = False
    applier = SceneApplier(server.scene)
    params = {"demon": args.demon, "x": args.x, "y": args.y, "resolution": args.resolution}
    print(f"the phase plane of {args.demon} at http://127.0.0.1:{args.port}/ (Ctrl-C stops)")
    with httpx.Client(base_url=args.url, timeout=30) as client:
        while True:
            response = client.get(f"/api/streams/{args.stream}/phase-plane", params=params)
            if response.status_code != 200:
                print(f"the server answered {response.status_code}: {response.text}")
                return 1
            with server.atomic():
                applier.apply(nodes_from(response.json()), "phase")
            time.sleep(0.5)


if __name__ == "__main__":
    raise SystemExit(main())
