"""Where a movement ends when the demonstrator rests their own way (``end = "rest"``).

Kopp & Graeser 2006, §4.1 and §4.2: a movement runs from an onset out of rest to the next rest, and the motor
command graph's *hub nodes* are "typical start states, positions and configurations in which a complete movement
normally starts and ends" (after Buchsbaum & Blumberg 2005's hubs, §4.1). A real person rests in their own stance,
changes it between gestures, and holds poses half-way through a gesture (a bow, a pointing hand). So a rest ends the
movement under way only where it is a hub of this demonstrator:

- near the pose the movement began from, or near any rest they have been seen in (``rest.radius`` body sizes, eq. 1's
  mean distance over the chosen parts, and no part farther than twice that: none has left it): a rest there ends it
  where the rest began;
- elsewhere the rest is a *hold* and the movement goes on, unless they leave it (some part farther than twice
  ``rest.radius``: a movement from it, not a hand fidgeting there) and come to rest there again later (near it, as
  near a hub: the mean and every part; a head bowing past the pose it was held in is not back there): then it
  was a new stance (movements leave it and come back to it), if they had held it a stance's time (``stance``; the
  segmenter's ``STANCE``, 0.2 s). The movement is cut where they first rested there, and the one from it back to it
  follows; so too where the rest is at a hub as well (a new stance near an old one): what led to the new stance was
  no part of the movement from it;
- or they rest ``settle`` seconds in one place (a new stance they stay in): the movement ends where that rest began.
  A rest stays in one place: a hold from which some part drifts farther than ``rest.radius`` was no rest (a
  movement slower than a tracker's jitter lets the speed show) and a new hold begins where they are (``still``).
  If the next movement from that stance ends back at the pose the settled one began from (``back``), the stance
  was a long hold of that one (a hand raised and held, then lowered) and its way back is no new movement;
- or they have rested a stance's time at a hold reached by a shift (below) from a hold before it that lasted as
  long and where the movement had come at least half-way back to its first pose: the movement ended at that hold (a
  take that ends in another stance than it began, then the shift to the next one's).

A *shift* of stance is not a movement: a piece that goes straight from one rest to another (no part farther from the
straight line between its first and last positions than ``rest.radius`` body sizes plus a quarter of its way: an arc
of up to about 100 degrees) is dropped, and one that ends away from where it began with such a shift after a hold
ends at the hold (if it left where it began before that hold: a movement, then the shift). A piece that never leaves
where it began (no part farther than twice ``rest.radius``) is motion at rest (sway, fidgeting) and is dropped too.
So two takes joined through a transition between their stances give the two takes, and a stance change between two
gestures gives the two gestures. "Where it began" and "elsewhere" are judged as a hub is (:func:`_there`): eq. 1's
mean within ``rest.radius`` and no part farther than twice it. A step to another stance moves the feet alone, whose
mean over the parts may stay within the radius; it is a shift all the same, not a movement back where it began.

On a noisy tracker each of these distances is at least what the jitter alone puts between two poses at rest (the
segmenter's ``near``, from the measured jitter): the radius and twice it are the demonstrator's own, the jitter's
margin where that is larger. Eq. 1's mean distance to a hub is taken over what the jitter does not explain: two
poses seen through means of the same frames lie apart by the jitter's root-mean-square distance ``near / jitter``
even at rest, so each part's squared distance less that square counts (an unbiased estimate of the square of the
distance between the poses themselves), else a tracker's jitter alone would use up much of the radius. A movement
the segmenter found by position (it left its rest slower than the speed shows) comes back where it began when it is
back at the rest pose it left (``origin``): its first frame already lies beyond the jitter's margin from there.

Everything here is bookkeeping on frame numbers and the working memory's poses, called by the segmenter only on the
frames where the demonstrator comes to rest or leaves it (:meth:`Rests.places` asks a hold's frames at once).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Hold", "Rests", "straight"]

SHIFT_BOW = 0.25
"""How far (a share of its length) a shift of stance may bow out of a straight line."""


def _part_distances(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Each chosen part's distance between two poses (3m,), over the parts seen in both."""
    d = np.linalg.norm((np.asarray(a) - np.asarray(b)).reshape(-1, 3), axis=1)
    return d[np.isfinite(d)]


def _apart(a: np.ndarray, b: np.ndarray) -> float:
    """Eq. 1's mean distance between two poses of the chosen parts (3m,), over the parts seen in both (NaN: none)."""
    d = _part_distances(a, b)
    return float(d.mean()) if d.size else float("nan")


