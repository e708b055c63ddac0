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
never falls below and a large body's sway may exceed, and the paper ends a movement at any rest. Each of these is a
parameter, off by default (the paper); the observer template (``characters/observers/recordings.toml``,
``[segmenters.velocity-direction]``) sets ``level = "movement"``, ``units = "body"``, ``window = 0.2``, ``stretch =
0.33``, ``jitter = 3`` and ``end = "rest"``:

- ``units = "body"``: the rest speed is ``body.rest_speed`` of the demonstrator's own body sizes per second
  (:func:`plugins.lib.body_size.body_scale` of the poses seen, a running mean: about 0.45 m for a standing adult,
  0.20 m for Max). 0.1 body sizes/s (4.5 cm/s on an adult) lies between standing sway (1-2 cm/s) and a gesture
  (tens of cm/s).
- ``window = w > 0``: each part's velocity is the slope of the least-squares line through its last ``w`` seconds of
  positions instead of its displacement over the sensory memory (:mod:`.speed`): a tracker's jitter is averaged
  out (2.5 times less noise at ``w = 0.2`` s and 30 frames/s), at the cost of ``w / 2`` seconds of delay, which the
  onset and the end are dated back by.
- ``jitter = k > 0``: the rest speed is at least ``k`` times the root-mean-square speed the tracker's jitter alone
  gives a part standing still, the jitter measured from the chosen parts' own positions (the median of their second
  differences over ``floor`` seconds, whether the person moves or not; :class:`.speed.Jitter`). ``k = 3``: a still
  part seems to move that fast about once in 100,000 frames.
- ``stretch = s > w``: where the jitter's floor (``jitter``) lies above the demonstrator's own rest speed by more
  than a doubling of the window lowers it (:data:`DOUBLING`), the line fit is lengthened (twice ``w``, ... up to
  ``s`` seconds; :func:`.speed.longer_fits`): a slow movement is still seen on a noisy tracker. The template's 1/3 s
  is no longer than the shortest pause people make between gestures, which must still be seen as a rest.
- ``noise = k > 0``: the rest speed is at least ``k`` times the slowest the demonstrator has been over the last
  ``floor`` seconds (their own speed distribution: sway plus the tracker's noise, whatever their units). It reads a
  walk's slow phase (a stride's turning point) as rest, so the template leaves it off.
- ``pause = p > 0``: the speed is averaged over the last ``p`` seconds before it is compared with the rest speed,
  so a movement begins and ends only at a *real rest* of about ``p`` seconds.
