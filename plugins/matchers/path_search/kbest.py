"""Path search's beam: the k best paths from the poses nearest the middle frame (Buchsbaum & Blumberg 2005, §5.2).

The paper's search, kept as it is for the paper's characters (``search = "k-best"``):

1. take a *representative frame from the middle* of the observed segment (the middle is less generic than the
   transitional beginning and end);
2. search *the whole graph* for the k poses nearest to it by eq. 1 (the only whole-graph search);
3. from those k nodes explore outward along the graph's edges, one observed sample at a time, keeping the k best
   paths by eq. 3 (the summed eq. 1), one path per end node;
4. the caller lets the movement to which the majority of the best path's nodes belong be the recognised one
   (§5.2.3).

A path may also stay on a node or skip up to ``max_skip - 1`` nodes per sample, so the same movement performed
slower or faster (Morris's longer cover face, §5.2.2) still aligns. Hidden parts are left out of every distance
(eq. 1 over the visible parts); samples with nothing visible cost nothing. It compares poses (eq. 1) only; the
search that finds each movement's best path exactly, with any comparison, is
:mod:`plugins.matchers.path_search.per_movement`.

The whole-graph search of step 2 (issue 22): on a posegraph of more than :data:`INDEX_MIN_NODES` nodes the k start
poses come from a spatial index (:class:`plugins.lib.pose_index.PoseIndex`, built on the first search and again
after the graph learns), which gives exactly the scan's k nearest in the scan's order. Below that size the scan is
as fast. With nodes excluded (the ranked candidates, the calibration) the scan answers. Where every part of the
middle sample is seen, the scan is screened (:meth:`KBest._screened`): every node measured in single precision
with a bound of the error (:meth:`plugins.lib.pose_distance.PoseScan.approximate`), and only the nodes that can be
chosen (within twice the bound of the k-th nearest) measured again with the scan's arithmetic, so the start nodes
and their costs are the scan's to the last bit.

Hubs (issue 22): a path that ends near a hub reaches, through it, the first nodes of every movement. The reach
tables are factored through the wide nodes (:class:`Fan`): a step lists each node's local reach, and a hub's
onward nodes only for the paths that can be the best way to them (the least cost up to rounding;
:func:`_candidates`), which keeps exactly the paths the full listing keeps.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import networkx as nx
import numpy as np

from plugins.lib.pose_distance import PoseScan, path_distance, pose_distance
from plugins.lib.pose_index import PoseIndex
from plugins.matchers.decision import Calibration
from plugins.matchers.path_search.search import Found, Search

__all__ = ["INDEX_MIN_NODES", "Beam", "KBest"]

INDEX_MIN_NODES = 5000
"""Posegraphs of more nodes than this find the k start poses with :class:`plugins.lib.pose_index.PoseIndex`
(``likeme bench posegraph``: the scan takes about 1.5 ms at 10,000 nodes of 11 parts; below a few thousand the
index gains nothing worth its tree)."""


class KBest:
    """The k-best beam over one posegraph's nodes (see the module).

    Parameters
    ----------
    graph : networkx.DiGraph
        The posegraph's edges.
    names : list of str
        Node names in the order of ``nodes``.
    nodes : array, shape (N, P, 3)
        Every node's root-relative pose.
    k, max_skip : int
        The beam's width and the most nodes a path advances per sample.
    index_min_nodes : int
        Above this many nodes the start poses come from the spatial index.
    """

    def __init__(self, graph: nx.DiGraph, names: list[str], nodes: np.ndarray, k: int, max_skip: int,
                 index_min_nodes: int = INDEX_MIN_NODES) -> None:
        index = {node: i for i, node in enumerate(names)}
        self.nodes_compared = nodes
        self.params = {"k": k, "max_skip": max_skip}
        self.index_min_nodes = index_min_nodes
        self.succ = _fan(graph, names, index, max_skip, forward=True)
        self.pred = _fan(graph, names, index, max_skip, forward=False)
        self._index = None  # the spatial index of the nodes, built by the first search that uses it
        self._scan = PoseScan(nodes)  # the scan of every node (the planes, built once per graph)

    def search(self, obs: np.ndarray, vis: np.ndarray,
               exclude: np.ndarray | None = None) -> tuple[np.ndarray | None, float, int]:
        """The best path (node indices, one per sample), its eq. 3 cost and the number of samples with evidence.

        ``obs`` (n, P, 3) and ``vis`` (n, P) are the samples, compared with the nodes; ``exclude`` (N,): nodes no
        path may use."""
        has = vis.any(axis=1)
        if not has.any():
            return None, 0.0, 0
        n = len(obs)
        mid = n // 2
        ev = np.flatnonzero(has)
        mid = int(ev[np.argmin(np.abs(ev - mid))])  # the visible frame nearest the middle
        nodes = self.nodes_compared
        k = self.params["k"]
        indexed = exclude is None
        if indexed and len(nodes) > self.index_min_nodes:
            if getattr(self, "_index", None) is None or self._index.poses is not nodes:
                self._index = PoseIndex(nodes)
            start, costs = self._index.nearest(obs[mid], vis[mid], k)  # the scan's k nearest, in its order
        else:
            every = vis[mid].all()  # every part seen: eq. 1 over every part, as the beam's
            # score computes it (the same numbers as pose_distance: its masked sum over n parts is the mean)
            if every and (getattr(self, "_scan", None) is None or self._scan.poses is not nodes):
                self._scan = PoseScan(nodes)
            screened = self._screened(obs[mid], k) if every and exclude is None else None
            if screened is not None:
                start, costs = screened
            else:
                first = self._scan(obs[mid]) if every else pose_distance(nodes, obs[mid], vis[mid])
                if exclude is not None:
                    first = np.where(exclude, np.inf, first)
                start = self._starts(first, k)
                costs = first[start]
        # beams: array of paths (B, length) and costs (B,)
        paths = start[:, None]
        paths, costs = self._extend(paths, costs, obs, vis, range(mid + 1, n), self.succ, exclude, append=True)
        paths, costs = self._extend(paths, costs, obs, vis, range(mid - 1, -1, -1), self.pred, exclude,
                                    append=False)
        best = int(np.argmin(costs))
        return paths[best], float(costs[best]), int(has.sum())

    def _extend(self, paths, costs, obs, vis, frames, table, exclude, *, append: bool):
        nodes = self.nodes_compared
        if getattr(self, "_scan", None) is None or self._scan.poses is not nodes:
            self._scan = PoseScan(nodes)
        scan = self._scan
        k = self.params["k"]
        ends = paths[:, -1] if append else paths[:, 0]
        steps = []  # per sample: each kept path's new node and the path it grew from (back-pointers)
        for t in frames:
            seen = vis[t]
            every = seen.all()

            def score(cand, t=t, seen=seen, every=every):
                if every:  # the hot loop of the search: eq. 1 over every part, inline
                    return scan(obs[t], cand)  # (pose_distance's arithmetic without its checks: the same numbers)
                if seen.any():  # eq. 1 over the parts seen in this sample: the mask is the same for every candidate,
                    # so the seen parts are taken first and pose_distance needs no mask
                    return pose_distance(nodes[cand][:, seen], obs[t, seen], None)
                return np.zeros(len(cand))

            beam, cand = _candidates(table, ends, costs, score)
            step = score(cand)
            if exclude is not None:
                step = np.where(exclude[cand], np.inf, step)
            total = costs[beam] + step
            order = total.argsort(kind="stable")
            # k best, one path per end node (distinct hypotheses): the first time each end node comes in the order
            first = _firsts(cand[order])
            keep = order[np.sort(first)][:k]
            steps.append((cand[keep], beam[keep]))
            ends, costs = cand[keep], total[keep]
        if not steps:
            return paths, costs
        if len(steps) == 1:  # one sample: the kept paths' nodes and the paths they grew from, as they are
            grown, row = steps[0][0][:, None], steps[0][1]
            return (np.hstack([paths[row], grown]) if append else np.hstack([grown, paths[row]])), costs
        row, grown = np.arange(len(ends)), []
        for node, parent in reversed(steps):  # follow the back-pointers from the last sample to the first
            grown.append(node[row])
            row = parent[row]
        grown = np.stack(grown[::-1], axis=1)  # (B, samples) in the order the samples were taken
        return (np.hstack([paths[row], grown]) if append else np.hstack([grown[:, ::-1], paths[row]])), costs

    def _screened(self, query: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray] | None:
        """:meth:`_starts` of every node's eq. 1 distance to ``query`` (every part seen) and the start nodes' distances
        (the scan's numbers), measuring few nodes with the scan's arithmetic; ``None`` where the screen does not
        apply (a coordinate not finite, or no more nodes than ``k``).

        All nodes are measured in single precision first (:meth:`PoseScan.approximate`, with a bound ``e`` of its
        error); a node can be among the k nearest (or tied with the k-th) only if its approximation is within
        ``2e`` of the k-th smallest approximation. Those few are measured again with the scan's arithmetic, and
        chosen among as :meth:`_starts` chooses among all: the k best by (distance, node). Every other node is
        farther than each of those choices."""
        n = len(self.nodes_compared)
        if n <= k:
            return None
        screen = self._scan.approximate(query)
        if screen is None:
            return None
        near, error = screen
        margin = 2.0 * error
        wanted = near <= np.partition(near, k - 1)[k - 1] + margin
        rows = np.flatnonzero(wanted)  # ascending: node order
        first = self._scan(query, rows)
        kth = np.partition(first, k - 1)[k - 1]
        chosen = np.flatnonzero(first <= kth)  # positions in rows; the k best and the nodes tied with the k-th
        chosen = chosen[np.lexsort((chosen, first[chosen]))][:k]  # by (distance, node): rows ascend with positions
        return rows[chosen], first[chosen]

    def _starts(self, first: np.ndarray, k: int) -> np.ndarray:
        """``np.argsort(first, kind="stable")[:k]`` without sorting all N nodes: the start nodes of a search from
        every node's distance ``first`` (N,), best first (ties: the lower node).

        The k best are the nodes up to the k-th smallest distance (:func:`numpy.partition`), ranked by (distance,
        node) as the stable sort ranks them. With NaN distances (which the sort puts last) the sort itself
        answers."""
        n = len(first)
        if n <= k or np.isnan(first).any():
            return np.argsort(first, kind="stable")[:k]
        kth = np.partition(first, k - 1)[k - 1]
        chosen = np.flatnonzero(first <= kth)  # the k best and the nodes tied with the k-th: the first k by node
        return chosen[np.lexsort((chosen, first[chosen]))][:k]


class Beam(Search):
    """The paper's k-best beam from the middle frame (:mod:`plugins.matchers.path_search.kbest`): the majority
    movement of the best path; runners-up (``candidates``) each from one more search without the movements found."""

    def rebuild(self) -> None:
        m = self.matcher
        options = m.params["beam"]
        self.kbest = KBest(m.motor.graph, m.node_names, m.motor.node_root_relative, options["k"],
                           options["max_skip"], m.index_min_nodes)

    def find(self, samples, motion):
        m = self.matcher
        obs, vis = samples.parts, samples.seen
        path, _, evidence = self.kbest.search(obs, vis)
        if path is None:
            return None
        ids = m.label_ids[path]
        voting = ids[ids != m.hub_id]  # the movements' numbers: hubs do not vote
        mean = path_distance(obs, m.motor.node_root_relative[path], vis) / max(evidence, 1)  # eq. 3 per sample
        details: dict[str, Any] = {"mean_distance": mean, "samples": len(path)}
        if voting.size == 0:
            return Found(None, path, 0.0, (), details)
        counts = np.bincount(voting)  # np.unique(voting, return_counts=True): the numbers voted for, ascending
        numbers = counts.nonzero()[0]
        counts = counts[numbers]
        names = m.label_names[numbers]  # the names in their order, as np.unique over the names gives them
        best = int(np.argmax(counts))
        movement = str(names[best])
        details["votes"] = {str(n): int(c) for n, c in zip(names, counts)}
        found = [(movement, mean)]
        exclude = m.labels == movement
        for _ in range(m.params["candidates"]):  # Fig. 13: the best path through the other movements' nodes
            other_path, cost, other_evidence = self.kbest.search(obs, vis, exclude)
            if other_path is None or not np.isfinite(cost):  # no path through the movements left
                break
            others = m.labels[other_path][m.labels[other_path] != ""]
            if others.size == 0:
                break
            values, tally = np.unique(others, return_counts=True)
            other = str(values[int(np.argmax(tally))])
            found.append((other, float(path_distance(obs, m.motor.node_root_relative[other_path], vis)
                                        / max(other_evidence, 1))))
            exclude = exclude | (m.labels == other)
        ranked = (found[0], *sorted(found[1:], key=lambda c: c[1]))
        still = float(np.mean(m.comparison.still(samples))) if m.decision.relative else 1.0
        return Found(movement, path, counts[best] / voting.size, ranked, details, still)

    def calibration(self):
        m = self.matcher
        own, other = [], []
        for movement, takes in m.take_nodes.items():
            for take in takes:
                obs = m.motor.node_root_relative[take]
                vis = np.ones(obs.shape[:2], dtype=bool)
                still = float(np.mean(m.comparison.still(m.comparison.frames(obs, vis, m.motor.node_rate))))
                mine = m.labels == movement
                searches = ((other, mine),)
                if len(takes) > 1:
                    alone = ~mine
                    alone[take] = True
                    searches += ((own, alone),)
                for out, exclude in searches:
                    path, _, evidence = self.kbest.search(obs, vis, exclude)
                    if path is not None:
                        d = path_distance(obs, m.motor.node_root_relative[path], vis) / max(evidence, 1)
                        out.append(d / still if still > 0 else np.inf)
        return Calibration.of(own, other)


class Fan(NamedTuple):
    """For every node, the nodes reachable in 0..max_skip steps along (or against) the edges (its *reach*), factored
    through the wide nodes (hubs), so that a beam step need not list every movement's first nodes once per path
    that reaches a hub, and so that the table grows with the graph, not with the graph times its largest hub.

    A node reaches (in 0..max_skip steps) its *local* nodes, found without passing through a wide node, and for
    each wide node ``h`` it reaches at distance ``j`` without passing through another, every node within
    ``max_skip - j`` steps of ``h``: the *rings* of ``h`` at distances 0..max_skip - j. (A shortest path to a node
    either meets no wide node, or meets a first one at the distance found without passing through another; so the
    union is exactly the node's reach.)"""

    full: tuple[np.ndarray, np.ndarray]
    """Compressed rows (indptr, sorted node indices): each short node's whole reach (a long node's row is empty)."""
    long: np.ndarray
    """(N,) bool: the nodes whose reach is longer than :data:`LONG_ROW` and passes a wide node: listed factored."""
    local: tuple[np.ndarray, np.ndarray]
    """Compressed rows (indptr, sorted node indices): each long node's local nodes (itself included)."""
    wide: tuple[np.ndarray, np.ndarray, np.ndarray]
    """Compressed rows (indptr, wide node number, distance): the wide nodes each long node reaches first."""
    rings: tuple[np.ndarray, np.ndarray]
    """Compressed rows (indptr, sorted node indices), row ``w * (max_skip + 1) + d``: the nodes at exactly ``d``
    steps from wide node number ``w``."""
    max_skip: int
    padded: np.ndarray | None = None
    """(N, W) each node's whole reach (``full``'s row) padded with -1 to the longest row W, when no node is long and
    W is at most :data:`LONG_ROW`: a beam step lists its candidates with one indexing."""


WIDE = 8
"""Nodes with more successors (or predecessors, backward) than this are wide: :class:`Fan` factors the reach
through them (a posegraph's hubs, each shared by many movements)."""

LONG_ROW = 64
"""Nodes that reach more nodes than this (through a wide node) have their reach listed factored; shorter rows are
listed whole, as fast as ever on small graphs."""


def _rows(rows: list[list[int]]) -> tuple[np.ndarray, np.ndarray]:
    """Compressed rows (indptr, indices) of lists of node indices, each row sorted."""
    indptr = np.zeros(len(rows) + 1, dtype=np.intp)
    np.cumsum([len(r) for r in rows], out=indptr[1:])
    flat = [i for r in rows for i in sorted(r)]
    return indptr, np.array(flat, dtype=np.intp)


def _fan(graph, nodes, index, max_skip: int, *, forward: bool) -> Fan:
    """Every node's reach factored through the wide nodes (:class:`Fan`).

    Each node's *local* nodes by a breadth-first search that stops at the wide nodes (recording the distance at
    which it meets each); each wide node's rings by one breadth-first search (networkx's, bounded by ``max_skip``).
    A node's whole reach is the union of its local nodes and the rings within ``max_skip`` minus the distance of
    each wide node it meets; it is listed whole only where it is short (at most :data:`LONG_ROW` nodes), so no row
    as long as a hub's fan is ever built."""
    g = graph if forward else graph.reverse(copy=False)
    succ = [[index[m] for m in g.successors(node)] for node in nodes]
    wide_nodes = [i for i, s in enumerate(succ) if len(s) > WIDE]
    number = {h: w for w, h in enumerate(wide_nodes)}
    rings, within = [], []  # within[w][r]: the nodes at most r steps from wide node w, sorted
    for h in wide_nodes:
        by_distance = [[] for _ in range(max_skip + 1)]
        for m, d in nx.single_source_shortest_path_length(g, nodes[h], cutoff=max_skip).items():
            by_distance[d].append(index[m])
        rings.extend(by_distance)
        so_far: list[int] = []
        upto = []
        for ring in by_distance:
            so_far = so_far + ring
            upto.append(np.sort(np.asarray(so_far, dtype=np.intp)))
        within.append(upto)
    long = np.zeros(len(nodes), dtype=bool)
    rows, local, first, dist = [], [], [], []
    for i in range(len(nodes)):
        if i in number:  # a wide node reaches everything through itself
            found, hubs = [i], {i: 0}
            parts = [within[number[i]][max_skip]]
        else:
            seen, frontier, hubs = {i}, [i], {}
            for depth in range(1, max_skip + 1):
                nxt = []
                for f in frontier:
                    for m in succ[f]:
                        if m in seen or m in hubs:
                            continue
                        if m in number:
                            hubs[m] = depth  # not passed through: its rings stand for what lies beyond
                        else:
                            seen.add(m)
                            nxt.append(m)
                frontier = nxt
            found = list(seen)
            parts = [np.asarray(found, dtype=np.intp)] + [within[number[h]][max_skip - d] for h, d in hubs.items()]
        sizes = [len(p) for p in parts]
        if max(sizes) > LONG_ROW:  # long whatever the others add
            row = None
        else:  # short parts: their union is cheap (at most a few times LONG_ROW nodes)
            row = np.unique(np.concatenate(parts)) if len(parts) > 1 else np.sort(parts[0])
            if len(row) > LONG_ROW:
                row = None
        long[i] = row is None and bool(wide_nodes)
        if row is None and not wide_nodes:  # no wide node to factor through: listed whole however long
            row = np.sort(parts[0])
        rows.append(row if row is not None else np.zeros(0, dtype=np.intp))
        if long[i]:
            local.append([i] if i in number else found)
            first.append([number[h] for h in hubs])
            dist.append(list(hubs.values()))
        else:
            local.append([])
            first.append([])
            dist.append([])
    widths = np.array([len(r) for r in rows], dtype=np.intp)
    indptr = np.zeros(len(nodes) + 1, dtype=np.intp)
    np.cumsum(widths, out=indptr[1:])
    full = (indptr, np.concatenate(rows).astype(np.intp) if rows else np.zeros(0, dtype=np.intp))
    wide_ptr = np.zeros(len(nodes) + 1, dtype=np.intp)
    np.cumsum([len(r) for r in first], out=wide_ptr[1:])
    wide = (wide_ptr, np.array([w for r in first for w in r], dtype=np.intp),
            np.array([d for r in dist for d in r], dtype=np.intp))
    padded = None
    if not long.any() and widths.max(initial=0) <= LONG_ROW:
        padded = np.full((len(nodes), widths.max(initial=0)), -1, dtype=np.intp)
        padded[np.repeat(np.arange(len(nodes)), widths), np.arange(len(full[1])) - np.repeat(full[0][:-1], widths)] = \
            full[1]
    return Fan(full, long, _rows(local), wide, _rows(rings), max_skip, padded)


def _candidates(fan: Fan, ends: np.ndarray, costs: np.ndarray, score) -> tuple[np.ndarray, np.ndarray]:
    """The (beam index, node) pairs of a beam step, in the order of :func:`_gather` on each node's whole reach (by
    beam, then node), keeping of the pairs through a wide node only those that can be the best way to their node.

    A node ``c`` at ``d`` steps from wide node ``h`` is reached through ``h`` by every path whose end reaches ``h``
    within ``max_skip - d`` steps, all at the same step cost ``score(c)``: the beam step keeps, for each node, the
    pair of the least total cost (ties: the first pair, the lowest beam index). Only the paths that can give that
    pair are listed: those of the least cost up to rounding (a cost within 2**-50 of the cost plus the largest step
    of ``h``'s ring), the lowest beam index (every total infinite), and as many more as there are paths that end in
    the ring (the one pair whose stay may be barred). Near a hub every movement's first nodes are then listed once
    or twice instead of once per path that reaches the hub."""
    if fan.padded is not None:  # every row short, at most LONG_ROW: one indexing (the same pairs in the same order)
        rows = fan.padded[ends]
        listed = rows >= 0
        return listed.nonzero()[0], rows[listed]
    long = fan.long[ends]
    if not long.any():  # every row short: listed whole
        return _gather(fan.full, ends)
    short = np.flatnonzero(~long)
    beam, cand = _gather(fan.full, ends[short])
    beams, nodes = [short[beam]], [cand]
    factored = np.flatnonzero(long)
    beam, cand = _gather(fan.local, ends[factored])
    beams.append(factored[beam])
    nodes.append(cand)
    indptr, wide, dist = fan.wide
    counts = indptr[ends[factored] + 1] - indptr[ends[factored]]
    via = np.repeat(factored, counts)
    at = _gather((indptr, np.arange(len(wide), dtype=np.intp)), ends[factored])[1]
    wide, dist = wide[at], dist[at]
    ring_ptr, ring_nodes = fan.rings
    span = fan.max_skip + 1
    for w in np.unique(wide):
        mine = wide == w
        for d in range(span):
            row = w * span + d
            ring = ring_nodes[ring_ptr[row]:ring_ptr[row + 1]]
            parents = via[mine & (dist <= fan.max_skip - d)]  # distinct: one distance per path and wide node
            if not len(ring) or not len(parents):
                continue
            if len(parents) > 1:
                c = costs[parents]
                inside = int(np.isin(ends[parents], ring).sum())  # paths ending in the ring: their stay may be barred
                ranked = np.lexsort((parents, c))
                top = c[ranked[min(inside, len(ranked) - 1)]]
                steps = score(ring)
                largest = float(steps[np.isfinite(steps)].max(initial=0.0))
                keep = c <= top + 2.0 ** -50 * (top + largest)
                keep[np.argsort(parents, kind="stable")[: inside + 1]] = True
                parents = parents[keep]
            beams.append(np.repeat(parents, len(ring)))
            nodes.append(np.tile(ring, len(parents)))
    beam, cand = np.concatenate(beams), np.concatenate(nodes)
    order = np.lexsort((cand, beam))
    return beam[order], cand[order]


def _firsts(values: np.ndarray) -> np.ndarray:
    """Where each distinct value of ``values`` (1-D) comes first, in the order of the values:
    ``np.unique(values, return_index=True)[1]`` as NumPy computes it (a stable sort, the head of each run), without
    its other work."""
    perm = values.argsort(kind="stable")
    ordered = values[perm]
    head = np.empty(len(ordered), dtype=bool)
    head[:1] = True
    np.not_equal(ordered[1:], ordered[:-1], out=head[1:])
    return perm[head]


def _gather(table: tuple[np.ndarray, np.ndarray], ends: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The candidates reachable from each end node of a beam: (beam index of each candidate, candidate node)."""
    indptr, indices = table
    counts = indptr[ends + 1] - indptr[ends]
    beam = np.repeat(np.arange(len(ends)), counts)
    within = np.arange(len(beam)) - np.repeat(np.cumsum(counts) - counts, counts)
    return beam, indices[indptr[ends][beam] + within]

