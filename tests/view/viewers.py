"""Browsers of the live view without a browser: raw viser WebSocket clients, and a view whose frames the
test draws itself.

`RawClient` connects as the viser client does (its subprotocol, then a camera message, after which viser
announces the client), reads what the server sends in a thread of its own so the server never blocks on
it, and can send GUI updates and clicks, as a hand-written client could.
"""

from __future__ import annotations

import threading
from typing import Any

import msgspec.msgpack
import viser
import zstandard
from viser import _messages
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import ClientConnection, connect

from horde.view import LiveView
from horde.view.source import ViewSource
from horde.view.viewer import Viewer
from polling import wait_until
from serving import free_port

MAX_KEPT = 1000  # messages a RawClient keeps
CAMERA = _messages.ViewerCameraMessage(
    wxyz=(1.0, 0.0, 0.0, 0.0),
    position=(0.0, 0.0, 10.0),
    fov=1.0,
    near=0.01,
    far=1000.0,
    image_height=600,
    image_width=800,
    look_at=(0.0, 0.0, 0.0),
    up_direction=(0.0, 1.0, 0.0),
)


class RawClient:
    """A viser client written by hand, connected to `view` (as a dashboard tab's browser with `key`)."""

    def __init__(self, view: LiveView, key: str | None = None) -> None:
        address = f"ws://127.0.0.1:{view.port}/" + (f"?viewer={key}" if key is not None else "")
        before = {v.client.client_id for v in view.viewers()}
        self.socket: ClientConnection = connect(
            address,
            origin=f"http://127.0.0.1:{view.port}",  # type: ignore[arg-type]
            subprotocols=[f"viser-v{viser.__version__}"],  # type: ignore[list-item]
            open_timeout=10,
        )
        self.received = 0
        self.messages: list[bytes] = []  # what the server sent, as sent (the first MAX_KEPT)
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        self.send(CAMERA)
        self.viewer: Viewer = wait_until(
            lambda: next((v for v in view.viewers() if v.client.client_id not in before), None),
            "the view to give the new client a viewer",
            10.0,
        )

    def _read(self) -> None:
        try:
            while True:
                message = self.socket.recv(timeout=60)
                if len(self.messages) < MAX_KEPT and isinstance(message, bytes):
                    self.messages.append(message)
                self.received += 1
        except (ConnectionClosed, TimeoutError, OSError):
            return

    def sent(self) -> list[dict[str, Any]]:
        """The messages the server sent this client (of those kept), each as its fields and `type`, decoded
        from viser's wire format: two sizes, the zstd-compressed msgpack of the window, then binary buffers."""
        decoded = []
        for window in self.messages:
            compressed = int.from_bytes(window[8:16], "little")
            inner = zstandard.ZstdDecompressor().decompress(window[16 : 16 + compressed])
            decoded.extend(msgspec.msgpack.decode(inner)["messages"])
        return decoded

    def send(self, message: _messages.Message) -> None:
        self.socket.send(msgspec.msgpack.encode(message.as_serializable_dict()))

    def update_gui(self, handle: Any, value: object) -> None:
        """Send what the viser client sends when its user changes `handle`'s value (or clicks a button)."""
        self.send(_messages.GuiUpdateMessage(handle._impl.uuid, {"value": value}))

    def close(self) -> None:
        self.socket.close()
        self._reader.join(timeout=10)


def started_by_hand(source: ViewSource, **options: Any) -> LiveView:
    """A started view whose frames the test draws itself (`refresh`), its thread stopped."""
    view = LiveView(source, port=free_port(), **options)
    view.start()
    view._stop.set()
    view.changed.set()
    assert view._thread is not None
    view._thread.join(timeout=5.0)
    return view
