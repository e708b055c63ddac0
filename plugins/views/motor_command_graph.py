"""View ``motor-command-graph``: guiding-stroke trajectories in the body frame, nodes, and a prediction under way.

Kopp & Graeser 2006, §3 and §4.4 (Fig. 3). Every edge of every motor subsystem's
graph is a motor command made of guiding strokes, one per part of the
subsystem; the view draws the trajectory each stroke produces (the forward
model run over the stroke's whole duration) as a line in the part's colour,
over the character's rest pose in its own body frame. Hub nodes (rest states)
are large black spheres, other nodes small grey ones.

With ``predict = "MOVEMENT"`` a demonstrator performs the movement and the
character's ``forward-model`` matcher watches the first ``at`` of it: the
active node is ringed in red, the candidate edges still predicting the
demonstration well are drawn thick in red, the dropped ones thin, and the
demonstration so far is a black line (§4.4: every edge leaving the active node
predicts the ongoing movement in parallel; candidates whose error passes the
threshold drop out).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from plugins.views.demonstration import demonstration, require
from toolkit.watching import ObservationLog
from plugins.lib.rendering import MAX_PIXELS, add_labels, draw_bodies, part_colours, plotter, save_png
from toolkit import Parameter, View, hookimpl

__all__ = ["MotorCommandGraphView", "edge_trajectories"]


def edge_trajectories(strokes: list[Any], fps: float = 60.0) -> list[np.ndarray]:
    """The trajectory (n, 3) of each stroke of a motor command, sampled at ``fps``."""
    return [s.trajectory(fps) for s in strokes]


class MotorCommandGraphView(View):
    """Stroke trajectories of every motor command in the body frame; the active node and candidate edges (§3, §4.4)."""

    name = "motor-command-graph"
    parameters = (
        Parameter("predict", str, "", "A movement the demonstrator performs while the forward model predicts it "
                  "(empty: just the graph)."),
        Parameter("demonstrator", str, "", "Character (file or name) who performs it (empty: the character itself)."),
        Parameter("at", float, 0.3, "Share of the demonstration watched before the picture is taken.",
                  minimum=0.0, maximum=1.0),
        Parameter("width", int, 1000, "Image width in pixels.", minimum=64, maximum=MAX_PIXELS),
        Parameter("height", int, 900, "Image height in pixels.", minimum=64, maximum=MAX_PIXELS),
    )

    def draw(self, subject: Any, out: Path) -> list[Path]:
        import pyvista as pv

        character = subject
        motor = require(character, "motor", "motor-command-graph")
        body = character.body
        colours = part_colours(body)
        prediction = self._predict(character) if self.params["predict"] else None
        pl = plotter((self.params["width"], self.params["height"]))
        try:
            draw_bodies(pl, body, motor.rest[None], radius=0.02, opacity=0.35)
            n_edges, hands = 0, []
            for subsystem, graph in motor.graphs.items():
                if motor.is_hand(subsystem):  # joint angles, not places: listed in the title, not drawn in space
                    hands.append(f"{subsystem} {graph.number_of_nodes()} nodes/{graph.number_of_edges()} commands")
                    continue
                idx = motor.subsystems[subsystem]
                candidates = set(prediction["candidates"]) if prediction and prediction["subsystem"] == subsystem else set()
                dropped = set(prediction["initial"]) - candidates if prediction and prediction["subsystem"] == subsystem else set()
                for edge in motor.edges(subsystem):
                    n_edges += 1
                    name = edge.name
                    width, opacity = (7, 1.0) if name in candidates else (1.5, 0.35) if name in dropped else (3, 0.9)
                    for part, path in zip(idx, edge_trajectories(edge.commands)):
                        colour = "red" if name in candidates else colours[part]
                        pl.add_mesh(pv.lines_from_points(path), color=colour, line_width=width, opacity=opacity)
                for node, d in graph.nodes(data=True):
                    state = np.asarray(d["state"], dtype=float).reshape(-1, 3)
                    sphere = pv.Sphere(radius=0.035 if d.get("hub") else 0.018)
                    pl.add_mesh(pv.PolyData(state).glyph(geom=sphere, scale=False, orient=False),
                                color="black" if d.get("hub") else "#808080")
                    if prediction and prediction["subsystem"] == subsystem and node == prediction["active"]:
                        ring = pv.Sphere(radius=0.05)
                        pl.add_mesh(pv.PolyData(state).glyph(geom=ring, scale=False, orient=False), color="red",
                                    style="wireframe", line_width=2)
                    add_labels(pl, state[:1] + [0.0, 0.05, 0.0], [f"{subsystem}:{node}"], font_size=10, align="centre",
                               colour="#303030")
            title = (f"{character.name}: motor command graphs, {len(motor.graphs)} subsystem(s), {n_edges} command(s)"
                     + (f"\nhands: {'; '.join(hands)}" if hands else ""))
            if prediction:
                seen = prediction["observed"]
                for j in range(seen.shape[1]):
                    track = seen[:, j][np.isfinite(seen[:, j]).all(axis=1)]
                    if len(track) > 1:
                        pl.add_mesh(pv.lines_from_points(track), color="black", line_width=4)
                title += (f"\n{self.params['predict']!r} by {prediction['who']}, {self.params['at']:.0%} seen: "
                          f"active node {prediction['subsystem']}:{prediction['active']}, "
                          f"{len(prediction['candidates'])} of {len(prediction['initial'])} candidate(s) left"
                          + (f", committed to {prediction['committed']}" if prediction["committed"] else ""))
            pl.add_text(title, position="upper_left", font_size=11, color="black")
            pl.view_xy()
            pl.reset_camera()
            pl.camera.zoom(1.2)
            return [save_png(pl, out)]
        finally:
            pl.close()

    def _predict(self, character: Any) -> dict[str, Any]:
        """Feed the first ``at`` of the demonstration to the character's forward model; what it holds then."""
        matcher = require(character, "matcher", "forward-model", "predict")
        who, motion = demonstration(character, self.params["demonstrator"], self.params["predict"], "predict")
        motion = motion.onto(character.body.parts)
        n = max(1, int(round(self.params["at"] * motion.n_frames)))
        log = ObservationLog(character.body.parts, motion.fps)  # working memory, fed a frame at a time
        memory = log.since(0)
        matcher.begin(memory)
        committed = None
        for f in range(n):
            log.append(motion.positions[f], motion.visible[f])
            memory.feed(f + 1)
            answer = matcher.observe(memory)
            if answer is not None and answer.movement and committed is None:
                committed = answer.movement
        signals = matcher.inspect()
        subsystem = signals["subsystem"] or next(iter(character.motor.graphs))
        idx = character.motor.subsystems[subsystem]
        observed = np.where(log.visible[:, idx, None], log.positions[:, idx], np.nan) + character.motor.rest_pose()[
            character.body.root_index]
        return {"who": who, "subsystem": subsystem, "active": signals["start_node"] or "hub",
                "candidates": sorted({p[0] for p in signals["candidates"]}), "initial": list(signals["initial"]),
                "committed": committed, "observed": observed}


@hookimpl
def likeme_register_views():
    return [MotorCommandGraphView]
