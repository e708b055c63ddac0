"""Segmenter ``velocity-direction``: break points at speed minima and at changes of movement direction.

Kopp & Graeser 2006, §4.1 and §4.3. A *sensory memory* of about a tenth of a
second detects the onset and the end of a movement (the chosen parts start or
stop moving); a *visual working memory* holds the positions and movement
vectors of the movement under consideration. When the movement ends it is
segmented in two ways (the stroke analysis of :mod:`plugins.lib.strokes`):

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
parts hold their last seen position (``docs/conventions.md``), so they do not
move; a part not seen yet carries no evidence.

Hands (§4.3): a finger of the observer's body (an angle part, whose values
are joint angles) moves at an *angular* velocity. Its angles are multiplied by
``angle_scale`` (metres per radian) as they enter the memories, so one rest
speed, one drop criterion and one direction clustering serve wrists and
fingers: a hand movement is cut at the minima of its angular velocity and
where its direction in joint-angle space changes cluster.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping, Sequence
from types import MappingProxyType
from typing import Any

import numpy as np

from plugins.lib.strokes import StrokeAnalysis, StrokeCriteria, analyse
from toolkit import ConfigError, Parameter, Segment, Segmenter, hookimpl

__all__ = ["VelocityDirection"]


class VelocityDirection(Segmenter):
    """Break points at significant speed minima and where the movement direction changes cluster (K&G §4.3)."""

    name = "velocity-direction"
    parameters = (
        Parameter("parts", list, [], "Parts whose velocity is used (the wrists...); empty: every part.", items=str),
        Parameter("rest_speed", float, 0.08, "Speed (m/s, over the sensory memory) below which the parts are at rest.", minimum=0.0, length=True),
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
                  "turning at 0.6 rad/s moves as fast as a wrist at 0.15 m/s).", minimum=0.0, length=True),
        Parameter("level", str, "stroke", "Report strokes (break points) or whole movements (onset to end).",
                  choices=("stroke", "movement")),
    )

    def attach(self, owner: Any) -> None:
        super().attach(owner)
        for i, part in enumerate(self.params["parts"]):
            owner.body.index(part, key=("parts", i))

    @property
    def criteria(self) -> StrokeCriteria:
        """The stroke analysis's criteria, from this segmenter's parameters."""
        p = self.params
        return StrokeCriteria(p["rest_speed"], p["drop"], p["angle"], p["corner"], p["min_stroke"], p["smooth"])

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
        self._memory = max(1, int(round(self.params["memory"] * self._fps)))
        self._moving = 0
        self._resting = 0
        self._start: int | None = None
        self._buffer: list[np.ndarray] = []  # working memory: positions of the chosen parts since onset
        self._history: deque[np.ndarray] = deque(maxlen=2 * self._memory + 2)  # the sensory memory
        self._last: tuple[int, int, np.ndarray] | None = None  # the last movement closed: start, end, working memory
        self._analysis: StrokeAnalysis | None = None

    @property
    def active_since(self) -> int | None:
        return self._start

    def push(self, pose: np.ndarray, visible: np.ndarray) -> list[Segment]:
        self._frame += 1
        points = pose[self._idx] * self._scale  # hidden parts are held where last seen; never seen: NaN
        seen = np.isfinite(points).all(axis=1)
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
        self._last, self._analysis = (start, end, window), None
        if self.params["level"] == "movement":
            return [Segment(start, end, self._fps)]
        cuts = self.analyse(window).breaks
        edges = [0, *cuts, end - start]
        return [Segment(start + a, start + b, self._fps) for a, b in zip(edges, edges[1:]) if b > a]

    def analyse(self, window: np.ndarray) -> StrokeAnalysis:
        """One movement's working memory (positions (N, 3k) of the chosen parts) cut into strokes by this
        segmenter's criteria (:func:`plugins.lib.strokes.analyse`)."""
        return analyse(window, self._fps, self.criteria)

    def inspect(self) -> Mapping[str, Any]:
        """The last movement the working memory closed: ``{"movement": (start, end), "analysis": StrokeAnalysis}``
        (its strokes' speed, direction clusters and break points; computed when asked), or empty before one."""
        if self._last is None:
            return MappingProxyType({})
        start, end, window = self._last
        if self._analysis is None:
            self._analysis = self.analyse(window)
        return MappingProxyType({"movement": (start, end), "analysis": self._analysis})


@hookimpl
def likeme_register_segmenters():
    return [VelocityDirection]
