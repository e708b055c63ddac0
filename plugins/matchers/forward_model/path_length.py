"""The path length observed: how far each part of a subsystem has moved since it is followed (K&G §4.4).

Kopp & Graeser re-parameterise a motor command by "the length of the movement seen so far": an edge predicts the
demonstration at the point of its command that has covered as much path as the part has been seen to cover
(:mod:`~plugins.matchers.forward_model.speed`). Observation noise adds length at every frame, so the positions are
averaged over three frames first (:func:`lengths`). The forward model needs the lengths at every frame of a segment;
:class:`Walk` keeps them frame by frame, the same values as :func:`lengths` of the whole segment, a few rows' work a
frame whatever the length of the segment.
"""

from __future__ import annotations

import numpy as np

__all__ = ["Grown", "Walk", "arc", "lengths", "norms"]


def arc(points: np.ndarray) -> np.ndarray:
    """Cumulative path length along points (N, 3)."""
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])


def norms(d: np.ndarray) -> np.ndarray:
    """``np.linalg.norm(d, axis=-1)`` of real values, as numpy computes it (the square root of the summed squares
    along the last axis), without its argument handling: the same values."""
    return np.sqrt(np.add.reduce(d * d, axis=-1))


def lengths(observed: np.ndarray) -> np.ndarray:
    """The observed path length of each part of a working memory (n, k, 3), robust to observation noise.

    Noise adds length at every frame; the positions are averaged over three frames first.
    """
    from scipy.ndimage import uniform_filter1d

    if len(observed) >= 3:
        observed = uniform_filter1d(observed, size=3, axis=0, mode="nearest")
    return np.linalg.norm(np.diff(observed, axis=0), axis=-1).sum(axis=0) if len(observed) > 1 else \
        np.zeros(observed.shape[1])


class Grown:
    """Rows computed once each and kept in a buffer that grows by doubling: :meth:`view` is the first ``n`` (a view).

    The forward model's per-frame work is incremental with it: a row of the working memory, once given, keeps its
    values while :attr:`WorkingMemory.revision <toolkit.watching.WorkingMemory.revision>` stays the same, so what
    is computed from it is computed once.
    """

    __slots__ = ("buffer", "n")

    def __init__(self, shape: tuple[int, ...], capacity: int = 64) -> None:
        self.buffer = np.empty((max(1, capacity), *shape))
        self.n = 0

    def extend(self, rows: np.ndarray) -> None:
        """Append ``rows`` (m, *shape)."""
        end = self.n + len(rows)
        if end > len(self.buffer):
            bigger = np.empty((max(end, 2 * len(self.buffer)), *self.buffer.shape[1:]))
            bigger[: self.n] = self.buffer[: self.n]
            self.buffer = bigger
        self.buffer[self.n : end] = rows
        self.n = end

    def view(self) -> np.ndarray:
        return self.buffer[: self.n]


class Walk:
    """:func:`lengths` of a growing working memory, frame by frame, with exactly the same values.

    The three-frame mean (``uniform_filter1d``, ``mode="nearest"``) is scipy's running sum: ``tmp`` starts at the
    sum of the first window, then adds each entering row minus the leaving one, and each output is ``tmp / 3``. A
    new frame changes only the last smoothed row (its right neighbour was the edge's copy) and adds one: the running
    sum is kept up to the last row whose window lies wholly inside the frames seen, and so are the norms of the
    steps between the smoothed rows that are final, so a frame costs a few rows whatever the length of the segment.
    The total is summed by numpy over the kept norms as :func:`lengths` sums them (same array layout, same order:
    the same bits). ``tests/plugins/matchers/forward_model/test_path_length.py`` compares it with :func:`lengths`
    on random data.
    """

    __slots__ = ("tmp", "final", "smooth", "norms", "seen")

    def __init__(self, k: int) -> None:
        self.tmp: np.ndarray | None = None  # scipy's running window sum at row ``final - 1`` (k, 3)
        self.final = 0  # smoothed rows [0, final) are final: their windows lie inside the frames seen
        self.smooth = Grown((k, 3))  # the final smoothed rows
        self.norms = Grown((k,))  # the norms of the steps between final smoothed rows, then one slot more
        self.seen = 0

    def lengths(self, observed: np.ndarray) -> np.ndarray:
        """``lengths(observed)`` for ``observed`` (n, k, 3), whose first rows are the ones given before."""
        n = len(observed)
        if n < self.seen:
            raise ValueError(f"the working memory shrank from {self.seen} to {n} rows")
        self.seen = n
        if n < 3:  # no filter below three frames (as lengths)
            return lengths(observed)
        if self.tmp is None:  # scipy: tmp = 0.0 + x[-1] + x[0] + x[1], the edge repeated
            self.tmp = (observed[0] + observed[0]) + observed[1]
            self.smooth.extend((self.tmp / 3)[None])
            self.final = 1
        if self.final == n - 2 and n >= 4:  # one more final row (the common case: one frame more)
            self.tmp = self.tmp + (observed[n - 1] - observed[n - 4])
            row = self.tmp / 3
            smooth = self.smooth
            if smooth.n == len(smooth.buffer):
                smooth.extend(row[None])
            else:
                smooth.buffer[smooth.n] = row
                smooth.n += 1
            self.final = n - 1
            self.norms.n = n - 3
            self.norms.extend(norms(row - smooth.buffer[n - 3])[None])
        elif self.final < n - 1:  # rows final .. n-2: tmp[i] = tmp[i-1] + (x[i+1] - x[i-2])
            tmp, out = self.tmp, []
            for i in range(self.final, n - 1):
                tmp = tmp + (observed[i + 1] - observed[max(i - 2, 0)])
                out.append(tmp / 3)
            self.tmp, self.final = tmp, n - 1
            before = self.smooth.n
            self.smooth.extend(np.stack(out))
            rows = self.smooth.buffer[before - 1 : self.smooth.n]
            self.norms.n = before - 1  # drop the slot of the last edge row
            self.norms.extend(np.linalg.norm(np.diff(rows, axis=0), axis=-1))
        # the last row's window repeats its own frame (the edge): tmp[n-1] = tmp[n-2] + (x[n-1] - x[n-3])
        edge = (self.tmp + (observed[n - 1] - observed[n - 3])) / 3
        kept = self.norms
        kept.n = n - 2
        if kept.n == len(kept.buffer):
            kept.extend(norms(edge - self.smooth.buffer[n - 2])[None])
        else:
            kept.buffer[kept.n] = norms(edge - self.smooth.buffer[n - 2])
            kept.n += 1
        return np.add.reduce(kept.buffer[: kept.n], axis=0)
