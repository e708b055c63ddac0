"""Time warping of a demonstration's frames against chains of one's own frames: the search matchers share.

A *chain* is one take of one's own movement as a sequence of frames (a posegraph's nodes, a motor command's
predicted trajectory): its frames in order, the movement it belongs to, and whether its last frame leads back to its
first (a looping take, a walk's cycle). The warping aligns the samples of a demonstration with a chain by dynamic
time warping (the steps: the next sample on the next frame of the chain, the next sample on the same frame, the
same sample on the next frame), free to begin at any frame of the chain and to end at any: a movement seen only in
part, or with frames before and after it, still finds its part (B&B 2005 §5.2.3). A chain's distance is its best
path's summed frame distance (the comparison's, :mod:`plugins.matchers.comparison`) over the path's length, so a
slower performance, which stays on frames, and a faster one, which passes several frames per sample, compare alike;
no limit is set on either.

- :func:`chain_distances`: every chain against a whole demonstration at once (path search's per-movement search,
  :mod:`plugins.matchers.path_search.per_movement`; the calibration of a decision);
- :func:`chain_path`: the frames of one chain's best path;
- the same warping advanced sample by sample as a demonstration comes in, each chain at its own pace, is
  :class:`plugins.matchers.pacing.PacedWarping` (the forward model following real people, K&G 2006 §4.4).

The loops are plain Python, their own reference, compiled by :mod:`plugins.lib.compiled`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plugins.lib.compiled import kernel
from plugins.matchers.comparison import Comparison, Frames
from plugins.matchers.decision import Calibration, relative_scores

__all__ = ["Chains", "chain_calibration", "chain_distances", "chain_path", "chain_rows", "chain_stills", "kept",
           "kept_chains", "relative_distances", "warp_chains"]


@dataclass(frozen=True)
class Chains:
    """Takes as chains of frames (a posegraph's nodes, hubs left out; a command's predicted samples).

    Attributes
    ----------
    nodes : array of int, shape (M,)
        Frame indices (a posegraph's node indices; else 0..M-1), chain after chain, each chain in its take's order.
    starts : array of int, shape (C + 1,)
        Chain ``c`` is ``nodes[starts[c]:starts[c + 1]]``.
    movements : tuple of str
        Each chain's movement.
    cyclic : array of bool, shape (C,)
        Whether the chain's last node leads back to its first (a looping clip).
    """

    nodes: np.ndarray
    starts: np.ndarray
    movements: tuple[str, ...]
    cyclic: np.ndarray

    def __len__(self) -> int:
        return len(self.movements)

    @classmethod
    def of_lengths(cls, lengths, movements, cyclic=None) -> Chains:
        """Chains of the given lengths over frames 0..M-1 in order (each chain's frames after the previous one's)."""
        starts = np.concatenate([[0], np.cumsum(lengths)]).astype(np.intp)
        cyclic = np.zeros(len(movements), dtype=bool) if cyclic is None else np.asarray(cyclic, dtype=bool)
        return cls(np.arange(starts[-1], dtype=np.intp), starts, tuple(movements), cyclic)

    def chain(self, c: int) -> np.ndarray:
        """The frame indices of chain ``c``."""
        return self.nodes[self.starts[c] : self.starts[c + 1]]


def _warp(cost, starts, cyclic, best, end, advanced):
    """Subsequence dynamic time warping of the samples (rows of ``cost``, (n, M)) on every chain (columns
    ``starts[c]:starts[c + 1]``): for each chain, the least summed cost over the path's length of a path that
    begins at any node with the first sample and ends at any node with the last (``best[c]``), the column it
    ends in (``end[c]``) and how many frames of the chain the path advanced over (``advanced[c]``: its diagonal and
    horizontal steps, a cyclic chain's last frame to its first one of them; over the ``n - 1`` steps from sample to
    sample it is the pace, :mod:`plugins.matchers.tempo`). Steps: (i-1, j-1), (i-1, j), (i, j-1); a cyclic chain's
    first node also follows its last. Ties keep the diagonal, then the vertical step. Plain Python as written (the
    reference), compiled by :func:`plugins.lib.compiled.kernel`."""
    n = cost.shape[0]
    for c in range(len(starts) - 1):
        a = starts[c]
        m = starts[c + 1] - a
        before = np.empty(m)
        before_len = np.empty(m)
        before_adv = np.empty(m)
        now = np.empty(m)
        now_len = np.empty(m)
        now_adv = np.empty(m)
        for j in range(m):
            before[j] = cost[0, a + j]
            before_len[j] = 1.0
            before_adv[j] = 0.0
        for i in range(1, n):
            for j in range(m):
                if j > 0:
                    d, dl, da = before[j - 1], before_len[j - 1], before_adv[j - 1] + 1.0
                elif cyclic[c] and m > 1:
                    d, dl, da = before[m - 1], before_len[m - 1], before_adv[m - 1] + 1.0
                else:
                    d, dl, da = np.inf, 0.0, 0.0
                v, vl = before[j], before_len[j]
                if v < d:
                    d, dl, da = v, vl, before_adv[j]
                if j > 0 and now[j - 1] < d:
                    d, dl, da = now[j - 1], now_len[j - 1], now_adv[j - 1] + 1.0
                now[j] = d + cost[i, a + j]
                now_len[j] = dl + 1.0
                now_adv[j] = da
            if cyclic[c] and m > 1:  # the same sample on from the last node to the first, then on along the chain
                j = 0
                while j < m:
                    left = m - 1 if j == 0 else j - 1
                    value = now[left] + cost[i, a + j]
                    if value < now[j]:
                        now[j] = value
                        now_len[j] = now_len[left] + 1.0
                        now_adv[j] = now_adv[left] + 1.0
                        j += 1
                    else:
                        break
            for j in range(m):
                before[j] = now[j]
                before_len[j] = now_len[j]
                before_adv[j] = now_adv[j]
        chosen = -1
        value = np.inf
        for j in range(m):
            mean = before[j] / before_len[j]
            if mean < value:
                value = mean
                chosen = j
        best[c] = value
        end[c] = chosen
        advanced[c] = before_adv[chosen] if chosen >= 0 else 0.0


def chain_distances(comparison: Comparison, samples: Frames, nodes: Frames, chains: Chains,
                    skip: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray | None]:
    """Each chain's distance to the samples (C,): its best path's summed frame distance over the path's length;
    and the frame distances it was found from (samples by the nodes kept, ``None`` when nothing was compared).

    ``nodes``: the frames of every node of the chains, in chain order (``Frames.join`` of the takes'); ``skip``
    (C,) bool: chains left out (infinite)."""
    keep = kept(chains, skip)
    best = np.full(len(chains), np.inf)
    if len(samples) == 0 or not keep.any():
        return best, None
    frames, starts, cyclic, _ = kept_chains(nodes, chains, keep)
    cost = comparison.costs(samples, frames)
    found, _, _ = warp_chains(cost, starts, cyclic)
    best[keep] = found
    return best, cost


def kept(chains: Chains, skip: np.ndarray | None) -> np.ndarray:
    """The chains not left out (C,) bool; ``skip`` (C,) bool: chains left out (``None``: none)."""
    return np.ones(len(chains), dtype=bool) if skip is None else ~np.asarray(skip, dtype=bool)


def kept_chains(nodes: Frames, chains: Chains, keep: np.ndarray
                ) -> tuple[Frames, np.ndarray, np.ndarray, np.ndarray | None]:
    """The chains ``keep`` (C,) bool as a warping takes them: their frames, their starts (K + 1,) and whether each
    loops (K,), and the columns of ``nodes`` they are (``None``: every chain, ``nodes`` itself)."""
    if keep.all():
        return nodes, chains.starts, chains.cyclic, None
    which = np.flatnonzero(keep)
    columns = np.concatenate([np.arange(chains.starts[c], chains.starts[c + 1]) for c in which])
    starts = np.concatenate([[0], np.cumsum(np.diff(chains.starts)[which])]).astype(np.intp)
    return nodes.take(columns), starts, chains.cyclic[which], columns


def warp_chains(cost: np.ndarray, starts: np.ndarray, cyclic: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_warp` of the frame distances ``cost`` (n, M) on the chains ``starts`` (C + 1,), compiled: each chain's
    distance (C,), the column (within the chain) its best path ends in and the frames it advanced over."""
    cost = np.ascontiguousarray(cost, dtype=np.float64)
    found = np.empty(len(starts) - 1)
    end = np.empty(len(starts) - 1, dtype=np.intp)
    advanced = np.empty(len(starts) - 1)
    kernel(_warp)(cost, np.ascontiguousarray(starts, dtype=np.intp), np.asarray(cyclic, dtype=bool), found, end,
                  advanced)
    return found, end, advanced


def _warp_path(cost, cyclic, out):
    """The warping of :func:`_warp` on one chain (``cost`` (n, m)), its steps kept and followed back from the best
    end: ``out[i]`` the column the sample ``i`` was last aligned with. Plain Python as written, compiled by
    :func:`plugins.lib.compiled.kernel`."""
    n, m = cost.shape
    total = np.empty((n, m))
    length = np.empty((n, m))
    step = np.zeros((n, m), dtype=np.int8)  # 0 start, 1 diagonal, 2 vertical, 3 horizontal
    for j in range(m):
        total[0, j] = cost[0, j]
        length[0, j] = 1.0
    for i in range(1, n):
        for j in range(m):
            if j > 0:
                d, dl, s = total[i - 1, j - 1], length[i - 1, j - 1], 1
            elif cyclic and m > 1:
                d, dl, s = total[i - 1, m - 1], length[i - 1, m - 1], 1
            else:
                d, dl, s = np.inf, 0.0, 1
            if total[i - 1, j] < d:
                d, dl, s = total[i - 1, j], length[i - 1, j], 2
            if j > 0 and total[i, j - 1] < d:
                d, dl, s = total[i, j - 1], length[i, j - 1], 3
            total[i, j] = d + cost[i, j]
            length[i, j] = dl + 1.0
            step[i, j] = s
        if cyclic and m > 1:
            j = 0
            while j < m:
                left = m - 1 if j == 0 else j - 1
                value = total[i, left] + cost[i, j]
                if value < total[i, j]:
                    total[i, j] = value
                    length[i, j] = length[i, left] + 1.0
                    step[i, j] = 3
                    j += 1
                else:
                    break
    j = 0
    best = np.inf
    for c in range(m):
        mean = total[n - 1, c] / length[n - 1, c]
        if mean < best:
            best = mean
            j = c
    i = n - 1
    for r in range(n):
        out[r] = -1
    while True:
        if out[i] < 0:  # the last node aligned with sample i (a horizontal step aligns it with several)
            out[i] = j
        s = step[i, j]
        if s == 0:
            break
        if s == 1:
            i -= 1
            j = j - 1 if j > 0 else m - 1
        elif s == 2:
            i -= 1
        else:
            j = j - 1 if j > 0 else m - 1


def relative_distances(comparison: Comparison, samples: Frames, nodes: Frames, chains: Chains,
                       skip: np.ndarray | None = None) -> np.ndarray:
    """Each chain's distance (:func:`chain_distances`) over the demonstration's distance to standing still (C,):
    the relative score of :mod:`plugins.matchers.decision` (``inf`` for a chain left out, and for every chain when
    the demonstration does not move at all: nothing to explain, nothing to calibrate on)."""
    distances, _ = chain_distances(comparison, samples, nodes, chains, skip)
    still = float(np.mean(comparison.still(samples)))
    return relative_scores(distances, np.full(len(distances), still), chain_stills(comparison, nodes, chains.starts))


def chain_stills(comparison: Comparison, nodes: Frames, starts: np.ndarray) -> np.ndarray:
    """Each chain's take's own distance to standing still (C,): the mean over its frames ``nodes[starts[c] :
    starts[c + 1]]`` of :meth:`~plugins.matchers.comparison.Comparison.still`, what
    :func:`~plugins.matchers.decision.relative_scores` weighs the demonstration's against."""
    still = comparison.still(nodes)
    starts = np.asarray(starts, dtype=np.intp)
    if len(still) == 0:
        return np.zeros(len(starts) - 1)
    return np.add.reduceat(still, np.minimum(starts[:-1], len(still) - 1)) / np.maximum(np.diff(starts), 1)


def chain_calibration(comparison: Comparison, takes: list[Frames], nodes: Frames, chains: Chains,
                      scores=relative_distances) -> Calibration:
    """The calibrated decision's scores from the takes themselves (:class:`~plugins.matchers.decision.Calibration`):
    each take against its movement's other takes (leave one take out) and against the other movements (leave one
    movement out), each nearest by the scores of :func:`chain_rows`."""
    return Calibration.of_rows(chain_rows(comparison, takes, nodes, chains, scores), chains.movements)


def chain_rows(comparison: Comparison, takes: list[Frames], nodes: Frames, chains: Chains,
               scores=relative_distances) -> np.ndarray:
    """Each take (chain ``c`` is ``takes[c]``) against every chain but itself (``inf``), (C, C), by
    ``scores(comparison, take, nodes, chains, skip)``: the chains' relative scores as the matcher's search gives
    them (:func:`relative_distances`; at each take's tempo, :func:`plugins.matchers.tempo.paced_scores`)."""
    rows = np.full((len(takes), len(chains)), np.inf)
    for c, take in enumerate(takes):
        skip = np.zeros(len(chains), dtype=bool)
        skip[c] = True
        rows[c] = scores(comparison, take, nodes, chains, skip)
        rows[c, c] = np.inf
    return rows


def chain_path(cost: np.ndarray, chains: Chains, c: int) -> np.ndarray:
    """The node indices of chain ``c``'s best path, one per sample (the node each sample was last aligned with),
    found by the same warping as :func:`chain_distances` with its steps kept and followed back; ``cost``: the frame
    distances :func:`chain_distances` returned (every chain kept)."""
    block = np.ascontiguousarray(cost[:, chains.starts[c] : chains.starts[c + 1]])
    out = np.empty(len(block), dtype=np.intp)
    kernel(_warp_path)(block, bool(chains.cyclic[c]), out)
    return chains.chain(c)[out]
