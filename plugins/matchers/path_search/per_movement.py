"""Path search's exact search: each movement's best path through the posegraph, by dynamic programming.

Buchsbaum & Blumberg 2005, §5.2 search the posegraph for the path nearest to the observed samples (eq. 3) with a
beam of k paths grown from the k poses nearest the middle frame (:mod:`plugins.matchers.path_search.kbest`). On a
repertoire of real clips the true movement's own best path is often not among them: a long varied clip's many
poses fill the k starts, and the middle frame of a styled performance lies nearer some other movement's poses.
This search cannot lose a movement: it finds, for every movement, the path through that movement's own nodes
that is nearest to the samples, exactly, and ranks the movements by it.

A movement's nodes are the takes it was built from (:meth:`Posegraph.takes`: one chain of nodes per clip, hubs
left out; a clip that loops, a walk's cycle, joins its last node to its first). The samples are warped against
every chain at once (:mod:`plugins.matchers.warping`: dynamic time warping free to begin and end at any node, so a
movement seen only in part still finds its part, §5.2.3; any tempo, no limit to set); a movement's distance is its
nearest take's, and the movements are ranked by it.
"""

from __future__ import annotations

import numpy as np

from plugins.matchers.comparison import Frames
from plugins.matchers.decision import Calibration
from plugins.matchers.path_search.search import Found, Search
from plugins.matchers.warping import Chains, chain_calibration, chain_distances, chain_path

__all__ = ["EachMovement", "posegraph_chains"]


def posegraph_chains(motor) -> Chains:
    """The chains of a posegraph motor system: one per take (its ``takes()``), in node order, hubs left out; a take
    whose last node leads back to its first (``graph``) loops."""
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
    return Chains(np.asarray(nodes, dtype=np.intp), np.asarray(starts, dtype=np.intp), tuple(movements),
                  np.asarray(cyclic, dtype=bool))


class EachMovement(Search):
    """Every movement's own best path, exactly (:mod:`plugins.matchers.path_search.per_movement`)."""

    def rebuild(self) -> None:
        m = self.matcher
        self.chains = posegraph_chains(m.motor)
        self.takes = [m.take_frames(self.chains.chain(c)) for c in range(len(self.chains))]
        self.nodes = Frames.join(self.takes) if self.takes else None

    def find(self, samples):
        if self.nodes is None or not samples.seen.any():
            return None
        m = self.matcher
        per_chain, cost = chain_distances(m.comparison, samples, self.nodes, self.chains)
        distances: dict[str, float] = {}
        for movement, d in zip(self.chains.movements, per_chain):
            distances[movement] = min(distances.get(movement, np.inf), float(d))
        ranked = tuple(sorted(((mv, d) for mv, d in distances.items() if np.isfinite(d)), key=lambda c: (c[1], c[0])))
        if not ranked:
            return None
        best = int(np.argmin(per_chain))
        path = chain_path(cost, self.chains, best)
        return Found(ranked[0][0], path, 1.0, ranked, {"mean_distance": ranked[0][1], "samples": len(samples)})

    def calibration(self) -> Calibration:
        return chain_calibration(self.matcher.comparison, self.takes, self.nodes, self.chains)
