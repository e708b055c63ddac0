"""Segmenter ``ruptures``: kernel change-point detection with a penalty (a baseline, via ruptures).

What most users compare against: :class:`ruptures.KernelCPD` on the stream of
root-relative part positions (an RBF kernel, so changes in any part's
distribution count), with the number of change points chosen by a penalty
rather than given. Every stretch between two change points that is at least
``min_length`` seconds long is a segment.

Change-point detection is offline: pushing frames stores them, and the segments
come out when ``window`` seconds of stream are held, and when the stream is
flushed (so this segmenter cannot drive response facilitation). Memory is
bounded by the window: when it is full, its change points are found, the
stretches before its last change point are reported, and the frames from that
change point on are kept for the next window (a last change point in the first
half of the window, or none, reports the window whole: every search moves on by
half a window at least, and no segment is longer than the window). A stream no
longer than the window is searched whole, as before; ``window = 0`` holds the
whole stream until it ends. :attr:`RupturesSegmenter.holds_since` tells the
watching loop the first frame it may still report.

The RBF kernel's bandwidth is ruptures' own median heuristic (``gamma`` = 1 /
the median squared distance between frames), computed on at most
``BANDWIDTH_SAMPLE`` frames evenly spaced over the stream rather than on all
pairs (ruptures builds the n x n matrix for it: an hour of stream did not fit
in 24 GB); streams of up to that many (strided) frames get exactly ruptures'
value. The change-point search itself (ruptures' C pelt) computes kernel
values as it goes and is linear in memory.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from toolkit import Motion, Parameter, Segment, Segmenter, hookimpl
from toolkit.motion import fill_hidden

__all__ = ["RupturesSegmenter", "rbf_gamma", "BANDWIDTH_SAMPLE"]

BANDWIDTH_SAMPLE = 2000


def rbf_gamma(x: np.ndarray, sample: int = BANDWIDTH_SAMPLE) -> float:
    """ruptures' median heuristic for the RBF kernel on at most ``sample`` evenly spaced rows of ``x`` (n, d).

    The same value as :class:`ruptures.costs.CostRbf` computes from all pairs when ``len(x) <= sample``;
    memory is O(sample^2) whatever the length of the stream.
    """
    from scipy.spatial.distance import pdist

    x = np.asarray(x, dtype=np.double)
    if x.ndim == 1:
        x = x.reshape(-1, 1)
    if len(x) > sample:
        x = x[np.unique(np.linspace(0, len(x) - 1, sample).round().astype(int))]
    median = np.median(pdist(x, metric="sqeuclidean"), overwrite_input=True)  # partitioned in place, no copy
    return 1.0 / median if median != 0 else 1.0


class RupturesSegmenter(Segmenter):
    """Kernel change points (ruptures KernelCPD, RBF) with a penalty; offline: segments come at the end."""

    name = "ruptures"
    parameters = (
        Parameter("penalty", float, 3.0, "Penalty per change point (larger: fewer segments).", minimum=0.0),
        Parameter("kernel", str, "rbf", "The kernel of the cost.", choices=("rbf", "linear", "cosine")),
        Parameter("min_length", float, 0.5, "Shortest segment in seconds.", minimum=0.0, seconds=True),
        Parameter("stride", int, 2, "Use every n-th frame (KernelCPD is quadratic in length).", minimum=1),
        Parameter("window", float, 60.0, "Seconds of stream held and searched at once (memory is bounded by it; "
                  "no segment is longer); 0: the whole stream, held until it ends.", minimum=0.0, seconds=True),
    )

    def attach(self, owner: Any) -> None:
        super().attach(owner)
        import ruptures  # noqa: F401  loaded when the observer is composed, not inside the first stream's flush

    def reset(self, parts: Sequence[str], fps: float) -> None:
        self._fps = float(fps)
        self._blocks: list[tuple[np.ndarray, np.ndarray]] = []  # copies of the poses and masks held, block by block
        self._held = 0  # frames held
        self._offset = 0  # the frame number of the first frame held
        self._window = int(round(self.params["window"] * self._fps)) if self.params["window"] > 0 else 0

    @property
    def active_since(self) -> int | None:
        return None

    @property
    def holds_since(self) -> int | None:
        """The first frame a segment still to be reported may begin at (the first frame held), ``None`` if none."""
        return self._offset if self._held else None

    def push(self, pose: np.ndarray, visible: np.ndarray) -> list[Segment]:
        # copies: the poses given are views of working memory
        self._blocks.append((np.array(pose, dtype=float)[None], np.array(visible, dtype=bool)[None]))
        self._held += 1
        if self._window and self._held >= max(self._window, 2):
            return self._advance()
        return []

    def push_block(self, poses: np.ndarray, visible: np.ndarray) -> tuple[list[tuple[int, Segment]], np.ndarray]:
        """What pushing the ``n`` poses one by one gives (segments come out only when a window is full), with one
        copy of each stretch up to the window's end rather than one per frame."""
        n = len(poses)
        closed: list[tuple[int, Segment]] = []
        full = max(self._window, 2) if self._window else 0
        i = 0
        while i < n:
            take = n - i if not full else min(n - i, full - self._held)
            self._blocks.append((np.array(poses[i : i + take], dtype=float),
                                 np.array(visible[i : i + take], dtype=bool)))
            self._held += take
            i += take
            if full and self._held >= full:
                closed.extend((i - 1, s) for s in self._advance())
        return closed, np.full(n, -1, dtype=int)

    def _taken(self) -> tuple[np.ndarray, np.ndarray]:
        """The poses (n, P, 3) and masks (n, P) held, and nothing held any more."""
        poses = np.concatenate([b for b, _ in self._blocks])
        visible = np.concatenate([v for _, v in self._blocks])
        self._blocks, self._held = [], 0
        return poses, visible

    def flush(self) -> list[Segment]:
        if not self._held:
            return []
        poses, visible = self._taken()
        out = self._segments(self._bounds(poses, visible), visible.any(axis=1), self._offset)
        self._offset += len(poses)
        return out

    def _advance(self) -> list[Segment]:
        """A full window: the stretches before its last change point (all of it when that is in its first half),
        the frames from there kept."""
        poses, visible = self._taken()
        n = len(poses)
        bounds = self._bounds(poses, visible)
        last = bounds[-2] if len(bounds) > 2 and bounds[-2] >= n // 2 else n
        out = self._segments([b for b in bounds if b <= last], visible.any(axis=1), self._offset)
        if last < n:
            self._blocks, self._held = [(poses[last:], visible[last:])], n - last
        self._offset += last
        return out

    def segment(self, motion: Motion) -> list[Segment]:
        self.reset(motion.parts, motion.fps)
        if not self._window or motion.n_frames < self._window:
            return self._segments(self._bounds(motion.positions, motion.visible), motion.visible.any(axis=1), 0)
        closed, _ = self.push_block(motion.positions, motion.visible)
        return [s for _, s in closed] + self.flush()

    def _bounds(self, poses: np.ndarray, visible: np.ndarray) -> list[int]:
        """0, the change points of ``poses`` (frames, not strided), ``len(poses)``; just the ends when fewer than
        two frames are seen or the stretch is too short to be cut."""
        import ruptures as rpt

        n, stride = len(poses), self.params["stride"]
        visible = visible & np.isfinite(poses).all(axis=2)  # a bad value is not seen, whatever the mask said
        seen = visible.any(axis=1)
        if seen.sum() < 2:
            return [0, n]
        x = fill_hidden(poses, visible, default=np.zeros(poses.shape[1:])).reshape(n, -1)  # docs/conventions.md
        x = np.nan_to_num(x - np.nanmean(x, axis=0))[::stride]
        min_size = max(2, int(round(self.params["min_length"] * self._fps / stride)))
        if len(x) < 2 * min_size:
            return [0, n]
        kernel = self.params["kernel"]
        params = {"gamma": rbf_gamma(x)} if kernel == "rbf" else None
        ends = rpt.KernelCPD(kernel=kernel, min_size=min_size, params=params).fit(x).predict(pen=self.params["penalty"])
        return [0, *[min(n, int(e) * stride) for e in ends[:-1]], n]

    def _segments(self, bounds: list[int], seen: np.ndarray, offset: int) -> list[Segment]:
        """The stretches between successive ``bounds`` at least ``min_length`` long with a frame seen, numbered
        from ``offset``."""
        if seen.sum() < 2:
            return []
        return [Segment(offset + a, offset + b, self._fps, "a change point") for a, b in zip(bounds, bounds[1:])
                if b > a and (b - a) / self._fps >= self.params["min_length"] and seen[a:b].any()]


@hookimpl
def likeme_register_segmenters():
    return [RupturesSegmenter]