- ``end = "rest"``: a rest ends the movement under way only where it is a *hub* of this demonstrator's
  (:mod:`.rests`; K&G §4.2's hub nodes, "typical start states ... in which a complete movement normally starts and
  ends"): near the pose it began from or another rest they were seen in (``rest.radius`` body sizes, eq. 1's mean
  distance over the chosen parts, and no part farther than twice that: no part has left it; poses at rest are
  compared as their mean over the sensory memory or the line fit's window, so the jitter is averaged out). A rest
  elsewhere is a *hold* (a bow, a pointing hand held half-way: one movement, not two) unless they leave it and come
  to rest there again (a new stance: the movement is cut where they first rested there) or rest there ``settle``
  seconds, in one place: a hold from which some part drifts farther than ``rest.radius`` was no rest (a movement
  slower than the tracker's jitter lets the speed show) and the rest counts again from there; the way back from such
  a stance to where the settled movement began is no movement of its own. A straight *shift*
  from one stance to another is no movement and is dropped, and a piece that never leaves where it began (some part
  farther than twice ``rest.radius``) is motion at rest (sway, fidgeting), dropped too. ``rest.radius = 0.1``:
  B&B's hub threshold (0.02 m on Max, 0.20 m body size); ``settle = 2`` s: longer than a gesture holds a pose (about
  a second), as ``hub-threshold``'s ``settle``. The paper's ``"still"`` (any rest ends it) is the default.
- the onset *by position* (``end = "rest"``): a movement also begins where some part leaves the pose the
  demonstrator rests in (the mean over the sensory memory, farther than twice ``rest.radius`` from the mean of the
  same frames where they came to rest), dated back to the first frame it lay farther than the tracker's jitter
  allows. A line fit's noise grows as its window shortens, a position's does not: a bow slower than a centimetre
  of jitter lets a third-of-a-second fit tell from rest is found by where the head goes, not by how fast. Every
  distance here is at least what the jitter alone gives (``jitter`` times the root-mean-square distance between two
  such means of a part standing still, :mod:`.departure`): the radius and twice it are the demonstrator's own, the
  jitter's margin where that is larger; eq. 1's mean distance to a hub counts only what that root-mean-square
  distance does not explain (each part's square less its square, :mod:`.rests`).

On locomotion, which never rests, the template's movement level finds no boundary inside a walk: a walk of several
takes is one movement (closed after ``max_movement`` seconds if it goes on), not one a stride.

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
from plugins.segmenters.velocity_direction.departure import Departure
from plugins.segmenters.velocity_direction.rests import Rests
from plugins.segmenters.velocity_direction.speed import Jitter, line_speeds, line_weights, longer_fits, speed_noise
from toolkit import ConfigError, Parameter, Segment, Segmenter, hookimpl

__all__ = ["VelocityDirection", "STANCE"]

STANCE = 0.2
"""Seconds a rest away from the hubs must last to be a stance that movements leave and come back to (``end =
"rest"``): twice a gesture's pauses (a tenth of a second, K&G's sensory memory), shorter than the pauses people
make between gestures (a third of a second and more)."""


DOUBLING = 2.0**1.5
"""How many times lower a line fit twice as long puts the jitter's floor (:mod:`.speed`). ``stretch`` lengthens the
fit only where the floor lies above the demonstrator's own rest speed by more than this: there even the doubled fit
hides their rest speed, so a slow movement is lost to the jitter, not to the rest speed (a floor within this factor
of the rest speed is what a person's own quick changes of velocity give a generated or cleanly captured stream)."""


class VelocityDirection(Segmenter):
    """Break points at significant speed minima and where the movement direction changes cluster (K&G §4.3)."""

    name = "velocity-direction"
    parameters = (
        Parameter("parts", list, [], "Parts whose velocity is used (the wrists...); empty: every part.", items=str),
        Parameter("rest_speed", float, 0.08, "Speed (m/s, over the sensory memory) below which the parts are at rest.", minimum=0.0, length=True),
        Parameter("memory", float, 0.1, "Seconds of the sensory memory: how long motion (or rest) must last to count "
                  "as the onset (or the end) of a movement.", minimum=0.0, seconds=True),
        Parameter("drop", float, 0.5, "A speed minimum is a break point when below this share of its neighbouring "
                  "maxima. Higher cuts more, lower only at near stops.", minimum=0.0, maximum=1.0),
        Parameter("angle", float, 50.0, "Degrees between movement directions that makes a new direction cluster.",
                  minimum=1.0, maximum=180.0),
        Parameter("corner", float, 0.9, "A direction break needs a speed minimum within 0.1 s that is below this "
                  "share of its neighbouring maxima (a gentler dip than `drop`).", minimum=0.0, maximum=1.0),
        Parameter("min_stroke", float, 0.15, "Shortest stroke (s); shorter pieces merge with a neighbour.", minimum=0.0, seconds=True),
        Parameter("smooth", float, 0.2, "Seconds of Savitzky-Golay smoothing of the working memory before it is "
                  "segmented (0: none).", minimum=0.0, seconds=True),
        Parameter("angle_scale", float, 0.25, "Metres one radian of a finger's joint angles counts as (0.25: a finger "
                  "turning at 0.6 rad/s moves as fast as a wrist at 0.15 m/s).", minimum=0.0, length=True),
        Parameter("level", str, "stroke", "Report strokes (break points) or whole movements (onset to end; a walk, "
                  "which never rests, is one movement).", choices=("stroke", "movement")),
        Parameter("units", str, "metres", "The rest speed in m/s (`rest_speed`, the paper) or in the demonstrator's "
                  "body sizes per second (`body.rest_speed`).", choices=("metres", "body")),
        Parameter("body", doc="With units = body: speeds in the demonstrator's body sizes (the root-mean-square "
                  "distance of the parts from their centroid, running mean over the poses seen).", parameters=(
            Parameter("rest_speed", float, 0.1, "The rest speed in body sizes per second.", minimum=0.0),
        )),
        Parameter("noise", float, 0.0, "The rest speed is at least this many times the slowest the demonstrator "
                  "has been over the last `floor` seconds (0: off, the paper; in a walk that is a stride's slow "
                  "phase, so walks are cut into strides).", minimum=0.0),
        Parameter("floor", float, 10.0, "Seconds over which the slowest speed is taken for `noise`.", minimum=0.1, seconds=True),
        Parameter("pause", float, 0.0, "Seconds the speed is averaged over before it is compared with the rest "
                  "speed: a movement begins and ends at a rest of about this long (0: the sensory memory, the "
                  "paper).", minimum=0.0, seconds=True),
        Parameter("end", str, "still", "Where a movement ends: at any rest (`still`, the paper) or only at one of "
                  "the demonstrator's own rests (`rest`): near where it began or another rest they were seen in, a "
                  "stance they left and came back to, or after `rest.settle` seconds; a rest elsewhere is a hold, and a "
                  "straight shift of stance is no movement; and a movement also begins where some part leaves their "
                  "rest (twice `rest.radius`), however slowly.", choices=("still", "rest")),
        Parameter("rest", doc="With end = rest: where the demonstrator's own rests are.", parameters=(
            Parameter("radius", float, 0.1, "How near (eq. 1's mean distance of the chosen parts, in the "
                      "demonstrator's body sizes) a pose at rest must be to one of their rests to be there; twice it, "
                      "for one part, is leaving (0.1: B&B's hub threshold, 0.02 m on Max).", minimum=0.0),
            Parameter("settle", float, 2.0, "Seconds of rest away from the demonstrator's rests after which a "
                      "movement ends anyway (a new stance: longer than a gesture holds a pose).", minimum=0.0, seconds=True),
        )),
        Parameter("window", float, 0.0, "Seconds over which each part's velocity is the slope of a least-squares "
                  "line through its positions (a tracker's jitter averaged out; 0: the displacement over the sensory "
                  "memory, the paper).", minimum=0.0, seconds=True),
        Parameter("jitter", float, 0.0, "The rest speed is at least this many times the root-mean-square speed the "
                  "tracker's jitter alone gives a part standing still, the jitter measured from the positions' second "
                  "differences over `floor` seconds (0: off, the paper).", minimum=0.0),
        Parameter("stretch", float, 0.0, "Seconds up to which the line fit is lengthened (doubling from `window`) "
                  "where the rest speed the tracker's measured jitter allows (`jitter`) lies above the "
                  "demonstrator's own (`rest_speed` or `body.rest_speed`): a slow movement is still seen on a noisy "
                  "tracker (0: `window` always).", minimum=0.0, seconds=True),
        Parameter("max_movement", float, 60.0, "Seconds after which a movement that has not ended is closed there and "
                  "the next begins at once (the working memory's bound; 0: none).", minimum=0.0, seconds=True),
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
        window = int(round(self.params["window"] * self._fps))
        self._weights = line_weights(window, self._fps) if window >= 2 else None  # the line fit's, or displacement
        self._lag = (window - 1) // 2 if self._weights is not None else 0  # the line fit's delay (frames)
        self._longer = longer_fits(window, int(round(self.params["stretch"] * self._fps)), self._fps) \
            if self._weights is not None and self.params["jitter"] > 0 else []  # stretch: the lengthened line fits
        widest = max([window] + [len(w) for w, _ in self._longer])
        self._still = max(self._memory, window)  # end = rest: poses are compared as the mean of this many frames
        pause = int(round(self.params["pause"] * self._fps))
        self._history: deque[np.ndarray] = deque(maxlen=max(2 * self._memory + 2, widest) + (widest - 1) // 2
                                                 + pause // 2 + self._still + int(round(self._fps)))  # the sensory
        # memory, and what an onset goes back to (one by position: up to a second)
        self._last: tuple[int, int, np.ndarray] | None = None  # the last movement closed: start, end, working memory
        self._done = 0  # the end of the last movement reported: a movement begins no earlier
        self._analysis: StrokeAnalysis | None = None
        self._pause = max(self._memory, int(round(self.params["pause"] * self._fps))) if self.params["pause"] > 0 else 0
        self._speeds: deque[float] = deque(maxlen=max(1, self._pause))  # for the mean over `pause`
        self._slowest: deque[tuple[int, float]] = deque()  # monotonic queue: the running minimum over `floor`
        self._floor = max(1, int(round(self.params["floor"] * self._fps)))
        self._jitter = Jitter(len(self._idx), self._floor, max(1, int(round(self._fps)))) \
            if self.params["jitter"] > 0 else None  # measured again every second
        self._positions = ~np.array([p in angles for p in parts]) if parts else np.zeros(0, bool)
        self._size_sum, self._size_n = 0.0, 0
        self._rests = Rests(stance=int(round(STANCE * self._fps)), smooth=self._still, jitter=self.params["jitter"]) \
            if self.params["end"] == "rest" else None
        # end = rest: the hubs and holds
        self._holding = False  # end = rest: the rest under way is a hold (away from the hubs)
        self._drift = -(1 << 62)  # end = rest: the frame the rest under way counts from, if it drifted
        self._departure = Departure(self.params["jitter"], self.params["rest"]["radius"], self._still)  # end = rest:
        # the rest pose, and where the parts leave it
        self._settle = max(1, int(round(self.params["rest"]["settle"] * self._fps)))

    @property
    def active_since(self) -> int | None:
        return self._start

    @property
    def holds_since(self) -> int | None:
        """The first frame a segment still to be reported may begin at: the onset of the movement under way, else
        the oldest frame of the sensory memory a movement's onset is back-dated into (never before the last movement
        reported), so a bounded working memory keeps those rows (:mod:`toolkit.watching`); ``None`` before any
        frame."""
        if self._start is not None:
            return self._start
        if not self._history:
            return None
        return max(self._done, self._frame + 1 - len(self._history))

    def push(self, pose: np.ndarray, visible: np.ndarray) -> list[Segment]:
        closed, _ = self.push_block(np.asarray(pose)[None], np.asarray(visible)[None])
        return [segment for _, segment in closed]

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
        if self._weights is not None:  # the slope of a line through the last `window` frames (.speed)
            speeds = self._fitted(rows, before, seen, self._weights)
        else:
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
        if (p["units"] == "metres" and not self._pause and not p["noise"] > 0 and p["end"] == "still"
                and self._weights is None and self._jitter is None):  # a fixed rest speed, and any rest ends a movement
            return self._follow(flat, speeds)
        sigma = self._jitter.update(flat) if self._jitter is not None else None
        floors = (p["jitter"] * speed_noise(sigma, self._weights if self._weights is not None else self._displacement)
                  if sigma is not None else np.zeros(n))
        scale = None  # every frame's body size at once (the running mean takes some of them; end = rest: leaving)
        if p["units"] == "body" or self._rests is not None:
            scale = body_scale(poses, self._positions) if len(self._positions) == poses.shape[1] else body_scale(poses)
        sizes = scale.tolist() if p["units"] == "body" else [None] * n
        lags = np.full(n, self._lag)
        if self._rests is not None:
            self._departure.block(rows, before, scale, sigma)
        walk = not self._pause and not p["noise"] > 0  # the rest speed known for the block at once
        own = self._own_rests(sizes) if walk or self._longer else None  # once for the block: stretch and _walk
        if self._longer:  # stretch: a longer line fit where the tracker's jitter hides the rest speed
            for weights, lag in self._longer:
                noisy = floors > DOUBLING * own[0]  # the jitter floor still above the own rest speed after a doubling
                if not noisy.any():
                    break
                longer = p["jitter"] * speed_noise(sigma, weights)
                speeds = np.where(noisy, self._fitted(rows, before, seen, weights), speeds)
                floors, lags = np.where(noisy, longer, floors), np.where(noisy, lag, lags)
        if walk:
            return self._walk(poses, flat, speeds, floors, sizes, lags, own)
        return self._steps(poses, flat, speeds, floors, sizes, lags)

    def _fitted(self, rows: np.ndarray, before: int, seen: np.ndarray, weights: np.ndarray) -> np.ndarray:
        """Each block frame's speed by the line fit ``weights`` (:func:`.speed.line_speeds`) over ``rows`` (the
        ``before`` rows of the sensory memory, then the block's); NaN where no chosen part is ``seen`` or the
        memory is too short yet."""
        n, w = len(seen), len(weights)
        speeds = np.full(n, np.nan)
        fitted = line_speeds(rows, weights)  # row i: the frame whose window ends at rows[i + w - 1]
        at = np.arange(n) + before - (w - 1)  # each block frame's row in `fitted`
        ok = seen & (at >= 0)
        speeds[ok] = fitted[at[ok]]
        return speeds

    def _own_rests(self, sizes: list) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The demonstrator's own rest speed at each frame of a block whose bodies' sizes are ``sizes`` (None:
        ``units = "metres"``): ``body.rest_speed`` times the running mean of the size, taken every sensory memory,
        summed in the same order as frame by frame (or ``rest_speed``); with the running sums and counts after each
        frame (n + 1,: the state before the block first). Not the jitter's floor, nor ``noise``."""
        n, p, m = len(sizes), self.params, self._memory
        first = self._frame + 1
        if p["units"] == "body":
            size = np.array([np.nan if x is None else x for x in sizes])
            take = ((first + np.arange(n)) % m == 0) & (size > 0)
            if not self._size_n and (size > 0).any():
                take[int(np.argmax(size > 0))] = True  # the first size there is, whatever the frame
            sums = np.cumsum(np.concatenate([[self._size_sum], np.where(take, size, 0.0)]))  # in order, as one by one
            counts = self._size_n + np.concatenate([[0], np.cumsum(take)])
            rest = p["body"]["rest_speed"] * np.where(counts[1:] > 0, sums[1:] / np.maximum(counts[1:], 1), 0.0)
        else:
            sums, counts = np.full(n + 1, self._size_sum), np.full(n + 1, self._size_n)
            rest = np.full(n, float(p["rest_speed"]))
        return rest, sums, counts

    def _steps(self, poses: np.ndarray, flat: np.ndarray, speeds: np.ndarray, floors: np.ndarray,
               sizes: list, lags: np.ndarray) -> tuple[list[tuple[int, Segment]], np.ndarray]:
        """:meth:`_step` for every frame of a block (``flat``: the chosen parts (n, 3m); ``speeds``, ``floors`` and
        ``sizes``: each frame's speed, jitter floor and body size; ``lags``: its line fit's delay): the segments
        closed and the onsets."""
        closed: list[tuple[int, Segment]] = []
        since = np.full(len(flat), -1, dtype=int)
        for f, floor in enumerate(floors.tolist()):
            self._frame += 1
            self._history.append(flat[f])
            closed.extend((f, s) for s in self._step(poses[f], flat[f], float(speeds[f]), floor, sizes[f],
                                                     int(lags[f]), f))
            if self._start is not None:
                since[f] = self._start
        return closed, since

    def _walk(self, poses: np.ndarray, flat: np.ndarray, speeds: np.ndarray, floors: np.ndarray,
              sizes: list, lags: np.ndarray, own: tuple[np.ndarray, np.ndarray, np.ndarray]
              ) -> tuple[list[tuple[int, Segment]], np.ndarray]:
        """:meth:`_step` for every frame of a block without ``pause`` and ``noise`` (the observer template's): the
        same segments at the same frames, with only the frames where something can happen stepped (``own``: the
        block's :meth:`_own_rests`).

        Without them the rest speed of every frame is known for the block at once (``body.rest_speed`` times the
        running mean of the body's size, summed in the same order as frame by frame, or ``rest_speed``; at least
        the jitter's ``floors``), and so are the counts of fast and slow frames that :meth:`_step` keeps. A frame
        can change something only where a movement begins (no movement under way, moving for the sensory memory),
        where one under way comes to rest, where a hold is left, or where one has lasted ``max_movement``: the state
        before such a frame (the counts, the size's sums, the sensory memory, the working memory) is set as the
        frames before it left it, and :meth:`_step` steps it."""
        n, p, m = len(flat), self.params, self._memory
        closed: list[tuple[int, Segment]] = []
        since = np.full(n, -1, dtype=int)
        first = self._frame + 1
        rest, sums, counts = own
        rest = np.maximum(rest, floors)
        valid = ~np.isnan(speeds)
        fast, frames = valid & (speeds > rest), np.arange(n)
        slow = valid & ~fast
        fast_run, slow_run = np.cumsum(fast), np.cumsum(slow)
        last_slow = np.maximum.accumulate(np.where(slow, frames, -1))
        last_fast = np.maximum.accumulate(np.where(fast, frames, -1))
        moving = np.where(last_slow >= 0, fast_run - fast_run[np.maximum(last_slow, 0)], self._moving + fast_run)
        resting = np.where(last_fast >= 0, slow_run - slow_run[np.maximum(last_fast, 0)], self._resting + slow_run)
        onsets = np.flatnonzero(fast & (moving >= m))  # a movement begins, or a hold is left
        rests = np.flatnonzero(slow & (resting >= m))  # a movement under way comes to rest
        longest = int(round(p["max_movement"] * self._fps))
        longest = max(longest, 2) if longest else 0
        pushed = 0  # the block's rows in the sensory memory so far

        def upto(f: int) -> None:  # the state the frames before f left
            nonlocal pushed
            self._history.extend(flat[max(pushed, f - (self._history.maxlen or f)) : f])
            pushed = f
            self._frame = first + f - 1
            self._moving = int(moving[f - 1]) if f else self._moving
            self._resting = int(resting[f - 1]) if f else self._resting
            self._size_sum, self._size_n = float(sums[f]), int(counts[f])

        f = 0
        while f < n:
            if self._start is None:
                e = int(onsets[np.searchsorted(onsets, f)]) if np.searchsorted(onsets, f) < len(onsets) else n
                if self._rests is not None:  # or where the parts leave the rest pose (_left_rest)
                    e = self._departure.next_left(f, e)
            else:
                i = np.searchsorted(rests, f)
                e = min(int(onsets[np.searchsorted(onsets, f)]) if self._holding and
                        np.searchsorted(onsets, f) < len(onsets) else n,
                        max(f, self._start + longest - first) if longest else n)
                if self._holding and i < len(rests) and rests[i] < e:  # a hold's frames where it just goes on
                    j = i + int(np.searchsorted(rests[i:], e))
                    e = min(e, self._holds_on(rests[i:j], resting, first, e))
                else:
                    e = min(e, int(rests[i]) if i < len(rests) else n)
                self._buffer.extend(flat[f:e])
                since[f:e] = self._start
            if e >= n:
                break
            upto(e)
            self._frame += 1
            self._history.append(flat[e])
            pushed = e + 1
            closed.extend((e, s) for s in self._step(poses[e], flat[e], float(speeds[e]), float(floors[e]), sizes[e],
                                                     int(lags[e]), e))
            if self._start is not None:
                since[e] = self._start
            f = e + 1
        upto(n)
        return closed, since

    def _holds_on(self, frames: np.ndarray, resting: np.ndarray, first: int, e: int) -> int:
        """The first of a hold's rest ``frames`` (block frames, before ``e``) where :meth:`_rested` does more than
        let the hold go on (it drifts, is at a hub, has lasted ``rest.settle`` or a stance's time), or ``e``;
        ``resting``: the counts of frames at the rest speed of the block's frames."""
        if not len(frames):
            return e
        rests = self._rests
        here = np.minimum(resting[frames], first + frames - self._drift)
        if len(rests.holds) < 2:
            pending = here >= self._settle
        else:
            pending = (here >= self._settle) | (here == max(self._memory, self._pause) + rests.stance)
        departure = self._departure
        pending |= ~departure.whole[frames]  # no mean of the block's rows yet: stepped
        a, size = 0, 8
        while a < len(frames):  # in chunks of growing size: the hold is most often left or drifts soon
            b = min(len(frames), a + size)
            chunk = frames[a:b]
            hub, still = rests.places(departure.recent[chunk], departure.near[chunk])
            event = np.flatnonzero(pending[a:b] | hub | ~still)
            if len(event):
                return int(chunk[event[0]])
            a, size = b, 2 * size
        return e

    @property
    def _displacement(self) -> np.ndarray:
        """The weights whose dot product with the positions over the sensory memory is the paper's speed."""
        w = np.zeros(self._memory + 1)
        w[0], w[-1] = -self._fps / self._memory, self._fps / self._memory
        return w

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

    def _step(self, pose: np.ndarray, points: np.ndarray, speed: float, floor: float = 0.0,
              size: float | None = None, fit_lag: int | None = None, at: int | None = None) -> list[Segment]:
        """One frame after its sensory memory was updated: ``points`` are the chosen parts (3m,), ``speed`` the
        fastest one's over the sensory memory (NaN: none seen, or not enough frames yet), ``floor`` the least rest
        speed the tracker's jitter allows (``jitter``), ``fit_lag`` the delay of the line fit that measured the
        speed (frames; None: ``window``'s). Segments it closes."""
        cut: list[Segment] = []
        if self._start is not None:
            longest = int(round(self.params["max_movement"] * self._fps))
            if longest and self._frame - self._start >= max(longest, 2):  # never ended: closed, the next one begun
                cut = self._close(self._frame, "longer than max_movement: cut")
                self._start, self._buffer = self._frame, []
                self._began(pose, points)
            self._buffer.append(points)
        rest = max(self._rest_speed(pose, speed, size), floor)
        if self._pause:
            if np.isnan(speed) or len(self._speeds) < self._pause:
                return cut
            speed = sum(self._speeds) / len(self._speeds)
        if np.isnan(speed):
            return cut
        lag = (self._lag if fit_lag is None else fit_lag) + self._pause // 2
        if speed > rest:
            self._moving += 1
            self._resting = 0
            if self._start is None and self._moving >= self._memory:
                # back-dated to where the motion began, but not into a movement already reported (one closed by
                # `max_movement` just before a rest too short to report)
                self._start = max(self._done, self._frame - 2 * self._memory - lag)
                self._buffer = list(self._history)[-(self._frame - self._start + 1):]
                self._began(pose, self._held(self._frame - self._start + 1))
            elif self._holding and self._moving >= self._memory:  # moving again after a hold
                self._rests.left(max(self._start + 1, self._frame - 2 * self._memory - lag))
                self._holding = False
        else:
            self._resting += 1
            self._moving = 0
            if self._start is not None and self._resting >= max(self._memory, self._pause):
                began = max(self._start + 1, self._frame - self._here() + 1 - self._memory // 2 - lag)
                if self.params["end"] == "still":
                    return cut + self._close(began)
                if at is not None:  # the pose at rest (_held(1)) as the block's means have it, as _walk reads it
                    departure = self._departure
                    points = departure.recent[at] if departure.whole[at] else self._held(1)
                    return cut + self._rested(began, points, float(departure.near[at]))
                return cut + self._rested(began, self._held(1))
        if self._rests is not None and at is not None:
            self._left_rest(pose, at)
        return cut

    def _left_rest(self, pose: np.ndarray, at: int) -> None:
        """With ``end = "rest"``, after block frame ``at`` was stepped: the onset by position (:mod:`.departure`). A
        movement begins where some part has left the pose the demonstrator rests in, dated back to the first of the
        frames it has lain beyond the jitter's margin since."""
        if self._start is not None:
            self._departure.moving()
            return
        away = self._departure.left(at)
        if away is not None:
            start = max(self._done, self._frame - min(away, len(self._history)) + 1)
            self._start = start
            self._buffer = list(self._history)[-(self._frame - start + 1):]
            rest = self._departure.pose
            self._began(pose, rest)
            self._rests.origin = rest  # its first frame lies beyond the jitter's margin from there already
            self._drift = self._frame  # a rest under way before the onset is not the movement's end

    def _here(self) -> int:
        """The frames the demonstrator has rested in one place (``end = "rest"``): since they last moved, or since
        the rest under way drifted away from where it began (:meth:`.rests.Rests.still`)."""
        return min(self._resting, self._frame - self._drift)

    def _held(self, back: int) -> np.ndarray:
        """The mean of the ``_still`` rows of the sensory memory up to the ``back``-th last (1: this frame's): a
        pose at rest with the tracker's jitter averaged out (3m,)."""
        rows = list(self._history)
        end = max(1, len(rows) - back + 1)
        rows = rows[max(0, end - self._still) : end]
        return np.add.reduce(rows, axis=0) / len(rows)  # np.mean's sum and division, without its overhead

    def _began(self, pose: np.ndarray, points: np.ndarray) -> None:
        """With ``end = "rest"``: a movement begins where the chosen parts are ``points`` (3m,), a rest of the
        demonstrator's (:class:`.rests.Rests`), near which is ``rest.radius`` times the body's size (from
        ``pose``)."""
        if self._rests is None:
            return
        size = body_scale(pose, self._positions) if len(self._positions) == len(pose) else body_scale(pose)
        self._rests.began(points, self.params["rest"]["radius"] * float(size))
        self._holding = False

    def _rested(self, began: int, points: np.ndarray, near: float = 0.0) -> list[Segment]:
        """With ``end = "rest"``: the demonstrator has rested since ``began`` with the chosen parts at ``points``
        (3m,) while a movement is under way. Back at a hold of the movement's (near a hub or not), the movement is
        cut where that hold began and the one from it back to it follows; near a hub, or after ``settle`` seconds,
        it ends there; held a
        stance's time after a shift from a hold where the movement had come most of the way back, it ended at that
        hold; else the rest is a hold and the movement goes on (:mod:`.rests`)."""
        rests = self._rests
        start = self._start
        hub, still = rests.place(points, near)
        if self._holding and not still:  # it drifted away: no rest, a new hold begins here
            fresh = max(self._memory, self._pause)
            began = max(start + 1, began + self._here() - fresh)
            self._drift = self._frame - fresh
            rests.left(began)
            rests.hold(began, points)
        resting = self._here()
        if self._holding and resting < self._settle and (
                resting != max(self._memory, self._pause) + rests.stance or len(rests.holds) < 2):
            if not hub:  # a hold goes on (the working memory is not needed)
                return []
        window = np.array(self._buffer)
        back = None if self._holding else rests.returned(points, start, window)
        if hub and back is None:
            return self._close_pieces(rests.pieces(start, began, window), began)
        if back is not None:
            hold = rests.holds[back]
            pieces = rests.pieces(start, hold.start, window, upto=back)
            rests.hub(hold.pose)
            second = window[hold.end - start : began - start]
            pieces += [] if rests.shift(second) else [(hold.end, began)]
            return self._close_pieces(pieces, began)
        if resting >= self._settle:  # a new stance they stay in: the movement ends where they came to it
            pieces = rests.pieces(start, began, window, shifts=False)
            rests.settle(rests.start_pose(window), points)
            return self._close_pieces(pieces, began)
        if not self._holding:
            rests.hold(began, points)
            self._holding = True
        elif resting == max(self._memory, self._pause) + rests.stance and rests.ended_before(start, window):
            # held a stance's time after a shift from a hold where the movement had come most of the way back
            before = rests.holds[-2]
            pieces = rests.pieces(start, before.start, window, upto=len(rests.holds) - 2)
            rests.hub(points)
            return self._close_pieces(pieces, began)
        return []

    def _rest_speed(self, pose: np.ndarray, speed: float, size: float | None = None) -> float:
        """The speed below which the parts are at rest now: ``rest_speed`` (m/s), or ``body.rest_speed`` body sizes
        per second; at least ``noise`` times the slowest (mean over ``pause``) speed of the last ``floor`` seconds.
        Records this frame's speed and size (``size``: the body's in ``pose``, if known) first."""
        p = self.params
        if p["units"] == "body":
            if not self._size_n or self._frame % self._memory == 0:  # the size changes with the pose, slowly
                if size is None:
                    size = body_scale(pose, self._positions) if len(self._positions) == len(pose) else body_scale(pose)
                if size > 0:
                    self._size_sum, self._size_n = self._size_sum + size, self._size_n + 1
            rest = p["body"]["rest_speed"] * (self._size_sum / self._size_n if self._size_n else 0.0)
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
        """The movement under way ends at ``end``: its segments (itself, or its strokes); ``reason``: why it ends."""
        return self._close_pieces([(self._start, end)], end, reason)

    def _close_pieces(self, pieces: list[tuple[int, int]], end: int, reason: str = "at rest again") -> list[Segment]:
        """The movement under way ends at ``end`` as the movements ``pieces`` ((start, end) frames inside it; none:
        it was no movement); their segments, each itself or its strokes, each ending for ``reason`` (a stroke
        before a piece's end: at a speed minimum or a turn)."""
        start, self._start = self._start, None
        window = np.array(self._buffer[: end - start])
        self._buffer, self._holding = [], False
        out = []
        for a, b in pieces:
            if b - a < 2:
                continue
            piece = window[a - start : b - start]
            self._last, self._analysis = (a, b, piece), None
            if self.params["level"] == "movement":
                out.append(Segment(a, b, self._fps, reason))
                continue
            cuts = breaks(piece, self._fps, self.criteria)  # analyse(piece).breaks (inspect() analyses it in full)
            edges = [0, *cuts, b - a]
            out.extend(Segment(a + u, a + v, self._fps, "a stroke's end: a speed minimum or a turn" if v < b - a
                               else reason) for u, v in zip(edges, edges[1:]) if v > u)
        if end - start >= 2:
            self._done = end
        if self._rests is not None:
            self._departure.rested(self._held(1))
        return out

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
