"""The viser live view: a run's world, agent and predictions in the browser, as they happen.

`LiveView` owns one viser server and draws, for each browser, the run that browser chose (its own
scene, panel and camera: `horde.view.viewer`) from a `ViewSource`: the run manager's runs behind
`ManagerSource`, in the server, in the standalone demo (`python -m horde.view`) and in the tests alike.
The scene is built by pure functions (scene.py) from frozen `ViewSnapshot`s.
"""

from horde.view.live import LiveView
from horde.view.manager_source import ManagerSource
from horde.view.source import CommandRefusedError, History, ViewSnapshot, ViewSource

__all__ = ["CommandRefusedError", "History", "LiveView", "ManagerSource", "ViewSnapshot", "ViewSource"]
