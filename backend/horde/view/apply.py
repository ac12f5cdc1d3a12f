"""`SceneApplier`: puts `Node` descriptions into a viser scene, sending only what changed."""

from __future__ import annotations

import weakref
from typing import Any

import numpy as np
import trimesh
import viser
from viser import _messages
from viser._scene_api import _encode_image_binary

from horde.view.nodes import Node, changed_fields

# An image node's PNG, encoded once however many browsers' scenes show it (the viewers of one frame share their
# nodes: horde.view.viewer.Frame). Encoding a 256 x 256 value map takes 3-4 ms; thirty browsers took 0.1 s a frame.
_ENCODED: weakref.WeakKeyDictionary[Node, tuple[str, bytes]] = weakref.WeakKeyDictionary()


def _encoded(node: Node) -> tuple[str, bytes]:
    """The node's image as PNG, encoded once per node."""
    assert node.image is not None
    encoded = _ENCODED.get(node)
    if encoded is None:
        encoded = _ENCODED[node] = _encode_image_binary(node.image, "png")
    return encoded


def _add_image(scene: viser.SceneApi, node: Node) -> viser.ImageHandle:
    """`scene.add_image` of the node's image, with its PNG encoded once per node (viser's own message and handle,
    as `add_image` makes them, but with the bytes given)."""
    assert node.image is not None
    encoded = _encoded(node)
    message = _messages.ImageMessage(
        name=node.name,
        props=_messages.ImageProps(
            _format="png", _data=encoded[1], render_width=node.size[0], render_height=node.size[1],
            cast_shadow=False, receive_shadow=True, scale=1.0,
        ),
    )  # fmt: skip
    handle = viser.ImageHandle._make(scene, message, node.name, (1.0, 0.0, 0.0, 0.0), node.position, True)
    handle._image, handle._jpeg_quality, handle._user_format = node.image, None, "png"
    return handle


def add_node(scene: viser.SceneApi, node: Node, label_scale: float = 1.0) -> viser.SceneNodeHandle:
    """Create (or replace) the viser node that draws `node` (a label `label_scale` times its normal size: 12 px)."""
    name, position = node.name, node.position
    if node.kind == "box":
        return scene.add_box(
            name,
            color=node.color,
            dimensions=node.size,
            opacity=node.opacity,
            position=position,
            cast_shadow=False,
        )
    if node.kind == "sphere":
        return scene.add_icosphere(name, radius=node.size[0], color=node.color, position=position, subdivisions=3)
    if node.kind == "label":
        anchor = node.anchor
        return scene.add_label(
            name,
            node.text,
            position=position,
            anchor=anchor,  # type: ignore[arg-type]
            font_screen_scale=label_scale,
        )
    if node.kind == "lines":
        assert node.points is not None
        return scene.add_line_segments(
            name, node.points, node.color, thickness=node.size[0], thickness_units="screen", position=position
        )
    if node.kind == "arrows":
        assert node.points is not None
        shaft, head, head_length = node.size
        return scene.add_arrows(
            name,
            node.points,
            node.color,
            shaft_radius=shaft,
            head_radius=head,
            head_length=head_length,
            position=position,
        )
    if node.kind == "image":
        return _add_image(scene, node)
    if node.kind == "mesh":
        assert node.points is not None and node.faces is not None
        mesh = trimesh.Trimesh(node.points, node.faces, vertex_colors=node.vertex_colors, process=False)
        return scene.add_mesh_trimesh(name, mesh, position=position)
    raise ValueError(f"unknown node kind {node.kind!r}")


DATA_FIELD = {"lines": "points", "image": "image"}  # the kinds whose data alone is updated in place


class SceneApplier:
    """The nodes drawn so far, by name and by owner (a part of the scene refreshed on its own).

    `apply(nodes, owner)` adds the new nodes, moves the ones whose position alone changed, rewrites the labels
    whose text (and position) alone changed, updates lines and images whose data alone changed (a trail, a value
    map), replaces the ones that changed otherwise, and removes the owner's
    nodes that are no longer listed. Call it inside `client.atomic()` so that a client sees one consistent frame.
    Labels are drawn `label_scale` times their normal size (Large text); change it, then `clear`, to redraw them.
    A list given is never changed afterwards (the viewers share them): the very list an owner's nodes were last
    applied from is skipped at once (a run's world and value map, frame after frame, for every browser).
    """

    def __init__(self, scene: viser.SceneApi, label_scale: float = 1.0) -> None:
        self.scene = scene
        self.label_scale = label_scale
        self.drawn: dict[str, tuple[Node, viser.SceneNodeHandle, str]] = {}
        self._applied: dict[str, list[Node]] = {}  # owner -> the list its nodes were last applied from

    def apply(self, nodes: list[Node], owner: str) -> None:
        if self._applied.get(owner) is nodes:
            return
        self._applied[owner] = nodes
        listed = {node.name for node in nodes}
        for name, (_, handle, node_owner) in list(self.drawn.items()):
            if node_owner == owner and name not in listed:
                handle.remove()
                del self.drawn[name]
        for node in nodes:
            old = self.drawn.get(node.name)
            changed = changed_fields(old[0], node) if old is not None else None
            if changed is None or "kind" in changed:
                self.drawn[node.name] = (node, add_node(self.scene, node, self.label_scale), owner)
                continue
            if not changed:
                continue
            assert old is not None
            target: Any = old[1]  # its kind's handle: a LineSegmentsHandle has points, an ImageHandle _data, ...
            data = DATA_FIELD.get(node.kind)
            if changed <= {"position"}:
                target.position = np.asarray(node.position)
            elif data is not None and changed <= {data, "position"}:
                # Lines (the trail) or an image (a value map) with new data alone: the data is updated in place (one
                # update message), not the node made anew (a new handle, and its type hints, on every redraw)
                if node.kind == "lines":
                    target.points = node.points
                else:
                    target._data = _encoded(node)[1]  # an ImageHandle's PNG
                if "position" in changed:
                    target.position = np.asarray(node.position)
            elif node.kind == "label" and changed <= {"position", "text"}:
                target.text = node.text  # a LabelHandle: its text, sent alone
                target.position = np.asarray(node.position)
            else:
                target = add_node(self.scene, node, self.label_scale)
            self.drawn[node.name] = (node, target, owner)

    def clear(self) -> None:
        """Remove every node drawn."""
        for _, handle, _ in self.drawn.values():
            handle.remove()
        self.drawn.clear()
        self._applied.clear()
