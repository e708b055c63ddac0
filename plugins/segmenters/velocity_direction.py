"""Segmenter ``velocity-direction``: break points at speed minima and at changes of movement direction.

Kopp & Graeser 2006, §4.1 and §4.3. A *sensory memory* of about a tenth of a
second detects the onset and the end of a movement (the chosen parts start or
stop moving); a *visual working memory* holds the positions and movement
vectors of the movement under consideration. When the movement ends it is
segmented in two ways:

- *speed*: local minima of the speed that fall below ``drop`` times the smaller
  of their neighbouring maxima are break points (a minimum that stays high
  relative to its surroundings belongs to one curved stroke);
- *direction*: the normalised movement vectors are clustered divisively (one
  cluster; while some vector differs from its cluster's mean direction by more
  than ``angle`` degrees, it founds a new cluster and all vectors are
  redistributed to the nearest mean, until every cluster is tight); a break
  point lies where two successive vectors fall into different clusters and the
  direction turns there by at least half of ``angle`` within a tenth of a second
  ("a significant change in movement direction compared to the overall
  curvature": a smooth C stroke crosses clusters gradually and is not cut), at
  a minimum of the speed below ``corner`` times its neighbouring maxima (an S
  stroke swings its direction at full speed and is not cut either).

Segments shorter than ``min_stroke`` seconds are merged into their neighbour.
With ``level = "movement"`` the segmenter reports whole movements (onset to
end, as the sensory memory finds them) instead of strokes.

It reads any body's pose stream: ``parts`` names the parts whose velocity is
used (the wrists and fingers for Max and Moritz; all parts when empty). Hidden
parts do not move; a frame with none of the parts visible carries no evidence.

Hands (§4.3): a finger of the observer's body (an angle part, whose values
are joint angles) moves at an *angular* velocity. Its angles are multiplied by
``angle_scale`` (metres per radian) as they enter the memories, so one rest
speed, one drop criterion and one direction clustering serve wrists and
fingers: a hand movement is cut at the minima of its angular velocity and
where its direction in joint-angle space changes cluster.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.signal import argrelextrema, savgol_filter

from toolkit import ConfigError, Parameter, Segment, Segmenter, hookimpl

__all__ = ["VelocityDirection", "StrokeAnalysis", "speed_breaks", "direction_clusters", "direction_breaks"]


def speed_breaks(speed: np.ndarray, drop: float, moving: float = 0.0) -> list[int]:
    """Indices of speed minima below ``drop`` times the smaller of the highest speeds on either side.

    A minimum is no higher than the two samples on each side of it. A hold counts once, at its middle: a run
    of such samples, or minima with nothing faster than ``moving`` (the rest speed) between them (the ripples
    of a pause). A side reaches to the neighbouring minimum or to the end of the movement, so a movement that
    starts or ends at full speed still brackets its minima; both sides must rise above ``moving``, so a dip
    between two flickers of noise at rest separates no strokes.
    """
    speed = np.asarray(speed, dtype=float)
    n = len(speed)
    if n < 3:
        return []
    low = argrelextrema(speed, np.less_equal, order=2)[0]
    low = low[(low >= 2) & (low <= n - 3)]  # two samples on each side, inside the movement
    if not len(low):
        return []
    holds = [[int(low[0])]]
    for m in low[1:]:
        previous = holds[-1][-1]
        if m == previous + 1 or speed[previous : m + 1].max() <= moving:
            holds[-1].append(int(m))
        else:
            holds.append([int(m)])
    minima = [(h[0] + h[-1]) // 2 for h in holds]
    bounds = [0, *(h[-1] for h in holds[:-1])], [*(h[0] for h in holds[1:]), n - 1]  # the neighbouring holds
    out = []
    for i, (m, hold) in enumerate(zip(minima, holds)):
        left, right = speed[bounds[0][i] : hold[0] + 1].max(), speed[hold[-1] : bounds[1][i] + 1].max()
        side = min(left, right)
        if speed[hold].min() < drop * side and side > moving:
            out.append(m)
    return out


def direction_clusters(vectors: np.ndarray, angle: float, max_clusters: int = 12) -> np.ndarray:
    """Divisive clustering of unit movement vectors (N, D); returns a cluster label per vector."""
    n = len(vectors)
    if n == 0:
        return np.zeros(0, dtype=int)
    cos_limit = np.cos(np.radians(angle))
    means = [_unit(vectors.mean(axis=0))]
    for _ in range(4 * max_clusters):
        sims = vectors @ np.array(means).T
        labels = np.argmax(sims, axis=1)
        best = sims[np.arange(n), labels]
        worst = int(np.argmin(best))
        if best[worst] >= cos_limit or len(means) >= max_clusters:
            break
        means.append(vectors[worst].copy())  # a new cluster around the most different element
        for _ in range(10):  # redistribute and re-average until stable
            labels = np.argmax(vectors @ np.array(means).T, axis=1)
            new = [_unit(vectors[labels == k].mean(axis=0)) if np.any(labels == k) else means[k] for k in range(len(means))]
            if np.allclose(new, means):
                break
            means = new
    return np.argmax(vectors @ np.array(means).T, axis=1)


def direction_breaks(labels: np.ndarray) -> list[int]:
    """Indices where two successive vectors fall into different clusters."""
    return [int(i) for i in np.flatnonzero(np.diff(labels) != 0) + 1]


@dataclass(frozen=True)
class StrokeAnalysis:
    """How one movement's working memory was cut into strokes (indices are frames into the movement).

    ``window``: the (smoothed) positions (N, 3k); ``speed``: the speed of the fastest chosen part between
    successive frames (N - 1,); ``clusters``: the direction cluster of each movement vector (-1: none, at rest);
    ``speed_breaks`` and ``direction_breaks``: the candidates each criterion found; ``breaks``: the ones kept.
    """

    window: np.ndarray
    speed: np.ndarray
    clusters: np.ndarray
    speed_breaks: list[int]
    direction_breaks: list[int]
    breaks: list[int]


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v)
    return v / n if n > 1e-12 else v


class VelocityDirection(Segmenter):
    """Break points at significant speed minima and where the movement direction changes cluster (K&G §4.3)."""

    name = "velocity-direction"
    parameters = (
        Parameter("parts", list, [], "Parts whose velocity is used (the wrists...); empty: every part.", items=str),
        Parameter("rest_speed", float, 0.08, "Speed (m/s, over the sensory memory) below which the parts are at rest.", minimum=0.0),
        Parameter("memory", float, 0.1, "Seconds of the sensory memory: how long motion (or rest) must last to count "
                  "as the onset (or the end) of a movement.", minimum=0.0),
        Parameter("drop", float, 0.5, "A speed minimum is a break point when below this share of its neighbouring "
                  "maxima. Higher cuts more, lower only at near stops.", minimum=0.0, maximum=1.0),
        Parameter("angle", float, 50.0, "Degrees between movement directions that makes a new direction cluster.",
                  minimum=1.0, maximum=180.0),
        Parameter("corner", float, 0.9, "A direction break needs a speed minimum within 0.1 s that is below this "
                  "share of its neighbouring maxima (a gentler dip than `drop`).", minimum=0.0, maximum=1.0),
        Parameter("min_stroke", float, 0.15, "Shortest stroke (s); shorter pieces merge with a neighbour.", minimum=0.0),
        Parameter("smooth", float, 0.2, "Seconds of Savitzky-Golay smoothing of the working memory before it is "
                  "segmented (0: none).", minimum=0.0),
        Parameter("angle_scale", float, 0.25, "Metres one radian of a finger's joint angles counts as (0.25: a finger "
                  "turning at 0.6 rad/s moves as fast as a wrist at 0.15 m/s).", minimum=0.0),
        Parameter("level", str, "stroke", "Report strokes (break points) or whole movements (onset to end).",
                  choices=("stroke", "movement")),
    )

    record: list[tuple[int, int, StrokeAnalysis]] | None = None
    """Set to a list to keep ``(start, end, analysis)`` of every movement the working memory closes (for plots)."""

    def reset(self, parts: Sequence[str], fps: float) -> None:
        parts = tuple(parts)
        chosen = self.params["parts"] or list(parts)
        missing = [p for p in chosen if p not in parts]
        if missing:
            raise ConfigError(f"parts {missing} are not in the observed body", key=("parts",),
                              expected="parts of the observed body", available=list(parts))
        self._idx = np.array([parts.index(p) for p in chosen])
        body = getattr(self.owner, "body", None)
        angles = set(body.angle_parts) if body is not None else set()
        self._scale = np.array([self.params["angle_scale"] if p in angles else 1.0 for p in chosen])[:, None]
        self._fps = float(fps)
        self._frame = -1
        self._prev: np.ndarray | None = None
        self._memory = max(1, int(round(self.params["memory"] * self._fps)))
        self._moving = 0
        self._resting = 0
        self._start: int | None = None
        self._buffer: list[np.ndarray] = []  # working memory: positions of the chosen parts since onset
        self._history: deque[np.ndarray] = deque(maxlen=2 * self._memory + 2)  # the sensory memory

    @property
    def active_since(self) -> int | None:
        return self._start

    def push(self, pose: np.ndarray, visible: np.ndarray) -> list[Segment]:
        self._frame += 1
        points = np.where(visible[self._idx, None], pose[self._idx] * self._scale, np.nan)
        seen = np.isfinite(points).all(axis=1)
        if self._prev is not None:
            points = np.where(seen[:, None], points, self._prev)  # a hidden part keeps its last position
        self._prev = points
        self._history.append(points.ravel())
        speed = np.nan
        if len(self._history) > self._memory and seen.any():
            # displacement over the sensory memory: steady against noise, as fast as the memory is short
            moved = (self._history[-1] - self._history[-1 - self._memory]).reshape(-1, 3)
            step = np.linalg.norm(moved, axis=1)
            step = step[np.isfinite(step)]
            speed = float(step.max()) * self._fps / self._memory if step.size else np.nan
        if self._start is not None:
            self._buffer.append(points.ravel())
        if np.isnan(speed):
            return []
        if speed > self.params["rest_speed"]:
            self._moving += 1
            self._resting = 0
            if self._start is None and self._moving >= self._memory:
                self._start = max(0, self._frame - 2 * self._memory)
                self._buffer = list(self._history)[-(self._frame - self._start + 1):]
        else:
            self._resting += 1
            self._moving = 0
            if self._start is not None and self._resting >= self._memory:
                return self._close(max(self._start + 1, self._frame - self._resting + 1 - self._memory // 2))
        return []

    def flush(self) -> list[Segment]:
        if self._start is None:
            return []
        return self._close(self._frame + 1)

    def _close(self, end: int) -> list[Segment]:
        start, self._start = self._start, None
        window = np.array(self._buffer[: end - start])
        self._buffer = []
        if end - start < 2:
            return []
        if self.params["level"] == "movement" and self.record is None:
            return [Segment(start, end, self._fps)]
        analysis = self.analyse(window)
        if self.record is not None:
            self.record.append((start, end, analysis))
        if self.params["level"] == "movement":
            return [Segment(start, end, self._fps)]
        cuts = analysis.breaks
        edges = [0, *cuts, end - start]
        return [Segment(start + a, start + b, self._fps) for a, b in zip(edges, edges[1:]) if b > a]

    def breaks(self, window: np.ndarray) -> list[int]:
        """Break points (indices into ``window``, positions (N, 3k) of the chosen parts) by speed and direction."""
        return self.analyse(window).breaks

    def analyse(self, window: np.ndarray) -> StrokeAnalysis:
        """The working memory of one movement (positions (N, 3k) of the chosen parts) analysed for break points.

        Speed minima below ``drop`` of their neighbouring maxima cut; direction-cluster changes cut where the
        direction turns sharply at a dip of the speed (see the module). Pieces shorter than ``min_stroke`` merge.
        """
        n = len(window)
        empty = np.zeros(max(0, n - 1))
        if n < 4:
            return StrokeAnalysis(np.asarray(window, dtype=float), empty, np.full(len(empty), -1), [], [], [])
        smooth = int(round(self.params["smooth"] * self._fps)) | 1
        if smooth >= 5 and n > smooth:
            window = savgol_filter(window, smooth, 2, axis=0, mode="interp")
        vectors = np.diff(window, axis=0)
        speed = np.linalg.norm(vectors.reshape(len(vectors), -1, 3), axis=2).max(axis=1) * self._fps
        moving = speed > self.params["rest_speed"]
        by_speed = sorted(b + 1 for b in speed_breaks(speed, self.params["drop"], self.params["rest_speed"]))
        cuts = set(by_speed)
        by_direction: list[int] = []
        units = np.array([_unit(v) for v in vectors])
        labels = np.full(len(units), -1)
        if moving.any():
            labels[moving] = direction_clusters(units[moving], self.params["angle"])
            for i in range(1, len(labels)):  # slow vectors take the cluster of the one before
                if labels[i] < 0:
                    labels[i] = labels[i - 1]
            k = max(2, int(round(0.1 * self._fps)))
            dips = np.array(speed_breaks(speed, self.params["corner"], self.params["rest_speed"]), dtype=int) + 1
            for b in direction_breaks(labels):
                # a cluster change inside one stroke is no break: the direction must turn sharply there, at a dip
                # of the speed (a C stroke turns gradually, an S stroke swings its direction at full speed)
                before, after = _unit(vectors[max(0, b - k) : b].sum(axis=0)), _unit(vectors[b : b + k].sum(axis=0))
                sharp = np.degrees(np.arccos(np.clip(before @ after, -1.0, 1.0))) >= 0.5 * self.params["angle"]
                near = dips[np.abs(dips - b) <= k]
                if sharp and near.size:
                    by_direction.append(int(near[np.argmin(np.abs(near - b))]))
        cuts.update(by_direction)
        shortest = max(1, int(round(self.params["min_stroke"] * self._fps)))
        kept: list[int] = []
        for c in sorted(cuts):
            if c - (kept[-1] if kept else 0) >= shortest and n - c >= shortest:
                kept.append(c)
        return StrokeAnalysis(window, speed, labels, by_speed, sorted(set(by_direction)), kept)


@hookimpl
def likeme_register_segmenters():
    return [VelocityDirection]
