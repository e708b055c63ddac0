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

Real people (the correspondence problem, K&G §6): the paper's rest is an absolute speed, which a noisy tracker
never falls below and a large body's sway may exceed. Each of these is a parameter, off by default (the paper):

- ``units = "body"``: the rest speed is ``size_rest_speed`` of the demonstrator's own body sizes per second
  (:func:`plugins.lib.body_size.body_scale` of the poses seen, a running mean: about 0.45 m for a standing adult,
  0.20 m for Max). 0.1 body sizes/s (4.5 cm/s on an adult) lies between standing sway (1-2 cm/s) and a gesture
  (tens of cm/s).
- ``noise = k > 0``: the rest speed is at least ``k`` times the slowest the demonstrator has been over the last
  ``floor`` seconds (their own speed distribution: sway plus the tracker's noise, whatever their units). ``k = 2``:
  the speed of a body at rest fluctuates around its level, so twice the lowest is still rest, and a gesture is
  many times faster.
- ``pause = p > 0``: the speed is averaged over the last ``p`` seconds before it is compared with the rest speed,
  so a movement begins and ends only at a *real rest* of about ``p`` seconds: a velocity minimum between two
  strokes lasts about a tenth of a second (the sensory memory, §4.1) and no longer ends the movement. ``p = 0.3``
  s: three sensory memories, shorter than the pauses people make between gestures.
- ``end = "rest"``: a rest ends the movement under way only where the demonstrator is back near the pose it began
  from (within ``rest_radius`` body sizes, eq. 1's mean distance of the chosen parts; the pose is the first of the
  working memory, so a stooped or wide-legged stance is their own rest), or once they have rested ``settle``
  seconds elsewhere (a new stance; the movement then ends where that rest began). A gesture that holds a pose
  half-way (a salute, a bow, a pointing hand) is one movement, not two: B&B's hubs are the poses movements leave and
  come back to, and K&G's forward model follows the whole performance between rests through the motor command
  graph. ``rest_radius = 0.1``: B&B's hub threshold (0.02 m on Max, 0.20 m body size); ``settle = 2`` s: longer
  than a gesture holds a pose (about a second), as ``hub-threshold``'s ``settle``. The paper's ``"still"`` (any
  rest ends it) is the default.

Memory: the visual working memory holds the movement under way, so a movement that never ends (a demonstrator who
never comes to rest) is closed after ``max_movement`` seconds, where it is, and the next one begins at once there:
the segmenter's memory is bounded whatever the stream. The default, 60 s, is the watching loop's own bound
(:data:`toolkit.watching.MAX_SEGMENT_SECONDS`), ten times the longest of the papers' movements.

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

from plugins.lib.body_size import body_scale
from plugins.lib.strokes import StrokeAnalysis, StrokeCriteria, _round_kernels, analyse, breaks
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
        Parameter("units", str, "metres", "The rest speed in m/s (`rest_speed`, the paper) or in the demonstrator's "
                  "body sizes per second (`size_rest_speed`).", choices=("metres", "body")),
        Parameter("size_rest_speed", float, 0.1, "With units = body: the rest speed in body sizes per second (the "
                  "root-mean-square distance of the parts from their centroid, running mean over the poses seen).",
                  minimum=0.0),
        Parameter("noise", float, 0.0, "The rest speed is at least this many times the slowest the demonstrator "
                  "has been over the last `floor` seconds (0: off, the paper).", minimum=0.0),
        Parameter("floor", float, 10.0, "Seconds over which the slowest speed is taken for `noise`.", minimum=0.1),
        Parameter("pause", float, 0.0, "Seconds the speed is averaged over before it is compared with the rest "
                  "speed: a movement begins and ends at a rest of about this long (0: the sensory memory, the "
                  "paper).", minimum=0.0),
        Parameter("end", str, "still", "Where a movement ends: at any rest (`still`, the paper) or only at a rest "
                  "near the pose it began from, or after `settle` seconds of rest elsewhere (`rest`).",
                  choices=("still", "rest")),
        Parameter("rest_radius", float, 0.1, "With end = rest: how near (eq. 1's mean distance of the chosen parts, "
                  "in the demonstrator's body sizes) the pose must be to the one the movement began from for a rest "
                  "to end it (0.1: B&B's hub threshold, 0.02 m on Max).", minimum=0.0),
        Parameter("settle", float, 2.0, "With end = rest: seconds of rest away from where the movement began after "
                  "which it ends anyway (a new stance: longer than a gesture holds a pose).", minimum=0.0),
        Parameter("max_movement", float, 60.0, "Seconds after which a movement that has not ended is closed there and "
                  "the next begins at once (the working memory's bound; 0: none).", minimum=0.0),
    )

    def attach(self, owner: Any) -> None:
        super().attach(owner)
        import scipy.signal  # noqa: F401  the stroke analysis's filters: loaded now, not at the end of the first movement

        _round_kernels()  # the direction clustering's compiled rounds: compiled or loaded now, not at a movement's end
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
        self._done = 0  # the end of the last movement reported: a movement begins no earlier
        self._analysis: StrokeAnalysis | None = None
        self._pause = max(self._memory, int(round(self.params["pause"] * self._fps))) if self.params["pause"] > 0 else 0
        self._speeds: deque[float] = deque(maxlen=max(1, self._pause))  # for the mean over `pause`
        self._slowest: deque[tuple[int, float]] = deque()  # monotonic queue: the running minimum over `floor`
        self._floor = max(1, int(round(self.params["floor"] * self._fps)))
        self._positions = ~np.array([p in angles for p in parts]) if parts else np.zeros(0, bool)
        self._size_sum, self._size_n = 0.0, 0
        self._origin: tuple[np.ndarray, float] | None = None  # end = rest: the chosen parts where the movement began,
        # and the body's size then
        self._settle = max(1, int(round(self.params["settle"] * self._fps)))

    @property
    def active_since(self) -> int | None:
        return self._start

    def push(self, pose: np.ndarray, visible: np.ndarray) -> list[Segment]:
        self._frame += 1
        points = pose[self._idx] * self._scale  # hidden parts are held where last seen; never seen: NaN
        points[~np.isfinite(points)] = np.nan  # an infinite value is not seen either (no inf - inf below)
        seen = np.isfinite(points).all(axis=1)
        self._history.append(points.ravel())
        speed = np.nan
        if len(self._history) > self._memory and seen.any():
            # displacement over the sensory memory: steady against noise, as fast as the memory is short
            moved = (self._history[-1] - self._history[-1 - self._memory]).reshape(-1, 3)
            step = np.linalg.norm(moved, axis=1)
            step = step[np.isfinite(step)]
            speed = float(step.max()) * self._fps / self._memory if step.size else np.nan
        return self._step(pose, points.ravel(), speed)

    def push_block(self, poses: np.ndarray, visible: np.ndarray) -> tuple[list[tuple[int, Segment]], np.ndarray]:
        """What ``n`` calls of :meth:`push` give, with the per-frame evidence (the chosen parts' speeds over the
        sensory memory) computed for the block at once, the same arithmetic element by element; the onset and end
        of movements are then followed frame by frame (:meth:`_step`)."""
        n = len(poses)
        closed: list[tuple[int, Segment]] = []
        since = np.full(n, -1, dtype=int)
        if n == 0:
            return closed, since
        points = np.asarray(poses)[:, self._idx] * self._scale  # (n, m, 3)
        points[~np.isfinite(points)] = np.nan  # an infinite value is not seen either (no inf - inf below)
        flat = points.reshape(n, -1)
        seen = np.isfinite(points).all(axis=2).any(axis=1)  # some chosen part seen
        m, before = self._memory, len(self._history)  # frames of the sensory memory before the block
        rows = np.concatenate([np.array(self._history).reshape(before, -1), flat]) if before else flat
        speeds = np.full(n, np.nan)
        # frame i of the block has i + before + 1 frames of history (at most maxlen: enough for the memory)
        ok = seen & (np.minimum(np.arange(n) + before + 1, self._history.maxlen) > m)
        if ok.any():
            i = np.flatnonzero(ok)
            moved = (rows[i + before] - rows[i + before - m]).reshape(len(i), -1, 3)
            step = np.linalg.norm(moved, axis=2)
            finite = np.isfinite(step)
            best = np.where(finite, step, -np.inf).max(axis=1)
            speeds[i] = np.where(finite.any(axis=1), best * self._fps / m, np.nan)
        p = self.params
        if p["units"] == "metres" and not self._pause and not p["noise"] > 0 and p["end"] == "still":  # a fixed rest
            # speed, and any rest ends a movement
            return self._follow(flat, speeds)
        for f in range(n):
            self._frame += 1
            self._history.append(flat[f])
            closed.extend((f, s) for s in self._step(poses[f], flat[f], float(speeds[f])))
            if self._start is not None:
                since[f] = self._start
        return closed, since

    def _follow(self, flat: np.ndarray, speeds: np.ndarray) -> tuple[list[tuple[int, Segment]], np.ndarray]:
        """:meth:`_step` for every frame of a block (rows ``flat`` (n, 3m), ``speeds`` (n,)) with a fixed rest speed
        (``units = "metres"``, no ``pause``, no ``noise``): the same onsets, ends and cuts at the same frames,
        found from the block's arrays instead of frame by frame.

        ``_step`` counts the frames faster (slower) than the rest speed since the last slower (faster) one, at every
        frame whatever the movement; a movement begins at a fast frame whose count reaches the sensory memory, ends
        at a slow one whose count does, and is cut ``max_movement`` after its start. So the counts are computed for
        the block at once, and only the frames where something happens are visited."""
        n = len(flat)
        closed: list[tuple[int, Segment]] = []
        since = np.full(n, -1, dtype=int)
        first = self._frame + 1  # the block's first frame
        valid = ~np.isnan(speeds)  # no speed: the counts stay as they are
        fast = valid & (speeds > self.params["rest_speed"])
        slow = valid & ~fast
        rows = np.arange(n)
        fast_run, slow_run = np.cumsum(fast), np.cumsum(slow)
        last_slow = np.maximum.accumulate(np.where(slow, rows, -1))
        last_fast = np.maximum.accumulate(np.where(fast, rows, -1))
        moving = np.where(last_slow >= 0, fast_run - fast_run[np.maximum(last_slow, 0)], self._moving + fast_run)
        resting = np.where(last_fast >= 0, slow_run - slow_run[np.maximum(last_fast, 0)], self._resting + slow_run)
        m = self._memory
        onsets = np.flatnonzero(fast & (moving >= m))
        ends = np.flatnonzero(slow & (resting >= m))
        longest = int(round(self.params["max_movement"] * self._fps))
        longest = max(longest, 2) if longest else 0
        before = list(self._history)  # the sensory memory before the block
        f = 0
        while f < n:
            if self._start is None:  # the next onset
                i = np.searchsorted(onsets, f)
                if i == len(onsets):
                    break
                g = int(onsets[i])
                frame = first + g
                # back-dated to where the motion began, but not into a movement already reported
                self._start = start = max(self._done, frame - 2 * m)
                recent = before + list(flat[max(0, g - 2 * m) : g + 1])  # the sensory memory at frame g
                self._buffer = recent[-(frame - start + 1):]
                since[g] = start
                f = g + 1
                continue
            start = self._start
            cut = max(start + longest - first, f) if longest else n  # the frame where it has lasted max_movement
            i = np.searchsorted(ends, f)
            e = int(ends[i]) if i < len(ends) else n
            if e < cut and e < n:  # it ends (rest for the sensory memory), back-dated to where the rest began
                self._buffer.extend(flat[f : e + 1])
                since[f:e] = start
                lag = m // 2
                closed.extend((e, s) for s in self._close(max(start + 1, first + e - int(resting[e]) + 1 - lag)))
                f = e + 1
            elif cut < n:  # never ended: closed, the next one begun
                self._buffer.extend(flat[f:cut])
                since[f:cut] = start
                closed.extend((cut, s) for s in self._close(first + cut, "longer than max_movement: cut"))
                self._start, self._buffer = first + cut, [flat[cut]]
                if e == cut:  # and this frame ends the one begun
                    closed.extend((cut, s) for s in self._close(max(first + cut + 1, first + cut - int(resting[cut])
                                                                    + 1 - m // 2)))
                else:
                    since[cut] = self._start
                f = cut + 1
            else:
                self._buffer.extend(flat[f:])
                since[f:] = start
                break
        self._frame = first + n - 1
        self._history.extend(flat[max(0, n - (self._history.maxlen or n)) :])
        self._moving, self._resting = int(moving[-1]), int(resting[-1])
        if valid.any():
            self._speeds.append(float(speeds[valid][-1]))
        return closed, since

    def _step(self, pose: np.ndarray, points: np.ndarray, speed: float) -> list[Segment]:
        """One frame after its sensory memory was updated: ``points`` are the chosen parts (3m,), ``speed`` the
        fastest one's over the sensory memory (NaN: none seen, or not enough frames yet). Segments it closes."""
        cut: list[Segment] = []
        if self._start is not None:
            longest = int(round(self.params["max_movement"] * self._fps))
            if longest and self._frame - self._start >= max(longest, 2):  # never ended: closed, the next one begun
                cut = self._close(self._frame, "longer than max_movement: cut")
                self._start, self._buffer = self._frame, []
                self._origin = self._began(pose, points)
            self._buffer.append(points)
        rest = self._rest_speed(pose, speed)
        if self._pause:
            if np.isnan(speed) or len(self._speeds) < self._pause:
                return cut
            speed = sum(self._speeds) / len(self._speeds)
        if np.isnan(speed):
            return cut
        if speed > rest:
            self._moving += 1
            self._resting = 0
            if self._start is None and self._moving >= self._memory:
                # back-dated to where the motion began, but not into a movement already reported (one closed by
                # `max_movement` just before a rest too short to report)
                self._start = max(self._done, self._frame - 2 * self._memory - self._pause // 2)
                self._buffer = list(self._history)[-(self._frame - self._start + 1):]
                self._origin = self._began(pose, self._buffer[0])
        else:
            self._resting += 1
            self._moving = 0
            if (self._start is not None and self._resting >= max(self._memory, self._pause)
                    and (self.params["end"] == "still" or self._returned(pose, points))):
                lag = self._memory // 2 + self._pause // 2
                return cut + self._close(max(self._start + 1, self._frame - self._resting + 1 - lag))
        return cut

    def _began(self, pose: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, float] | None:
        """With ``end = "rest"``: where a movement begins (the chosen parts ``points``, (3m,)) and the body's size
        then (from ``pose``); ``None`` otherwise."""
        if self.params["end"] != "rest":
            return None
        size = body_scale(pose, self._positions) if len(self._positions) == len(pose) else body_scale(pose)
        return np.array(points, dtype=float), float(size)

    def _returned(self, pose: np.ndarray, points: np.ndarray) -> bool:
        """With ``end = "rest"``: whether the rest now ends the movement under way, because the chosen parts
        (``points``, (3m,)) are back within ``rest_radius`` body sizes (eq. 1: the mean distance over the parts seen
        in both) of where the movement began, or have rested ``settle`` seconds. Where it began is the first pose of
        its working memory (the onset, back-dated to where the motion began), taken with the body's size then."""
        if self._resting >= self._settle or self._origin is None:
            return True
        first, size = self._origin
        apart = np.linalg.norm((points - first).reshape(-1, 3), axis=1)
        apart = apart[np.isfinite(apart)]
        if not apart.size or not size > 0:  # nothing to compare: the paper's rule
            return True
        return float(apart.mean()) <= self.params["rest_radius"] * size

    def _rest_speed(self, pose: np.ndarray, speed: float) -> float:
        """The speed below which the parts are at rest now: ``rest_speed`` (m/s), or ``size_rest_speed`` body sizes
        per second; at least ``noise`` times the slowest (mean over ``pause``) speed of the last ``floor`` seconds.
        Records this frame's speed and size first."""
        p = self.params
        if p["units"] == "body":
            if not self._size_n or self._frame % self._memory == 0:  # the size changes with the pose, slowly
                size = body_scale(pose, self._positions) if len(self._positions) == len(pose) else body_scale(pose)
                if size > 0:
                    self._size_sum, self._size_n = self._size_sum + size, self._size_n + 1
            rest = p["size_rest_speed"] * (self._size_sum / self._size_n if self._size_n else 0.0)
        else:
            rest = p["rest_speed"]
        if not np.isnan(speed):
            self._speeds.append(speed)
        if p["noise"] > 0 and not np.isnan(speed) and len(self._speeds) >= max(1, self._pause):
            level = sum(self._speeds) / len(self._speeds)
            while self._slowest and self._slowest[-1][1] >= level:
                self._slowest.pop()
            self._slowest.append((self._frame, level))
        while self._slowest and self._slowest[0][0] <= self._frame - self._floor:
            self._slowest.popleft()
        if self._slowest:
            rest = max(rest, p["noise"] * self._slowest[0][1])
        return rest

    def flush(self) -> list[Segment]:
        if self._start is None:
            return []
        return self._close(self._frame + 1, "the stream ended")

    def _close(self, end: int, reason: str = "at rest again") -> list[Segment]:
        start, self._start = self._start, None
        window = np.array(self._buffer[: end - start])
        self._buffer = []
        if end - start < 2:
            return []
        self._last, self._analysis, self._done = (start, end, window), None, end
        if self.params["level"] == "movement":
            return [Segment(start, end, self._fps, reason)]
        cuts = breaks(window, self._fps, self.criteria)  # analyse(window).breaks (inspect() analyses it in full)
        edges = [0, *cuts, end - start]
        return [Segment(start + a, start + b, self._fps, "a stroke's end: a speed minimum or a turn" if b < end - start
                        else reason) for a, b in zip(edges, edges[1:]) if b > a]

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