def _there(a: np.ndarray, b: np.ndarray, radius: float) -> bool:
    """Whether pose ``b`` (3m,) is where pose ``a`` is: eq. 1's mean distance over the parts seen in both within
    ``radius`` and no part farther than twice it (none has left it; as :meth:`Rests.at_hub`)."""
    d = _part_distances(a, b)
    return bool(d.size) and float(d.mean()) <= radius and float(d.max()) <= 2.0 * radius


def straight(window: np.ndarray, radius: float) -> bool:
    """Whether poses ``window`` (N, 3m) go straight from the first to the last: no part strays from the straight
    line between its own first and last positions farther than ``radius`` plus :data:`SHIFT_BOW` of its own way's
    length (a part not seen throughout is not counted)."""
    window = np.asarray(window, dtype=float)
    if len(window) < 2:
        return True
    points = window.reshape(len(window), -1, 3)
    a, b = points[0], points[-1]
    way = b - a  # (m, 3)
    length = np.sqrt((way * way).sum(axis=1))
    with np.errstate(all="ignore"):
        t = np.clip(((points - a) * way).sum(axis=2) / np.where(length > 0, length * length, 1.0), 0.0, 1.0)
        off = np.linalg.norm(points - (a + t[..., None] * way), axis=2)  # (N, m)
        seen = np.isfinite(off).all(axis=0) & np.isfinite(length)
    if not seen.any():
        return True
    return bool((off[:, seen].max(axis=0) <= radius + SHIFT_BOW * length[seen]).all())


@dataclass
class Hold:
    """A rest during a movement away from its hubs: where it began and ended (frames; ``end`` None while it lasts)
    and the pose (3m,)."""

    start: int
    pose: np.ndarray
    end: int | None = None


