"""A movement's onset found by position (``end = "rest"``): where some part leaves the pose the demonstrator rests in.

Kopp & Graeser 2006, §4.1: a movement begins where the parts leave rest. The speed over the sensory memory finds it
where a part moves faster than the tracker's jitter lets a line fit tell from rest (:mod:`.speed`); a movement
slower than that (a bow under a centimetre of jitter) is found by where the parts go instead: a position's noise
does not grow as the fit shortens. Each pose is seen through the mean of its last frames (the sensory memory or the
line fit's window), and a movement begins where some part lies farther from the rest pose than twice ``rest.radius``
(the demonstrator's own, in body sizes) and than the tracker's jitter allows, dated back to the first frame it lay
beyond the jitter's margin. The margin is ``jitter`` times the root-mean-square distance between two such means of a
part standing still.
"""

from __future__ import annotations

import numpy as np

__all__ = ["Departure"]


class Departure:
    """The rest pose, how long the parts have been away from it, and a block's poses and margins.

    Parameters
    ----------
    jitter : float
        How many times the jitter's root-mean-square distance between two means a part may lie from the rest pose
        and still be there (the segmenter's ``jitter``).
    radius : float
        ``rest.radius``: a part has left the rest pose beyond twice it (body sizes).
    still : int
        The frames each pose is the mean of.
    """

    def __init__(self, jitter: float, radius: float, still: int) -> None:
        self.jitter, self.radius, self.still = float(jitter), float(radius), int(still)
        self.pose: np.ndarray | None = None  # where the demonstrator rests between movements
        self.away = 0  # frames the parts have lain farther from it than the tracker's jitter allows
        self.recent = self.near = self.leave = np.zeros(0)  # the block's poses, jitter margins and distances to leave
        self.whole = np.zeros(0, bool)  # the block's frames with a whole mean

    def block(self, rows: np.ndarray, before: int, scale: np.ndarray, sigma: np.ndarray | None) -> None:
        """A block of frames: each one's pose seen through the mean of its last ``still`` frames (NaN before there
        are as many), how far a part of it may lie from the rest pose for the tracker's jitter alone (``jitter``
        times the root-mean-square distance between two such means of a part standing still), and how far leaving
        is (twice ``radius`` times the body's size in each frame, ``scale``); ``rows``: the ``before`` rows of the
        sensory memory, then the block's; ``sigma``: the measured jitter (None: not measured)."""
        n, w = len(scale), self.still
        recent = np.full((n, rows.shape[1]), np.nan)
        at = np.arange(n) + before - (w - 1)
        whole = at >= 0  # the frames with as many rows before them
        if whole.any():
            means = np.lib.stride_tricks.sliding_window_view(rows, w, axis=0).mean(axis=-1)  # row j: rows j..j+w-1
            recent[whole] = means[at[whole]]
        self.recent, self.whole = recent, whole
        jitter = np.zeros(n) if sigma is None else np.asarray(sigma)
        self.near = self.jitter * jitter * np.sqrt(3.0 * 2.0 / w)
        self.leave = 2.0 * self.radius * np.asarray(scale, dtype=float)

    def rested(self, pose: np.ndarray) -> None:
        """A movement ended, the demonstrator at rest in ``pose`` (the chosen parts, (3m,))."""
        self.pose, self.away = pose, 0

    def moving(self) -> None:
        """A movement is under way: nothing is leaving the rest pose."""
        self.away = 0

    def farthest(self, poses: np.ndarray) -> np.ndarray:
        """The farthest any chosen part of each pose (N, 3m) lies from the rest pose (N,); NaN: none seen in both."""
        apart = (poses.reshape(len(poses), -1, 3) - self.pose.reshape(-1, 3))
        d = np.sqrt((apart * apart).sum(axis=2))
        finite = np.isfinite(d)
        return np.where(finite.any(axis=1), np.where(finite, d, -np.inf).max(axis=1), np.nan)

    def left(self, at: int) -> int | None:
        """Block frame ``at``, no movement under way: how many frames back (this one included) the movement that
        leaves the rest pose here began, or ``None`` where none does (the first pose seen is taken as the rest)."""
        recent = self.recent[at]
        if self.pose is None:
            if np.isfinite(recent).any():
                self.pose, self.away = recent.copy(), 0
            return None
        d = float(self.farthest(recent[None])[0])
        if not d > self.near[at]:
            self.away = 0
            return None
        self.away += 1
        if d > self.leave[at]:
            away, self.away = self.away, 0
            return away
        return None

    def next_left(self, f: int, e: int) -> int:
        """No movement under way from block frame ``f``: the first frame before ``e`` where :meth:`left` can begin a
        movement or sets the rest pose (``e`` if none), :attr:`away` as the frames before it left it."""
        if e <= f:
            return e
        recent = self.recent[f:e]
        if self.pose is None:
            seen = np.flatnonzero(np.isfinite(recent).any(axis=1))
            return f + int(seen[0]) if len(seen) else e
        d = self.farthest(recent)
        over = d > self.near[f:e]
        leaves = np.flatnonzero(over & (d > self.leave[f:e]))
        g = f + int(leaves[0]) if len(leaves) else e
        k = g - f  # the frames before g
        if k:
            below = np.flatnonzero(~over[:k])
            self.away = k - 1 - int(below[-1]) if len(below) else self.away + k
        return g
