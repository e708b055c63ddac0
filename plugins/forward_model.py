"""Matcher ``forward-model``: predicting the ongoing demonstration from the active node's edges (Kopp & Graeser 2006, §4.4, Fig. 3).

When a demonstration begins, every edge leaving the active node of the moving
subsystem's motor command graph predicts, in parallel, where the demonstrator's
part should be (its forward model, :meth:`GuidingStroke.position`). A candidate
whose prediction error exceeds ``threshold`` drops out. When exactly one
prevails (and enough of its path has been seen) it is executed at once, well
before the demonstration ends: *response facilitation*. While imitating, the
observation keeps being compared with the chosen edge; if they part by more
than ``deviation`` the imitation is stopped, the edge is excluded for this
segment, the subsystem returns to the last correct node and the rest is learned.

Speed: the forward model is evaluated not at the elapsed time but at the time at
which the edge would have covered the same length of path as has been observed,
so a familiar movement performed faster or slower still fits; the ratio of the
two times re-parameterises the command's speed for the imitation.

*True imitation* (§4.3, Fig. 3 top): when no edge predicts the demonstration,
the working memory of the segment is cut into strokes by the velocity/direction
segmenter's break points and each stroke is turned into a guiding stroke by the
inverse model; the strokes become new edges and nodes leading from the active
node (ending in the hub when the demonstration returns there).

The subsystem "under consideration" is the one whose parts have moved most
since the onset; subsystems moving at the same time are handled one at a time.

Hands: a hand subsystem's edges are hand transitions over the fingers' joint
angles (:mod:`plugins.hand_transition`); they predict the observed finger
configuration just as guiding strokes predict the wrist. Angles are compared
with the same thresholds through ``angle_scale`` (metres one radian counts as),
and a new hand movement is learned as one edge whose key postures are the
angular-velocity minima and direction changes (§4.3).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.ndimage import uniform_filter1d

from plugins.inverse_model import learn_commands
from plugins.velocity_direction import VelocityDirection
from toolkit import ConfigError, Match, Matcher, Motion, Parameter, hookimpl

__all__ = ["ForwardModel"]


def _arc(points: np.ndarray) -> np.ndarray:
    """Cumulative path length along points (N, 3)."""
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])


def _observed_length(points: np.ndarray) -> float:
    """Path length of an observed trajectory (N, 3), robust to observation noise.

    Noise adds length at every frame; the positions are averaged over three frames first.
    """
    if len(points) < 3:
        return float(_arc(points)[-1])
    return float(_arc(uniform_filter1d(points, size=3, axis=0, mode="nearest"))[-1])


class ForwardModel(Matcher):
    """Edges of the active node predict the demonstration in parallel; the last one left is imitated at once (K&G §4.4)."""

    name = "forward-model"
    motor_systems = ("motor-command-graph",)
    parameters = (
        Parameter("threshold", float, 0.05, "Prediction error (m) above which a candidate edge drops out.", minimum=0.0),
        Parameter("deviation", float, 0.05, "Error (m) between the imitated edge and the demonstration that stops the "
                  "imitation (also checked at the end: the demonstration must end where the edge does).", minimum=0.0),
        Parameter("min_progress", float, 0.2, "Share of the edge's path that must be seen before committing.", minimum=0.0, maximum=1.0),
        Parameter("min_move", float, 0.02, "Displacement (m) of a subsystem that makes it the one under consideration.", minimum=0.0),
        Parameter("angle_scale", float, 0.25, "Metres one radian of finger joint angle counts as when a hand "
                  "subsystem's errors and movement are compared with threshold, deviation and min_move "
                  "(0.25: the 0.05 m threshold is 0.2 rad, 11 degrees).", minimum=1e-6),
        Parameter("max_candidates", int, 24, "Most candidate command paths followed at once (the best predictions).", minimum=1),
        Parameter("error", str, "max", "How the prediction errors of a subsystem's parts combine: the largest "
                  "(a wrist subsystem, §4.4) or the mean (eq. 1 of B&B 2005, for whole-body subsystems).",
                  choices=("max", "mean")),
        Parameter("relative", bool, False, "Compare displacements since the onset instead of positions, so that a "
                  "demonstrator whose posture differs from the observer's own (another style's stance) still fits."),
        Parameter("learn", bool, True, "Learn new edges by the inverse model when no edge predicts the demonstration."),
        Parameter("drop", float, 0.5, "Speed-minimum criterion of the stroke segmentation used for learning.", minimum=0.0, maximum=1.0),
        Parameter("angle", float, 50.0, "Direction criterion (degrees) of the stroke segmentation used for learning.", minimum=1.0, maximum=180.0),
    )

    def attach(self, owner: Any) -> None:
        super().attach(owner)
        motor = owner.motor
        if not hasattr(motor, "graphs"):
            raise ConfigError(f"forward-model needs a motor command graph, not {motor.name!r}", key=("plugin",),
                              expected='[motor] plugin = "motor-command-graph"')
        self.motor = motor
        # observed root-relative positions are placed at the observer's own root height; finger angles stay as they are
        self._root_height = np.where(owner.body.angle_mask[:, None], 0.0, motor.rest_pose()[owner.body.root_index])
        self._strokes = VelocityDirection(drop=self.params["drop"], angle=self.params["angle"])
        self._tables: dict[int, tuple] = {}

    # -- streaming ------------------------------------------------------------------------------

    def begin(self, fps: float) -> None:
        self.fps = fps
        self.frames: list[np.ndarray] = []
        self.subsystem: str | None = None
        self._scale, self._hand = 1.0, False
        self.start_node: str | None = None
        self.candidates: dict[tuple[str, ...], float] = {}
        self.excluded: set[str] = set()
        self.committed: str | None = None
        self.committed_path: tuple[str, ...] = ()
        self.deviated = False
        self.initial: list[str] = []
        # per frame of the segment (once a subsystem moves): the prediction error of every candidate path evaluated,
        # dropped ones included at the frame they drop; while imitating, the committed path's error
        self.trace: list[tuple[int, dict[tuple[str, ...], float]]] = []
        self.committed_at: int | None = None  # frames of the segment seen when it committed, and when it deviated
        self.deviated_at: int | None = None

    def _local(self, pose: np.ndarray) -> np.ndarray:
        """Root-relative observed positions in the observer's motor frame (root at its own rest height; angles as seen)."""
        return pose + self._root_height

    def observe(self, pose: np.ndarray, visible: np.ndarray) -> Match | None:
        points = np.where(visible[:, None], self._local(pose), np.nan)
        if self.frames:
            points = np.where(np.isfinite(points), points, self.frames[-1])
        self.frames.append(points)
        if self.subsystem is None and not self._choose_subsystem():
            return None
        observed = np.array(self.frames)[:, self.motor.subsystems[self.subsystem]]  # (n, k, 3)
        lengths = np.array([_observed_length(observed[:, j]) for j in range(observed.shape[1])])  # once per frame
        last = observed[-1]
        frame = len(self.frames) - 1
        if self.committed is not None:
            if self.deviated:
                return None
            error = self._error(self.committed_path, lengths, last)
            self.trace.append((frame, {self.committed_path: error}))
            if error > self.params["deviation"]:
                self.deviated = True
                self.deviated_at = len(self.frames)
                self.excluded.add(self.committed_path[0])
                return Match(self.committed, 0.0, len(self.frames), details={"stop": True, "reason": "deviation"})
            return None
        errors = {path: self._error(path, lengths, last) for path in self._extended(list(self.candidates), lengths)}
        self.trace.append((frame, errors))
        alive = {path: error for path, error in errors.items() if error <= self.params["threshold"]}
        if len(alive) > self.params["max_candidates"]:  # keep the best predictions
            alive = dict(sorted(alive.items(), key=lambda kv: kv[1])[: self.params["max_candidates"]])
        self.candidates = alive
        if alive and len({self._movement_key(p) for p in alive}) == 1:  # one first command (or movement) prevails
            path = min(alive, key=alive.get)
            progress = self._progress(path[0], lengths)
            if progress >= self.params["min_progress"] or len(path) > 1:
                self.committed_path = self._known_continuation(path)
                self.committed = self.motor.add_sequence(list(self.committed_path))
                self.committed_at = len(self.frames)
                speed = self._speed(path[0], lengths, len(observed))
                label = self._path_label(self.committed_path) or self.motor.label(self.committed)
                return Match(label, float(np.exp(-alive[path] / self.params["threshold"])), len(self.frames),
                             path=self.committed_path,
                             details={"candidates": list(self.initial), "speed": speed, "progress": progress})
        return None

    def _choose_subsystem(self) -> bool:
        first, last = self.frames[0], self.frames[-1]
        best, moved = None, self.params["min_move"]
        for name, idx in self.motor.subsystems.items():
            d = float(np.nanmax(np.linalg.norm(last[idx] - first[idx], axis=-1))) * self._scale_of(name)
            if d > moved:
                best, moved = name, d
        if best is None:
            return False
        self.subsystem = best
        self._hand = self.motor.is_hand(best)
        self._scale = self._scale_of(best)
        self.start_node = self.motor.active[best]
        # a command that moves no part farther than min_move (standing still) cannot be seen to begin
        self.candidates = {(name,): 0.0 for name, _ in self.motor.edges_from(best, self.start_node)
                           if name not in self.excluded and self._length(name) * self._scale > self.params["min_move"]}
        self.initial = sorted(p[0] for p in self.candidates)
        return True

    def _scale_of(self, subsystem: str) -> float:
        """Metres one unit of the subsystem's values counts as: ``angle_scale`` for a hand's radians, else 1."""
        return self.params["angle_scale"] if self.motor.is_hand(subsystem) else 1.0

    def _length(self, name: str) -> float:
        """Path length (m, or radians for a hand) of a command's lead part."""
        return float(self._table(self._strokes_of(name)[self._lead(name)])[2][-1])

    def _strokes_of(self, name: str) -> list[Any]:
        return self.motor.edge(name)[3]["commands"]

    def _lead(self, name: str) -> int:
        """The part of the subsystem that moves farthest along a command: progress and speed are measured on it."""
        return int(np.argmax([self._table(st)[2][-1] for st in self._strokes_of(name)]))

    def _table(self, stroke: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(times, positions, cumulative path length) of a stroke on a fine grid, computed once per stroke."""
        table = self._tables.get(id(stroke))
        if table is None or table[0] is not stroke:
            grid = np.linspace(0.0, stroke.duration, 200)
            positions = stroke.position(grid)
            table = (stroke, grid, positions, _arc(positions))
            self._tables[id(stroke)] = table
        return table[1], table[2], table[3]

    def _extended(self, paths: list[tuple[str, ...]], lengths: np.ndarray) -> list[tuple[str, ...]]:
        """Paths whose commands have all been covered by the observation continue along every edge of their end node.

        ``lengths`` holds the observed path length of each part of the subsystem.
        """
        out = []
        for path in paths:
            lead = self._lead(path[0])
            seen = lengths[lead]
            total = sum(self._table(self._strokes_of(e)[lead])[2][-1] for e in path)
            end = self.motor.edge(path[-1])[2]
            nxt = [name for name, _ in self.motor.edges_from(self.subsystem, end)] if seen > total + 0.01 / self._scale else []
            out.extend([(*path, n) for n in nxt if n not in path] or [path])
        return out

    def _path_label(self, path: tuple[str, ...]) -> str | None:
        """The labelled movement (clip repertoires) every sequence along ``path`` is an example of, else ``None``."""
        label_of_path = getattr(self.motor, "label_of_path", None)
        return label_of_path(path) if label_of_path is not None else None

    def _movement_key(self, path: tuple[str, ...]) -> str:
        """What a candidate stands for: the labelled movement its sequences are examples of, else its first command."""
        label = self._path_label(path)
        return label if label is not None else path[0]

    def _known_continuation(self, path: tuple[str, ...]) -> tuple[str, ...]:
        """The whole learned command sequence that ``path`` begins, else ``path`` itself."""
        for edges in self.motor.sequences.values():
            if tuple(edges[: len(path)]) == path:
                return tuple(edges)
        return path

    def _mapped_time(self, stroke: Any, length: float) -> float:
        """The stroke time at which it has covered ``length`` metres of path (the speed-free forward model)."""
        grid, _, arc = self._table(stroke)
        return float(np.interp(min(length, arc[-1]), arc, grid))

    def _predict(self, path: tuple[str, ...], lengths: np.ndarray) -> np.ndarray:
        """Where each part of the subsystem should be after as much path as it has been observed to cover.

        The fingers of a hand share their timing (one transition function, §4.2): they are all predicted at the
        time at which the lead finger has covered its observed path, so fingers that move in another order than
        the command's do not fit it.
        """
        if self._hand:
            lead = self._lead(path[0])
            left = lengths[lead]
            for i, name in enumerate(path):
                commands = self._strokes_of(name)
                arc = self._table(commands[lead])[2]
                if left <= arc[-1] or i == len(path) - 1:
                    t = self._mapped_time(commands[lead], left)
                    return np.array([c.position(t) for c in commands])
                left -= arc[-1]
        out = []
        for j, left in enumerate(lengths):
            strokes = [self._strokes_of(e)[j] for e in path]
            for i, stroke in enumerate(strokes):
                _, positions, arc = self._table(stroke)
                if left <= arc[-1] or i == len(strokes) - 1:
                    x = min(left, arc[-1])
                    out.append([np.interp(x, arc, positions[:, d]) for d in range(3)])
                    break
                left -= arc[-1]
        return np.array(out)

    def _error(self, path: tuple[str, ...], lengths: np.ndarray, last: np.ndarray) -> float:
        """Distance between the path's prediction and the parts' last observed positions ``last`` (k, 3).

        The largest over the parts, or their mean (``error``); with ``relative`` the prediction is moved by
        the offset between the observed onset posture and the path's start.
        """
        return self._distance(self._predict(path, lengths) + self._onset_offset(path[0]), last)

    def _onset_offset(self, name: str) -> np.ndarray | float:
        """With ``relative``: the observed onset posture minus where command ``name`` starts (k, 3); else 0."""
        if not self.params["relative"]:
            return 0.0
        start = np.array([self._table(st)[1][0] for st in self._strokes_of(name)])
        return self.frames[0][self.motor.subsystems[self.subsystem]] - start

    def _distance(self, predicted: np.ndarray, observed: np.ndarray) -> float:
        """Per-part distances (k, 3 each) combined as ``error`` says: the largest or the mean (radians of a hand scaled)."""
        d = np.linalg.norm(predicted - observed, axis=-1) * self._scale
        return float(d.max() if self.params["error"] == "max" else d.mean())

    def _progress(self, name: str, lengths: np.ndarray) -> float:
        lead = self._lead(name)
        stroke = self._strokes_of(name)[lead]
        return self._mapped_time(stroke, lengths[lead]) / stroke.duration

    def _speed(self, name: str, lengths: np.ndarray, n_frames: int) -> float:
        """How much faster than the command the demonstration goes (1: same speed)."""
        lead = self._lead(name)
        stroke = self._strokes_of(name)[lead]
        elapsed = (n_frames - 1) / self.fps
        return float(np.clip(self._mapped_time(stroke, lengths[lead]) / max(elapsed, 1e-6), 0.25, 4.0))

    # -- the end of the demonstration ------------------------------------------------------------

    def conclude(self, motion: Motion) -> Match | None:
        if not getattr(self, "frames", None):
            self.begin(motion.fps)
            for f in range(motion.n_frames):
                self.observe(motion.positions[f], motion.visible[f])
        if self.subsystem is None:
            return Match.unknown(reason="nothing moved")
        if self.committed is not None and not self.deviated:
            end = self.motor.edge(self.committed_path[-1])[2]
            state = self.motor.graphs[self.subsystem].nodes[end]["state"]
            observed_end = self.frames[-1][self.motor.subsystems[self.subsystem]]
            expected = state + self._onset_offset(self.committed_path[0])
            if self._distance(expected, observed_end) <= self.params["deviation"]:
                self.motor.active[self.subsystem] = end
                return None  # already reported when it committed
            self.deviated = True  # it ended somewhere else: the committed command was not the right one
        start = self.start_node
        if self.deviated:
            self.motor.reset_to(self.subsystem, start)  # back to the last correct node
        if not self.params["learn"]:
            return Match.unknown(reason="no edge predicts the demonstration")
        observed = np.array(self.frames)[:, self.motor.subsystems[self.subsystem]]
        names = self._learn(observed, start)
        movement = self.motor.add_sequence(names)
        end = self.motor.edge(names[-1])[2]
        self.motor.active[self.subsystem] = end
        return Match(movement, 1.0, None, tuple(names),
                     details={"learned": names, "from": start, "to": end, "candidates": list(self.initial),
                              "deviated": self.deviated})

    def _learn(self, observed: np.ndarray, start: str) -> list[str]:
        """Cut the working memory into strokes and add one edge per stroke, chained from ``start``."""
        k = observed.shape[1]
        self._strokes.reset(tuple(f"p{i}" for i in range(k)), self.fps)
        return learn_commands(self.motor, self.subsystem, observed, self.fps, start, self._strokes.breaks)

    def match(self, motion: Motion) -> Match:
        """Batch use: the whole segment at once (no facilitation)."""
        self.begin(motion.fps)
        early = None
        for f in range(motion.n_frames):
            early = early or self.observe(motion.positions[f], motion.visible[f])
        late = self.conclude(motion)
        return late or early or Match.unknown()


@hookimpl
def likeme_register_matchers():
    return [ForwardModel]
