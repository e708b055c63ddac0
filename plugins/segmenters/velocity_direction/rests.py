"""Where a movement ends when the demonstrator rests their own way (``end = "rest"``).

Kopp & Graeser 2006, §4.1 and §4.2: a movement runs from an onset out of rest to the next rest, and the motor
command graph's *hub nodes* are "typical start states, positions and configurations in which a complete movement
normally starts and ends" (after Buchsbaum & Blumberg 2005's hubs, §4.1). A real person rests in their own stance,
changes it between gestures, and holds poses half-way through a gesture (a bow, a pointing hand). So a rest ends the
movement under way only where it is a hub of this demonstrator:

- near the pose the movement began from, or near any rest they have been seen in (``rest_radius`` body sizes, eq. 1's
  mean distance over the chosen parts): a rest there ends it where the rest began;
- elsewhere the rest is a *hold* and the movement goes on, unless they leave it (farther than ``rest_radius``) and
  come to rest near it again later: then it was a new stance (movements leave it and come back to it). The movement is cut where they first rested there,
  and the one from it back to it follows;
- or they rest ``settle`` seconds in one place (a new stance they stay in): the movement ends where that rest began.

A *shift* of stance is not a movement: a piece that goes straight from one rest to another (no pose farther from the
straight line between its first and last poses than ``rest_radius`` body sizes plus a quarter of the way: an arc of
up to about 100 degrees) is dropped, and one that ends away from where it began with such a shift after a hold ends at the hold. So two takes
joined through a transition between their stances give the two takes, and a stance change between two gestures
gives the two gestures.

Everything here is bookkeeping on frame numbers and the working memory's poses, called by the segmenter only on the
frames where the demonstrator comes to rest or leaves it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Hold", "Rests", "straight"]

SHIFT_BOW = 0.25
"""How far (a share of its length) a shift of stance may bow out of a straight line."""


def _apart(a: np.ndarray, b: np.ndarray) -> float:
    """Eq. 1's mean distance between two poses of the chosen parts (3m,), over the parts seen in both (NaN: none)."""
    d = np.linalg.norm((np.asarray(a) - np.asarray(b)).reshape(-1, 3), axis=1)
    d = d[np.isfinite(d)]
    return float(d.mean()) if d.size else float("nan")


def straight(window: np.ndarray, radius: float) -> bool:
    """Whether poses ``window`` (N, 3m) go straight from the first to the last: no pose is farther (eq. 1's mean over
    the parts of each part's distance from its own segment) from the straight line than ``radius`` plus
    :data:`SHIFT_BOW` of the way's length (the mean over the parts of their displacements)."""
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
    return float(off[:, seen].mean(axis=1).max()) <= radius + SHIFT_BOW * float(length[seen].mean())


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
    ``rest_radius`` times the body's size when a movement begins.
    """

    radius: float = 0.0
    keep: int = 8
    hubs: list[np.ndarray] = field(default_factory=list)
    holds: list[Hold] = field(default_factory=list)

    def began(self, pose: np.ndarray, radius: float) -> None:
        """A movement begins from ``pose`` (3m,), where the demonstrator was: a hub."""
        self.radius = radius
        self.holds = []
        self.hub(pose)

    def hub(self, pose: np.ndarray) -> None:
        """``pose`` is a rest of this demonstrator's (the latest first; one near it replaced)."""
        pose = np.array(pose, dtype=float)
        self.hubs = [pose] + [h for h in self.hubs if not _apart(h, pose) <= self.radius][: self.keep - 1]

    def at_hub(self, pose: np.ndarray) -> bool:
        """Whether ``pose`` is near one of the hubs (nothing to compare with: the paper's rule, any rest)."""
        near = [_apart(h, pose) for h in self.hubs]
        near = [d for d in near if np.isfinite(d)]
        return not near or min(near) <= self.radius

    def returned(self, pose: np.ndarray, start: int, window: np.ndarray) -> int | None:
        """The index of the last finished hold near ``pose`` that the demonstrator left (some pose since it ended
        farther than the radius from it: a movement from it and back) and came back to rest at, or None.
        ``window``: the movement's poses from frame ``start`` on."""
        for i in range(len(self.holds) - 1, -1, -1):
            h = self.holds[i]
            if h.end is None or not _apart(h.pose, pose) <= self.radius:
                continue
            since = np.asarray(window[h.end - start :], dtype=float).reshape(-1, len(h.pose) // 3, 3)
            with np.errstate(all="ignore"):
                away = np.nanmean(np.linalg.norm(since - h.pose.reshape(-1, 3), axis=2), axis=1)
            if since.size and np.nanmax(np.append(away, -np.inf)) > self.radius:
                return i
        return None

    def hold(self, frame: int, pose: np.ndarray) -> None:
        """A rest away from the hubs began at ``frame`` in ``pose``."""
        self.holds.append(Hold(frame, np.array(pose, dtype=float)))

    def left(self, frame: int) -> None:
        """The demonstrator moves again at ``frame``: the hold under way (if any) ends there."""
        if self.holds and self.holds[-1].end is None:
            self.holds[-1].end = frame

    def pieces(self, start: int, end: int, window: np.ndarray, upto: int | None = None,
               shifts: bool = True) -> list[tuple[int, int]]:
        """The movements (start, end) in frames of the stretch from ``start`` to ``end`` (its poses ``window``, one a
        frame from ``start``) whose holds are ``self.holds[:upto]``: the stretch, dropped if it is a shift of stance
        (unless not ``shifts``: a reach held for ``settle`` is as much a movement as a shift), or, when it ends away from where
        it began, ended at its last hold if what follows that hold is a shift (a return is no shift)."""
        holds = [h for h in self.holds[:upto] if h.end is not None and start < h.start and h.end < end]
        if shifts and straight(window[: end - start], self.radius):
            return []
        if holds and not _apart(window[0], window[end - start - 1]) <= self.radius:  # it ends elsewhere
            last = holds[-1]
            if straight(window[last.end - start : end - start], self.radius):
                return [(start, last.start)]
        return [(start, end)]
