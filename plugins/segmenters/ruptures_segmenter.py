"""Segmenter ``ruptures``: kernel change-point detection with a penalty (a baseline, via ruptures).

What most users compare against: :class:`ruptures.KernelCPD` on the stream of
root-relative part positions (an RBF kernel, so changes in any part's
distribution count), with the number of change points chosen by a penalty
rather than given. Every stretch between two change points that is at least
``min_length`` seconds long is a segment.

Change-point detection over a whole recording is offline: pushing frames only
stores them, and the segments come out when the stream is flushed (so this
segmenter cannot drive response facilitation).

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

import numpy as np
import ruptures as rpt
from scipy.spatial.distance import pdist

from toolkit import Motion, Parameter, Segment, Segmenter, hookimpl
from toolkit.motion import fill_hidden

__all__ = ["RupturesSegmenter", "rbf_gamma", "BANDWIDTH_SAMPLE"]

BANDWIDTH_SAMPLE = 2000


def rbf_gamma(x: np.ndarray, sample: int = BANDWIDTH_SAMPLE) -> float:
    """ruptures' median heuristic for the RBF kernel on at most ``sample`` evenly spaced rows of ``x`` (n, d).

    The same value as :class:`ruptures.costs.CostRbf` computes from all pairs when ``len(x) <= sample``;
    memory is O(sample^2) whatever the length of the stream.
    """
    x = np.asarray(x, dtype=np.double)
    if x.ndim == 1:
        x = x.reshape(-1, 1)
    if len(x) > sample:
        x = x[np.unique(np.linspace(0, len(x) - 1, sample).round().astype(int))]
    median = np.median(pdist(x, metric="sqeuclidean"))
    return 1.0 / median if median != 0 else 1.0


class RupturesSegmenter(Segmenter):
    """Kernel change points (ruptures KernelCPD, RBF) with a penalty; offline: segments come at the end."""

    name = "ruptures"
    parameters = (
        Parameter("penalty", float, 3.0, "Penalty per change point (larger: fewer segments).", minimum=0.0),
        Parameter("kernel", str, "rbf", "The kernel of the cost.", choices=("rbf", "linear", "cosine")),
        Parameter("min_length", float, 0.5, "Shortest segment in seconds.", minimum=0.0),
        Parameter("stride", int, 2, "Use every n-th frame (KernelCPD is quadratic in length).", minimum=1),
    )

    def reset(self, parts: Sequence[str], fps: float) -> None:
        self._fps = float(fps)
        self._frames: list[np.ndarray] = []
        self._visible: list[np.ndarray] = []

    @property
    def active_since(self) -> int | None:
        return None

    def push(self, pose: np.ndarray, visible: np.ndarray) -> list[Segment]:
        self._frames.append(np.asarray(pose, dtype=float))
        self._visible.append(np.asarray(visible, dtype=bool))
        return []

    def flush(self) -> list[Segment]:
        if not self._frames:
            return []
        out = self._detect(np.array(self._frames), np.array(self._visible))
        self._frames, self._visible = [], []
        return out

    def segment(self, motion: Motion) -> list[Segment]:
        self.reset(motion.parts, motion.fps)
        return self._detect(motion.positions, motion.visible)

    def _detect(self, poses: np.ndarray, visible: np.ndarray) -> list[Segment]:
        n, stride = len(poses), self.params["stride"]
        seen = visible.any(axis=1)
        if seen.sum() < 2:
            return []
        x = fill_hidden(poses, visible, default=np.zeros(poses.shape[1:])).reshape(n, -1)  # docs/conventions.md
        x = np.nan_to_num(x - np.nanmean(x, axis=0))[::stride]
        min_size = max(2, int(round(self.params["min_length"] * self._fps / stride)))
        if len(x) < 2 * min_size:
            return [Segment(0, n, self._fps)] if n / self._fps >= self.params["min_length"] else []
        kernel = self.params["kernel"]
        params = {"gamma": rbf_gamma(x)} if kernel == "rbf" else None
        ends = rpt.KernelCPD(kernel=kernel, min_size=min_size, params=params).fit(x).predict(pen=self.params["penalty"])
        bounds = [0, *[min(n, int(e) * stride) for e in ends[:-1]], n]
        return [Segment(a, b, self._fps) for a, b in zip(bounds, bounds[1:])
                if b > a and (b - a) / self._fps >= self.params["min_length"] and seen[a:b].any()]


@hookimpl
def likeme_register_segmenters():
    return [RupturesSegmenter]
