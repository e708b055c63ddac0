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
movement seen only in part still finds its part, §5.2.3), then again with the samples' motion at the pace the first
warping found for the chain (:mod:`plugins.matchers.tempo`: a performance up to four times slower or faster than a
take is compared at the take's tempo); a movement's score is its nearest take's, relative to the samples' distance
to standing still at that take's tempo, and the movements are ranked by it (``comparison = "motion+strokes"`` mixes
in the takes' strokes: :mod:`plugins.matchers.path_search.evidence`). The decision is calibrated on the takes
compared alike (:meth:`plugins.matchers.path_search.evidence.Evidence.calibration`).
"""

from __future__ import annotations

import numpy as np

from plugins.matchers.comparison import Frames
from plugins.matchers.decision import Calibration
from plugins.matchers.path_search.search import Found, Search
from plugins.matchers.tempo import paced_distances
from plugins.matchers.warping import Chains, chain_path

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
        if self.takes:
            m.evidence.rebuild(self)

    def find(self, samples, motion):
        if self.nodes is None or not samples.seen.any():
            return None
        m = self.matcher
        paced = paced_distances(m.comparison, samples, self.nodes, self.chains)
        # ranked by the relative score itself (each chain's distance over the demonstration's distance to standing
        # still at its pace), which the decision then takes as it is; a demonstration that does not move at all has
        # none (inf): its distances, over a distance to standing still of 0 (the decision's score is 0 for a
        # distance of 0, else inf); a decision that is not relative takes the distances
        relative = m.decision.relative and bool(np.isfinite(paced.scores).any())
        values = m.evidence.scores(paced, motion) if relative else paced.distances
        still = 0.0 if m.decision.relative and not relative else 1.0
        best: dict[str, int] = {}
        for c, movement in enumerate(self.chains.movements):
            if np.isfinite(values[c]) and (movement not in best or values[c] < values[best[movement]]):
                best[movement] = c
        if not best:
            return None
        ranked = tuple((mv, float(values[c])) for mv, c in sorted(best.items(), key=lambda kv: (values[kv[1]], kv[0])))
        chosen = best[ranked[0][0]]
        path = chain_path(paced.cost, self.chains, chosen)
        return Found(ranked[0][0], path, 1.0, ranked, {"mean_distance": float(paced.distances[chosen]),
                                                       "pace": float(paced.pace[chosen]), "samples": len(samples)},
                     still)

    def calibration(self) -> Calibration:
        if not self.takes:
            return Calibration()
        return self.matcher.evidence.calibration(self)
