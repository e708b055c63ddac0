"""View ``posegraph``: the posegraph in 3D, hubs large, nodes coloured by movement, a matched path highlighted.

Buchsbaum & Blumberg 2005, §4.1 and §5.2.1. Each node of the posegraph is a
whole-body pose; the view lays the nodes out by their pose vectors (root-relative,
flattened, projected on their three principal components), so similar poses sit
close together and every movement is a loop out of a hub and back. Hubs are
large black spheres, other nodes small spheres in their movement's colour,
transitions thin lines. With ``match = "MOVEMENT"`` the character performs that
movement, its own ``path-search`` matcher parses it, and the path it found is
drawn as a thick red line through the graph (§5.2.1: recognising a movement is
finding the best path).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from plugins.views.demonstration import demonstration, require
from plugins.lib.rendering import MAX_PIXELS, _PALETTE, add_labels, hex_to_rgb, plotter, save_png
from toolkit import Parameter, View, hookimpl

__all__ = ["PosegraphView", "pose_layout"]


def pose_layout(poses: np.ndarray) -> np.ndarray:
    """Node positions (N, 3) from pose vectors (N, P, 3): the principal-component projection, scaled to about ±1."""
    x = np.nan_to_num(poses.reshape(len(poses), -1))
    x = x - x.mean(axis=0)
    _, s, vt = np.linalg.svd(x, full_matrices=False)
    k = min(3, len(s))
    coords = np.zeros((len(poses), 3))
    coords[:, :k] = x @ vt[:k].T
    return coords / max(float(np.abs(coords).max()), 1e-9)


class PosegraphView(View):
    """The posegraph laid out from its pose vectors: hubs large, nodes by movement, a matched path in red (§4.1)."""

    name = "posegraph"
    parameters = (
        Parameter("match", str, "", "A movement the character performs and its path-search matcher parses; "
                  "the path found is highlighted (empty: none)."),
        Parameter("demonstrator", str, "", "Character (file or name) who performs the movement to match "
                  "(empty: the character itself)."),
        Parameter("speed", float, 1.0, "Speed of the performed movement.", minimum=0.05),
        Parameter("labels", bool, True, "Name each movement beside its nodes."),
        Parameter("width", int, 1200, "Image width in pixels.", minimum=64, maximum=MAX_PIXELS),
        Parameter("height", int, 900, "Image height in pixels.", minimum=64, maximum=MAX_PIXELS),
    )

    def draw(self, subject: Any, out: Path) -> list[Path]:
        import pyvista as pv

        character = subject
        motor = require(character, "motor", "posegraph")
        names = motor.nodes
        coords = pose_layout(motor.node_root_relative)
        index = {n: i for i, n in enumerate(names)}
        movements = sorted({m for n in names if (m := motor.movement_of(n))})
        colour = {m: _PALETTE[i % len(_PALETTE)] for i, m in enumerate(movements)}
        hub = np.array([bool(motor.graph.nodes[n]["hub"]) for n in names])
        pl = plotter((self.params["width"], self.params["height"]))
        try:
            edges = np.array([(index[a], index[b]) for a, b in motor.graph.edges], dtype=int).reshape(-1, 2)
            if len(edges):
                lines = pv.PolyData(coords, lines=np.column_stack([np.full(len(edges), 2), edges]).ravel())
                pl.add_mesh(lines, color="#9a9a9a", line_width=1)
            nodes = pv.PolyData(coords[~hub])
            if nodes.n_points:
                nodes["rgb"] = np.array([hex_to_rgb(colour[motor.movement_of(n)]) for n, h in zip(names, hub) if not h],
                                        dtype=np.uint8)
                pl.add_mesh(nodes.glyph(geom=pv.Sphere(radius=0.012), scale=False, orient=False), scalars="rgb", rgb=True)
            pl.add_mesh(pv.PolyData(coords[hub]).glyph(geom=pv.Sphere(radius=0.05), scale=False, orient=False), color="black")
            add_labels(pl, coords[hub] + [0, 0.08, 0], [f"hub {n}" for n, h in zip(names, hub) if h], font_size=16,
                       align="centre")
            if self.params["labels"]:
                where = [coords[[index[n] for n in names if motor.movement_of(n) == m]] for m in movements]
                far = [w[np.argmax(np.linalg.norm(w, axis=1))] for w in where]
                add_labels(pl, np.array(far) * 1.08, movements, font_size=11, align="centre", colour="#303030")
            title = f"{character.name}: posegraph, {len(names)} poses, {len(movements)} movements, {int(hub.sum())} hub(s)"
            if self.params["match"]:
                match = self._match(character)
                path = [index[n] for n in match.path if n in index]
                if len(path) > 1:
                    pl.add_mesh(pv.lines_from_points(coords[path]), color="red", line_width=6)
                    pl.add_mesh(pv.PolyData(coords[path]).glyph(geom=pv.Sphere(radius=0.02), scale=False, orient=False),
                                color="red")
                who = self.params["demonstrator"] or character.name
                title += (f"\npath of {self.params['match']!r} performed by {who}: recognised as "
                          f"{match.movement or 'unknown'} (confidence {match.confidence:.2f})")
            pl.add_text(title, position="upper_left", font_size=12, color="black")
            pl.view_isometric()
            pl.reset_camera()
            pl.camera.zoom(1.4)
            return [save_png(pl, out)]
        finally:
            pl.close()

    def _match(self, character: Any) -> Any:
        matcher = require(character, "matcher", "path-search", "match")
        _, motion = demonstration(character, self.params["demonstrator"], self.params["match"], "match",
                                  speed=self.params["speed"])
        return matcher.match(motion.onto(character.body.parts))


@hookimpl
def likeme_register_views():
    return [PosegraphView]
