"""Speed (Kopp & Graeser 2006, §4.4): where along its command an edge predicts the demonstration, and how fast.

"If the demonstrated movement is in principle familiar to Max but now performed with a different speed, the
predictions of the corresponding forward model (or edge) will not be correct. [...] One solution to this problem is to
map the length of the movement seen so far onto the trajectory predicted by a forward model, yielding the time
parameter at which the corresponding motor command (with the speed demonstrated at first) would have produced a
movement of the same length. From this, the speed difference can be calculated and used to re-parameterize the
motor command."

The clock is a strategy chosen once, by ``reparameterise``:

- :class:`PathLength` (the default, the solution above): every part is predicted at the point of its command that
  has covered the path length it has been seen to cover, so a familiar movement performed faster or slower still
  fits; the speed is measured against the demonstration the edge was learned from (:func:`measure`) and the
  imitation performed at it. A commitment waits until the movement has been seen for three frames, so that its
  speed can be told from when it began. Every candidate is predicted at the same lengths: all at once.
- :class:`Elapsed` (the paper's baseline, Fig. 3 without it): an edge predicts at the time elapsed, at the speed it
  was learned, so a familiar movement at another speed is learned as new.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, Any

import numpy as np

from plugins.matchers.forward_model.path_length import arc, norms

if TYPE_CHECKING:
    from plugins.matchers.forward_model.matcher import ForwardModel
    from plugins.matchers.forward_model.tracks import Track

__all__ = ["Clock", "Elapsed", "PathLength", "measure", "shown"]

Path = tuple[str, ...]

SPEED_PARTS = 5
"""The most parts a speed is measured on (those that move farthest)."""

MIN_MOVING_FRAMES = 3
"""Frames of movement a speed is measured from (:meth:`PathLength.timed`)."""


class Clock(ABC):
    """How far along its commands a candidate path predicts each part of a subsystem (the strategy chosen by
    ``reparameterise``), and what follows from it: the candidates' errors and extensions, the speed of a commitment,
    and the frame at which the demonstration passed a node."""

    def __init__(self, model: ForwardModel) -> None:
        self.model = model

    @abstractmethod
    def along(self, track: Track, path: Path, lengths: np.ndarray, n: int) -> np.ndarray:
        """How far along ``path`` each part is predicted (path lengths from where the demonstration joined it), the
        parts having been seen to cover ``lengths`` in the ``n`` frames observed."""

    @abstractmethod
    def errors(self, track: Track, paths: list[Path], lengths: np.ndarray, n: int,
               last: np.ndarray) -> dict[Path, float]:
        """Every candidate path's prediction error against the parts' last observed positions ``last`` (k, 3)."""

    @abstractmethod
    def extended(self, track: Track, lengths: np.ndarray, n: int) -> list[Path]:
        """The candidate paths, those whose commands have all been covered continued along the next edges."""

    @abstractmethod
    def speed(self, track: Track, path: Path, n_frames: int) -> float:
        """How much faster than the commands of ``path`` the demonstration goes (1: the same speed)."""

    @abstractmethod
    def timed(self, track: Track, observed: np.ndarray) -> bool:
        """Whether enough of the movement has been seen to commit to it."""

    @abstractmethod
    def passed(self, track: Track, path: Path, on: int, observed: np.ndarray, ends: np.ndarray,
               joined: float) -> int:
        """The frame (since the track's onset) at which the demonstration passed the start of ``path[on]``: ``ends``
        are the path lengths of the lead part at the end of each edge of ``path``, ``joined`` where the lead joined
        its first command."""


class PathLength(Clock):
    """K&G §4.4's re-parameterisation: each part predicted at the path length it has been seen to cover."""

    def along(self, track, path, lengths, n):
        return lengths

    def errors(self, track, paths, lengths, n, last):
        return self.model.predictions.errors(track, paths, lengths, last)  # every candidate at once

    def extended(self, track, lengths, n):
        return self.model.predictions.extended(track, lengths)

    def speed(self, track, path, n_frames):
        """:func:`measure` (1 with fewer than three frames)."""
        if n_frames < 3:
            return 1.0
        m = self.model
        observation = m.observation
        arcs = m.tables.edge(path[0]).arcs[:, -1]
        parts = np.argsort(-arcs)[:SPEED_PARTS]  # the parts that move farthest (a hand: every finger)
        idx = m.motor.subsystems[track.subsystem][parts]  # the rows in the motor frame, as the observation places them
        seen = observation.memory.positions[track.onset: track.onset + n_frames, idx] + observation.root_height[idx]
        if not np.isfinite(seen).all():
            return 1.0
        return measure(seen, *shown(m.motor, path, parts), m.fps)

    def timed(self, track, observed):
        """:data:`MIN_MOVING_FRAMES` frames on which the subsystem's parts are away from where they were at the onset
        by more than a quarter of ``min_move`` (with one or two, how fast it goes and when it began cannot be told
        apart). A commitment waits for them: a frame or two, for a fast movement."""
        away = norms(observed - observed[0]).max(axis=1) * track.scale
        return int((away > 0.25 * self.model.params["min_move"]).sum()) >= MIN_MOVING_FRAMES

    def passed(self, track, path, on, observed, ends, joined):
        """Where the lead part's path length walked (positions averaged over three frames) reaches the node."""
        from scipy.ndimage import uniform_filter1d

        lead = self.model.tables.lead(path[0])
        walked = arc(uniform_filter1d(observed[:, lead], size=3, axis=0, mode="nearest"))
        return int(np.searchsorted(walked, ends[on - 1] - joined))


class Elapsed(Clock):
    """The paper's baseline: each part predicted at the time elapsed, its commands at the speed they were learned."""

    def along(self, track, path, lengths, n):
        """The path length the part's commands cover, at their own speed, in the time the ``n`` frames observed
        took, from where the demonstration joined the path (:meth:`Anchors.anchor
        <plugins.matchers.forward_model.anchors.Anchors.anchor>`)."""
        m = self.model
        tables = m.tables
        elapsed = (n - 1) / m.fps
        anchor = m.anchors.anchor(track, path[0])
        out = np.empty(len(lengths))
        for p in range(len(lengths)):
            t = tables.mapped_time(tables.strokes_of(path[0])[p], anchor[p]) + elapsed
            covered = 0.0
            for i, name in enumerate(path):
                edge = m.motor.edge(name)
                grid, _, a = tables.table(edge.commands[p])
                if t <= edge.duration or i == len(path) - 1:
                    covered += float(np.interp(t, grid, a))
                    break
                t -= edge.duration
                covered += float(a[-1])
            out[p] = covered - anchor[p]
        return out

    def errors(self, track, paths, lengths, n, last):
        predictions = self.model.predictions
        return {path: predictions.error(track, path, self.along(track, path, lengths, n), last) for path in paths}

    def extended(self, track, lengths, n):
        return self.model.predictions.extended(track, lengths, lambda path: self.along(track, path, lengths, n))

    def speed(self, track, path, n_frames):
        """1: a command is predicted at the speed it was learned."""
        return 1.0

    def timed(self, track, observed):
        return True

    def passed(self, track, path, on, observed, ends, joined):
        """When the commands, at their own speed, reached the node."""
        m = self.model
        tables = m.tables
        lead = tables.lead(path[0])
        reached = sum(m.motor.edge(e).duration for e in path[:on])
        return int(round((reached - tables.mapped_time(tables.strokes_of(path[0])[lead], joined)) * m.fps))


def measure(seen: np.ndarray, times: np.ndarray, points: np.ndarray, first: float, fps: float) -> float:
    """How much faster than a path of commands a demonstration goes (1: same speed), K&G §4.4's speed difference.

    ``seen`` (n, p, 3): the parts' positions in the ``n`` frames observed since the track's onset (at ``fps``);
    ``times`` (M,) and ``points`` (M, p, 3): the path as it was first demonstrated (:func:`shown`), ``first`` the
    time its first edge ends. The frames are matched with the path played from time ``c`` at ``s`` times its
    speed, each part taken relative to its mean over the frames (so a stance unlike one's own does not count), in
    the least squares sense. ``s`` is the speed factor: first the best of a grid on the first part (the one that
    moves farthest; ``s`` from 0.25 to 4 in steps of 12%, ``c`` from half a second before the path's start to the
    end of its first edge, a frame apart), then refined on every part by three grids about the best, each five
    times finer (to 0.1% of speed). Positions, not path lengths walked, are compared: observation noise adds length
    at every frame, and smoothing it away would stretch the movement's onset by the same frames whatever its speed.
    """
    n_frames = len(seen)
    seen = seen - seen.mean(axis=0)
    t = np.arange(n_frames) / fps
    flat = points.reshape(len(points), -1)

    def played(c: np.ndarray, s: np.ndarray, columns: int) -> np.ndarray:  # (G,) starts, speeds -> (G, n, m)
        q = (c[:, None] + s[:, None] * t).ravel()
        out = np.stack([np.interp(q, times, flat[:, d]) for d in range(columns)], axis=-1)
        out = out.reshape(len(c), len(t), columns)
        return out - out.mean(axis=1, keepdims=True)  # centred

    seen = seen.reshape(n_frames, -1)
    # the grid on the part that moves farthest, every 1/fps of start and 12% of speed; refined on every part
    speeds = np.geomspace(0.25, 4.0, 25)
    starts = np.arange(-0.5, first + 1.0 / fps, 1.0 / fps)
    c, s = (a.ravel() for a in np.meshgrid(starts, speeds))
    best = int(np.argmin(((played(c, s, 3) - seen[:, :3]) ** 2).sum(axis=(1, 2))))
    c0, s0, dc, ds = c[best], s[best], 1.0 / fps, np.log(speeds[1] / speeds[0])
    for _ in range(3):  # finer grids about the best, on every part: each a fifth of the step before
        cs, ls = np.meshgrid(c0 + dc * np.linspace(-1, 1, 11), np.log(s0) + ds * np.linspace(-1, 1, 11))
        cs, ss = cs.ravel(), np.clip(np.exp(ls.ravel()), 0.25, 4.0)
        best = int(np.argmin(((played(cs, ss, seen.shape[1]) - seen) ** 2).sum(axis=(1, 2))))
        c0, s0, dc, ds = cs[best], ss[best], dc / 5, ds / 5
    return float(s0)


def shown(motor: Any, path: Path, parts: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """The trajectories of ``parts`` (indices into the subsystem's parts) along ``path`` as it was first
    demonstrated ("the motor command (with the speed demonstrated at first)"): times (M,) and positions (M, p, 3),
    the edges laid end to end, and the time the first edge ends. An edge learned by watching keeps the piece of the
    demonstration it was learned from (``Edge.shown``); one without it (written by hand, or saved without) stands for
    its commands played at their own speed, each part holding its target once its command has ended."""
    times, points, t0, first = [], [], 0.0, 0.0
    for i, name in enumerate(path):
        edge = motor.edge(name)
        demonstrated = getattr(edge, "shown", None)
        if demonstrated is not None and getattr(edge, "shown_fps", 0.0) > 0:
            p, t = demonstrated[:, parts], np.arange(len(demonstrated)) / edge.shown_fps
        else:
            t = np.linspace(0.0, edge.duration, max(2, int(np.ceil(edge.duration * 120.0)) + 1))
            p = np.stack([edge.commands[j].position(np.minimum(t, edge.commands[j].duration)) for j in parts],
                         axis=1)
        times.append(t + t0)
        points.append(p)
        t0 += float(t[-1])
        if i == 0:
            first = t0
    times_all, points_all = np.concatenate(times), np.concatenate(points)
    keep = np.append(np.diff(times_all) > 1e-9, True)  # where two edges meet, the later's first frame
    return times_all[keep], points_all[keep], first
