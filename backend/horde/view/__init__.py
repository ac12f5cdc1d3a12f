"""The viser live view: a run's world, agent and predictions in the browser, as they happen.

`LiveView` owns one viser server and draws the run chosen in its GUI from a `ViewSource` (the run
manager in the server; `SimulationSource` for tests and the demo, `python -m horde.view`). The scene
is built by pure functions (scene.py) from frozen `ViewSnapshot`s.
"""

from horde.view.live import LiveView
from horde.view.sim_source import SimulationSource
from horde.view.source import History, ViewSnapshot, ViewSource

__all__ = ["History", "LiveView", "SimulationSource", "ViewSnapshot", "ViewSource"]
