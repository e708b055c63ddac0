"""Path search's exact search: each movement's best path through the posegraph, by dynamic programming.

Buchsbaum & Blumberg 2005, §5.2 search the posegraph for the path nearest to the observed samples (eq. 3) with a
beam of k paths grown from the k poses nearest the middle frame (:mod:`plugins.matchers.path_search.kbest`). On a
repertoire of real clips the true movement's own best path is often not among them: a long varied clip's many
poses fill the k starts, and the middle frame of a styled performance lies nearer some other movement's poses.
This search cannot lose a movement: it finds, for every movement, the path through that movement's own nodes
that is nearest to the samples, exactly, and ranks the movements by it.

A movement's nodes are the takes it was built from (:meth:`Posegraph.takes`: one chain of nodes per clip, hubs
left out; a clip that loops, a walk's cycle, joins its last node to its first). On each chain the search is
dynamic time warping between the samples and the nodes (the steps: the next sample on the next node, the next
sample on the same node, the same sample on the next node), free to begin at any node and end at any node: a
movement seen only in part, or with frames before and after it, still finds its part (§5.2.3). A path's distance
is its summed frame distance (eq. 3 with the matcher's comparison) over its length, so a slower performance,
which stays on nodes, and a faster one, which passes several nodes per sample, compare alike; no limit is set on
either (the beam's ``max_skip`` does not apply). A movement's distance is its nearest take's.

Cost: one distance per sample and node (the comparison's :meth:`~plugins.matchers.comparison.Comparison.costs`),
then one pass over samples and nodes, compiled (:mod:`plugins.lib.compiled`), for every chain at once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plugins.lib.compiled import compiled
from plugins.matchers.comparison import Comparison, Frames

__all__ = ["Chains", "chain_distances", "chain_path"]


@dataclass(frozen=True)
class Chains:
    """A posegraph's takes as chains of nodes, hubs left out.

    Attributes
    ----------
    nodes : array of int, shape (M,)
        Node indices, chain after chain, each chain in its take's order.
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

    @classmethod
    def of(cls, motor) -> Chains:
        """The chains of a posegraph motor system (its ``takes()``, ``graph`` and ``nodes``)."""
        index = {node: i for i, node in enumerate(motor.nodes)}
        nodes, starts, movements, cyclic = [], [0], [], []
        for movement, takes in motor.takes().items():
            for take in takes:
                if not take:
                    continue
                nodes.extend(index[n] for n in take)
                starts.append(len(nodes))
                movements.append(movement)
                cyclic.append(len(take) > 1 and motor.graph.has_edge(take[-1], take[0]))
        return cls(np.asarray(nodes, dtype=np.intp), np.asarray(starts, dtype=np.intp), tuple(movements),
                   np.asarray(cyclic, dtype=bool))

    def __len__(self) -> int:
        return len(self.movements)

    def chain(self, c: int) -> np.ndarray:
        """The node indices of chain ``c``."""
        return self.nodes[self.starts[c] : self.starts[c + 1]]