@dataclass
class Rests:
    """One demonstrator's rests, as far as seen: the hubs (poses they rested in that movements began from or came
    back to, the latest ``keep``) and the holds of the movement under way.

    ``radius``: how near (in the units of the poses) a pose must be to a hub to be there; the segmenter sets it to
    ``rest.radius`` times the body's size when a movement begins. ``stance``: the frames a hold must last to be a
    stance that movements leave and come back to (shorter: a pause in a gesture, a hand fidgeting). ``smooth``: the
    frames of the moving average the working memory is seen through (the tracker's jitter averaged out) when it is
    asked whether a piece leaves where it began, is a shift, or comes back to a hold. ``jitter``: how many times
    the jitter's root-mean-square distance between two poses at rest the margins ``near`` are (the segmenter's
    ``jitter``; 0: no jitter measured). ``origin``: the rest pose a movement found by position left (the segmenter
    sets it; None: the movement's first frame is where it began). ``settled``: where the movement that last ended
    by ``settle`` began and the stance it settled in (:meth:`settle`); ``back``: the same for the movement under
    way, which began from that stance (None: the last one did not end so).
    """

    radius: float = 0.0
    stance: int = 0
    smooth: int = 1
    keep: int = 8
    jitter: float = 0.0
    origin: np.ndarray | None = None
    settled: tuple[np.ndarray, np.ndarray] | None = None
    back: tuple[np.ndarray, np.ndarray] | None = None
    hubs: list[np.ndarray] = field(default_factory=list)
    holds: list[Hold] = field(default_factory=list)
    _stacked: np.ndarray | None = field(default=None, repr=False)  # the hubs (and the hold under way) (k, m, 3)

    def began(self, pose: np.ndarray, radius: float) -> None:
        """A movement begins from ``pose`` (3m,), where the demonstrator was: a hub."""
        self.radius = radius
        self.holds = []
        self.origin = None
        self.back, self.settled = self.settled, None
        self.hub(pose)

    def settle(self, first: np.ndarray, pose: np.ndarray) -> None:
        """The movement under way, which began at ``first`` (3m,), ended by ``settle`` in ``pose``: a new stance (a
        hub), unless the next movement from it goes back to ``first``."""
        self.hub(pose)
        self.settled = (np.asarray(first, dtype=float), np.asarray(pose, dtype=float))

    def hub(self, pose: np.ndarray) -> None:
        """``pose`` is a rest of this demonstrator's (the latest first; one near it replaced)."""
        pose = np.array(pose, dtype=float)
        self.hubs = [pose] + [h for h in self.hubs if not _apart(h, pose) <= self.radius][: self.keep - 1]
        self._stacked = None

    def at_hub(self, pose: np.ndarray, near: float = 0.0) -> bool:
        """Whether ``pose`` is at one of the hubs: within the radius of it (eq. 1's mean over the parts) and no part
        having left it (farther than twice the radius, or than ``near`` where that is larger: how far the tracker's
        jitter alone puts a part from where it rests). Nothing to compare with: the paper's rule, any rest."""
        return self.place(pose, near)[0]

    def still(self, pose: np.ndarray, near: float = 0.0) -> bool:
        """Whether ``pose`` (3m,) is still where the hold under way began: no part farther than the radius from
        where it was, or than ``near`` where that is larger (how far the tracker's jitter alone puts it). A rest
        stays in one place; one that drifts farther is a movement too slow for the speed to show (a tracker's
        jitter hides it), not a rest. True with no hold under way."""
        return self.place(pose, near)[1]

    def place(self, pose: np.ndarray, near: float = 0.0) -> tuple[bool, bool]:
        """:meth:`at_hub` and :meth:`still` of ``pose`` (3m,) at once: its distances to the hubs and to the hold
        under way, one array (the segmenter asks both at every frame of a hold)."""
        hub, still = self.places(np.asarray(pose)[None], np.array([near], dtype=float))
        return bool(hub[0]), bool(still[0])

    def places(self, poses: np.ndarray, near: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`place` of each of ``poses`` (k, 3m) with its ``near`` (k,): (hub (k,), still (k,)), the same
        arithmetic pose by pose (a hold's frames are asked at once)."""
        k = len(poses)
        holding = bool(self.holds) and self.holds[-1].end is None
        if not self.hubs and not holding:
            return np.ones(k, bool), np.ones(k, bool)
        if self._stacked is None or len(self._stacked) != len(self.hubs) + holding:
            rows = self.hubs + ([self.holds[-1].pose] if holding else [])
            self._stacked = np.array(rows).reshape(len(rows), -1, 3)
        apart = self._stacked[None] - np.asarray(poses).reshape(k, 1, -1, 3)
        d2 = (apart * apart).sum(axis=3)  # (k, hubs [+ the hold], m); NaN: a part not seen in both
        if holding:
            drift = np.maximum(self.radius, near)
            with np.errstate(invalid="ignore"):
                still = ~(d2[:, -1] > (drift * drift)[:, None]).any(axis=1)  # NaN: not counted
        else:
            still = np.ones(k, bool)
        if not self.hubs:
            return np.ones(k, bool), still
        d2 = d2[:, : len(self.hubs)]
        left = np.maximum(2.0 * self.radius, near)[:, None]
        # eq. 1 on the distances the poses' own jitter does not explain: each part's square less the jitter's
        noise = np.asarray(near, dtype=float) / self.jitter if self.jitter > 0 else np.zeros(k)
        real = np.maximum(d2 - (noise * noise)[:, None, None], 0.0)  # NaN stays NaN
        if np.isfinite(d2).all():  # eq. 1: the mean over the parts (np.mean's sum and division, without its overhead)
            at = (np.add.reduce(np.sqrt(real), axis=2) / d2.shape[2] <= self.radius) & (d2.max(axis=2) <= left * left)
            return at.any(axis=1), still
        with np.errstate(all="ignore"):
            seen = np.isfinite(d2)
            mean = np.nanmean(np.where(seen, np.sqrt(real), np.nan), axis=2)  # eq. 1 over the parts seen in both
            farthest = np.where(seen, d2, -np.inf).max(axis=2)
            compared = np.isfinite(mean)
            at = ((mean <= self.radius) & (farthest <= left * left) & compared).any(axis=1)
        return at | ~compared.any(axis=1), still

    def returned(self, pose: np.ndarray, start: int, window: np.ndarray) -> int | None:
        """The index of the last finished hold ``pose`` is at (:func:`_there`) that the demonstrator held a stance's
        time, left (some part farther than twice the radius from it since it ended: a movement from it and back, not a
        hand fidgeting there) and came back to rest at, or None.
        ``window``: the movement's poses from frame ``start`` on."""
        for i in range(len(self.holds) - 1, -1, -1):
            h = self.holds[i]
            if h.end is None or h.end - h.start < self.stance or not _there(h.pose, pose, self.radius):
                continue
            since = self.seen(window[h.end - start :]).reshape(-1, len(h.pose) // 3, 3)
            with np.errstate(all="ignore"):
                away = np.linalg.norm(since - h.pose.reshape(-1, 3), axis=2)
            if since.size and np.nanmax(np.append(away.ravel(), -np.inf)) > 2.0 * self.radius:
                return i
        return None

    def hold(self, frame: int, pose: np.ndarray) -> None:
        """A rest away from the hubs began at ``frame`` in ``pose``."""
        self.holds.append(Hold(frame, np.array(pose, dtype=float)))
        self._stacked = None

    def left(self, frame: int) -> None:
        """The demonstrator moves again at ``frame``: the hold under way (if any) ends there."""
        if self.holds and self.holds[-1].end is None:
            self.holds[-1].end = frame
            self._stacked = None

    def pieces(self, start: int, end: int, window: np.ndarray, upto: int | None = None,
               shifts: bool = True) -> list[tuple[int, int]]:
        """The movements (start, end) in frames of the stretch from ``start`` to ``end`` (its poses ``window``, one a
        frame from ``start``) whose holds are ``self.holds[:upto]`` (those that lasted: a rest dated back to where the
        motion resumed ends where it began and is no hold): none if it never leaves where it began (motion at
        rest) or if it began from a settled stance and ends where the settled movement began (``back``: that one's
        way back); the stretch if it comes back where it began; dropped if it is a shift of stance (unless not
        ``shifts``: a reach held for ``settle`` is as much a movement as a shift); or ended at its last hold if what
        follows that hold is a shift and it left where it began before the hold."""
        holds = [h for h in self.holds[:upto] if h.end is not None and start < h.start < h.end < end]
        if not self.leaves(window[: end - start]):  # motion at rest (sway, a hand fidgeting): no movement
            return []
        last = self.seen(window[: end - start])[-1]  # the jitter averaged out
        first = self.start_pose(window)
        if self.back is not None and _there(self.back[0], last, self.radius):  # a settled movement's way back:
            self.hubs = [h for h in self.hubs if not _there(self.back[1], h, self.radius)]  # that was no stance
            self._stacked = None
            return []
        if _there(first, last, self.radius):  # back where it began: no shift
            return [(start, end)]
        if shifts and self.shift(window[: end - start]):
            return []
        if holds:
            last = holds[-1]
            if self.shift(window[last.end - start : end - start]) and self.leaves(window[: last.start - start]):
                return [(start, last.start)]  # a movement to the hold, then a shift
        return [(start, end)]

    def ended_before(self, start: int, window: np.ndarray) -> bool:
        """Whether the movement (from frame ``start``, poses ``window``) ended at its hold before the last one: that
        hold lasted a stance's time, the movement had come at least half-way back there (eq. 1 from its first pose
        at most half the farthest it had been), and it went from there to the last hold by a shift."""
        if len(self.holds) < 2:
            return False
        before, now = self.holds[-2], self.holds[-1]
        if before.end is None or before.end - before.start < self.stance:
            return False
        points = np.asarray(window[: before.start - start], dtype=float).reshape(before.start - start, -1, 3)
        with np.errstate(all="ignore"):
            way = np.nanmean(np.linalg.norm(points - points[:1], axis=2), axis=1)  # eq. 1 from the first pose
        way = way[np.isfinite(way)]
        if not way.size or not _apart(window[0], before.pose) <= 0.5 * float(way.max()):
            return False
        return self.shift(window[before.end - start : now.start - start])

    def start_pose(self, window: np.ndarray) -> np.ndarray:
        """Where the movement under way (its poses ``window`` from its first frame) began: the rest pose it left
        (:attr:`origin`), else its first pose seen through the moving average."""
        return self.origin if self.origin is not None else self.seen(window[:1])[0]

    def seen(self, window: np.ndarray) -> np.ndarray:
        """Poses ``window`` (N, 3m) through a centred moving average of ``smooth`` frames (the ends held)."""
        window = np.asarray(window, dtype=float)
        if self.smooth <= 1 or len(window) < 2:
            return window
        from scipy.ndimage import uniform_filter1d

        return uniform_filter1d(window, self.smooth, axis=0, mode="nearest")

    def leaves(self, window: np.ndarray) -> bool:
        """Whether poses ``window`` (N, 3m) leave where they began: some part farther than twice the radius from its
        first position (a movement, not motion at rest)."""
        points = self.seen(window).reshape(len(window), -1, 3)
        with np.errstate(all="ignore"):
            away = np.linalg.norm(points - points[:1], axis=2)
        return bool(np.nanmax(np.append(away.ravel(), -np.inf)) > 2.0 * self.radius)

    def shift(self, window: np.ndarray) -> bool:
        """Whether poses ``window`` (N, 3m) are a shift of stance: they end away from where they began (eq. 1 farther
        than the radius) and go there :func:`straight`."""
        if len(window) < 2:
            return False
        window = self.seen(window)
        return not _there(window[0], window[-1], self.radius) and straight(window, self.radius)