def _warp(cost, starts, cyclic, best, end):
    """Subsequence dynamic time warping of the samples (rows of ``cost``, (n, M)) on every chain (columns
    ``starts[c]:starts[c + 1]``): for each chain, the least summed cost over the path's length of a path that
    begins at any node with the first sample and ends at any node with the last (``best[c]``) and the column it
    ends in (``end[c]``). Steps: (i-1, j-1), (i-1, j), (i, j-1); a cyclic chain's first node also follows its
    last. Ties keep the diagonal, then the vertical step. Plain Python as written (the reference), compiled by
    :func:`_kernel`."""
    n = cost.shape[0]
    for c in range(len(starts) - 1):
        a = starts[c]
        m = starts[c + 1] - a
        before = np.empty(m)
        before_len = np.empty(m)
        now = np.empty(m)
        now_len = np.empty(m)
        for j in range(m):
            before[j] = cost[0, a + j]
            before_len[j] = 1.0
        for i in range(1, n):
            for j in range(m):
                if j > 0:
                    d, dl = before[j - 1], before_len[j - 1]
                elif cyclic[c] and m > 1:
                    d, dl = before[m - 1], before_len[m - 1]
                else:
                    d, dl = np.inf, 0.0
                v, vl = before[j], before_len[j]
                if v < d:
                    d, dl = v, vl
                if j > 0 and now[j - 1] < d:
                    d, dl = now[j - 1], now_len[j - 1]
                now[j] = d + cost[i, a + j]
                now_len[j] = dl + 1.0
            if cyclic[c] and m > 1:  # the same sample on from the last node to the first, then on along the chain
                j = 0
                while j < m:
                    left = m - 1 if j == 0 else j - 1
                    value = now[left] + cost[i, a + j]
                    if value < now[j]:
                        now[j] = value
                        now_len[j] = now_len[left] + 1.0
                        j += 1
                    else:
                        break
            for j in range(m):
                before[j] = now[j]
                before_len[j] = now_len[j]
        chosen = -1
        value = np.inf
        for j in range(m):
            mean = before[j] / before_len[j]
            if mean < value:
                value = mean
                chosen = j
        best[c] = value
        end[c] = chosen


_compiled = None


def _kernel():
    global _compiled
    if _compiled is None:
        found = compiled(_warp)
        _compiled = found[0] if found is not None else _warp
    return _compiled


def chain_distances(comparison: Comparison, samples: Frames, nodes: Frames, chains: Chains,
                    skip: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray | None]:
    """Each chain's distance to the samples (C,): its best path's summed frame distance over the path's length;
    and the frame distances it was found from (samples by the nodes kept, ``None`` when nothing was compared).

    ``nodes``: the frames of every node of the chains, in chain order (``Frames.join`` of the takes'); ``skip``
    (C,) bool: chains left out (infinite)."""
    keep = np.ones(len(chains), dtype=bool) if skip is None else ~np.asarray(skip, dtype=bool)
    best = np.full(len(chains), np.inf)
    if len(samples) == 0 or not keep.any():
        return best, None
    if keep.all():
        cost, starts, cyclic = comparison.costs(samples, nodes), chains.starts, chains.cyclic
    else:
        kept = np.flatnonzero(keep)
        columns = np.concatenate([np.arange(chains.starts[c], chains.starts[c + 1]) for c in kept])
        cost = comparison.costs(samples, nodes.take(columns))
        starts = np.concatenate([[0], np.cumsum(np.diff(chains.starts)[kept])]).astype(np.intp)
        cyclic = chains.cyclic[kept]
    cost = np.ascontiguousarray(cost, dtype=np.float64)
    found = np.empty(len(starts) - 1)
    end = np.empty(len(starts) - 1, dtype=np.intp)
    _kernel()(cost, starts, cyclic, found, end)
    best[keep] = found
    return best, cost


def _warp_path(cost, cyclic, out):
    """The warping of :func:`_warp` on one chain (``cost`` (n, m)), its steps kept and followed back from the best
    end: ``out[i]`` the column the sample ``i`` was last aligned with. Plain Python as written, compiled by
    :func:`_path_kernel`."""
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


_compiled_path = None


def _path_kernel():
    global _compiled_path
    if _compiled_path is None:
        found = compiled(_warp_path)
        _compiled_path = found[0] if found is not None else _warp_path
    return _compiled_path


def chain_path(cost: np.ndarray, chains: Chains, c: int) -> np.ndarray:
    """The node indices of chain ``c``'s best path, one per sample (the node each sample was last aligned with),
    found by the same warping as :func:`chain_distances` with its steps kept and followed back; ``cost``: the frame
    distances :func:`chain_distances` returned (every chain kept)."""
    block = np.ascontiguousarray(cost[:, chains.starts[c] : chains.starts[c + 1]])
    out = np.empty(len(block), dtype=np.intp)
    _path_kernel()(block, bool(chains.cyclic[c]), out)
    return chains.chain(c)[out]
