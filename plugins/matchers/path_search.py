"""Matcher ``path-search``: the observed movement as the closest path through one's own posegraph.

Buchsbaum & Blumberg 2005, §5.2 (Fig. 5-8):

1. take a *representative frame from the middle* of the observed segment (the
   middle is less generic than the transitional beginning and end);
2. search *the whole graph* for the k poses nearest to it by eq. 1 (the only
   whole-graph search);
3. from those k nodes explore outward along the graph's edges, one observed
   frame at a time, keeping the k best paths by eq. 3 (the summed eq. 1);
4. the movement to which the majority of the best path's nodes belong is the
   recognised movement (§5.2.3: a partly seen movement, or one with extra frames
   before and after, still has most of its path inside the right movement).

Observed frames are sampled at the posegraph's ``node_rate`` so one step along
an edge corresponds to one observed sample; a path may also stay on a node or
skip up to ``max_skip - 1`` nodes per sample, so the same movement performed
slower or faster (Morris's longer cover face, §5.2.2) still aligns. Hub nodes
belong to no movement and do not vote. Hidden parts are left out of every
distance (eq. 1 over visible parts); samples with nothing visible cost nothing.

The answer is "unknown" when the best path's mean pose distance (eq. 3 over
the samples with evidence, :func:`plugins.lib.pose_distance.path_distance`)
exceeds ``max_distance``; with ``learn = true`` that path is then added to the
posegraph as a new movement (§5.2.3, §7.3). What path search needs of the motor
system is the :class:`PoseGraph` protocol, checked when it is attached.

Decisions relative to the repertoire (issue 18; not in the paper): with ``spread`` > 0, a movement the
repertoire holds several takes of (several clips: performers, styles) is accepted up to ``spread`` times its own
*spread between takes*: the median, over its takes, of the mean eq. 1 distance from the take to the nearest path
through the rest of the graph when that take's own nodes are left out. A movement people perform alike is then held
to a tight threshold, one they perform in many ways to a loose one; a movement of one take keeps ``max_distance``.

Travel (issue 18; not in the paper, which compares root-relative poses only, §5.1): with ``travel`` = τ > 0
seconds, where the body goes is compared as one more part: the root's displacement over τ at its current velocity
in the body's own frame (:mod:`plugins.lib.travel`), observed from the motion's world positions and, for the
graph's nodes, from the clips or key poses they were sampled from (``node_travel``, the :class:`Travelling`
protocol). A walk forwards, a walk backwards and a run then differ as they do to the eye, not only in the legs.
Where the motion's world positions are not known the travel part is hidden, and eq. 1 leaves it out.

Style (issue 18; not in the paper, which compares the poses as they are, §5.1 eq. 1): with ``posture = "removed"``
the demonstration is compared about its own mean posture over the segment and each node about its take's, so a
posture held through the whole movement (a stoop, a wide stance) cancels; with ``"still"`` each part's posture is
removed, from the demonstration and from every node alike, as far as the part is still in the demonstration, so the
stance cancels and where the moving parts go still counts; with ``amplitude`` = a the demonstration and each take are
scaled about their posture to the repertoire's median take amplitude, at most a times either way
(:mod:`plugins.lib.style`). With ``separation`` = s a movement is unknown beyond s times its distance to the
repertoire's other movements.

Tempo (issue 18; not in the paper, whose nodes are taken at one rate, §4.1): with the posegraph's ``tempo``, each
clip is sampled at the node rate times its own *frequency* (its RMS speed over its RMS distance from its mean posture,
:func:`plugins.lib.style.frequency`) over the repertoire's median, so a node is a step of the movement's own time;
the demonstration is sampled the same way, so a movement performed much slower or faster than one's own (a tired
guide, a brisk wave) still aligns one sample to one node, as ``max_skip`` and ``max_stay`` allow for up to twice.

Two limits on the search itself (issue 18; both off by default, the paper's search). ``per_movement`` keeps, besides
the k best paths, the best path ending in each movement at every sample (and starts from each movement's nearest
pose too): §5.2 starts from the k poses nearest the middle frame over the whole graph, and a repertoire of real
clips has long varied clips (a dance of a minute) whose many poses fill all k starts, so a movement of ten nodes
never gets a hypothesis. ``max_stay`` limits how many samples in a row a path may stay on one node, as ``max_skip``
limits how far it may jump: without it a path may stand on one pose of a long clip that resembles the average of a
whole demonstration, which explains no movement.

Ranked candidates (Buchsbaum & Blumberg Fig. 13): with ``candidates`` = n > 0 the answer also ranks up to n runners-up
(``Match.candidates``): the best path through the graph that leaves out the recognised movement's nodes is the second
explanation, its majority movement the second candidate, and so on, each with its mean eq. 3 distance. When two are
about as close (a reach and a jump that look alike), the observer's can-I triggers choose between them
(:mod:`plugins.action.behaviour_identification`). Each candidate is one more search: 0, the paper's single answer, is
the default.

The whole-graph search of step 2 (issue 22): on a posegraph of more than :data:`INDEX_MIN_NODES` nodes the k start
poses come from a spatial index (:class:`plugins.lib.pose_index.PoseIndex`, built on the first search and again
after the graph learns), which gives exactly the scan's k nearest in the scan's order. Below that size the scan is
as fast. The scan is kept, exact by construction, where the index would have to answer another question: with
attention (weights), with nodes excluded (the spread between takes), and with ``per_movement`` (each movement's
nearest pose, however far). Where every part of the middle sample is seen, that scan is screened
(:meth:`PathSearch._screened`): every node measured in single precision with a bound of the error
(:meth:`plugins.lib.pose_distance.PoseScan.approximate`), and only the nodes that can be chosen (within twice the
bound of the k-th nearest or of their movement's nearest) measured again with the scan's arithmetic, so the start
nodes and their costs are the scan's to the last bit.

Hubs (issue 22): a path that ends near a hub reaches, through it, the first nodes of every movement, and with
``per_movement`` (one path per movement in the beam) a beam step would list those nodes once per path near the hub:
candidates growing as the square of the movements. The reach tables are factored through the wide nodes
(:class:`Fan`): a step lists each node's local reach, and a hub's onward nodes only for the paths that can be the
best way to them (the least cost up to rounding; :func:`_candidates`), which keeps exactly the paths the full
listing keeps.
"""

from __future__ import annotations

from typing import Any, NamedTuple, Protocol

import networkx as nx
import numpy as np

from plugins.lib.attention import movement_weights
from plugins.lib.pose_distance import PoseScan, path_distance, pose_distance
from plugins.lib.pose_index import PoseIndex
from plugins.lib.style import extent, mean_posture, rescale, stillness, take_means
from plugins.lib.travel import body_velocity, travel_part
from toolkit import Match, Matcher, Motion, Parameter, hookimpl
from toolkit.components import provides

__all__ = ["INDEX_MIN_NODES", "PathSearch", "PoseGraph", "Takes", "Travelling"]

INDEX_MIN_NODES = 5000
"""Posegraphs of more nodes than this find the k start poses with :class:`plugins.lib.pose_index.PoseIndex`
(``likeme bench posegraph``: the scan takes about 1.5 ms at 10,000 nodes of 11 parts; below a few thousand the
index gains nothing worth its tree)."""


class PoseGraph(Protocol):
    """A posegraph: whole-body poses as nodes, movements as paths between hubs (Buchsbaum & Blumberg 2005, §4.1).

    What path search needs of a motor system: ``plugins.motor.posegraph`` provides it.
    """

    graph: nx.DiGraph
    """Nodes by name; an edge from each pose to the next of its movement (hubs are shared)."""
    node_root_relative: np.ndarray
    """Every node's pose, root-relative, (N, P, 3), in the order of :attr:`nodes`."""
    node_rate: float
    """Pose nodes per second of movement."""

    @property
    def nodes(self) -> list[str]:
        """Node names in the order of ``node_root_relative``."""

    def movement_of(self, node: str) -> str | None:
        """The movement a node belongs to (``None`` for a hub)."""

    def movements(self) -> list[str]:
        """The movements of the repertoire."""

    def learn(self, name: str, poses: np.ndarray, visible: np.ndarray | None = None, *, source: str = "",
              announce: bool = True) -> list[str]:
        """Add an observed path of root-relative poses as a new movement; its nodes."""


class Takes(Protocol):
    """A posegraph that knows which nodes came from which take (example clip) of each movement."""

    def takes(self) -> dict[str, list[list[str]]]:
        """Movement -> the node names of each of its takes (hubs left out)."""


class Travelling(Protocol):
    """A posegraph that knows each node's travel: the root's velocity in the body's frame (m/s), (N, 3), in the
    order of ``node_root_relative`` (:mod:`plugins.lib.travel`)."""

    node_travel: np.ndarray


MEASURE = "mean pose distance along the path (eq. 3)"
"""What a match's ``score`` and ``threshold`` are."""


class PathSearch(Matcher):
    """k-best path search through the observer's posegraph from the middle frame outward (§5.2)."""

    name = "path-search"
    motor_systems = ("posegraph",)
    report_details = ("learned",)
    index_min_nodes = INDEX_MIN_NODES
    """Above this many nodes the start poses come from the spatial index (tests set it to force the index on or
    off)."""
    parameters = (
        Parameter("k", int, 8, "Number of start poses and of paths kept at every step (the beam width). "
                  "Larger is more robust to noise and occlusion, and slower.", minimum=1),
        Parameter("max_skip", int, 2, "Most nodes a path may advance per observed sample (0 = stay is always "
                  "allowed); 2 tolerates movements up to twice as fast as one's own.", minimum=1, maximum=5),
        Parameter("per_movement", bool, False, "Besides the k best paths, keep the best path ending in each movement "
                  "at every sample, and start from each movement's nearest pose too: a movement of few nodes is not "
                  "crowded out of the beam by a long clip's many similar poses (false: the k best only, the "
                  "paper)."),
        Parameter("max_stay", int, 0, "Most samples in a row a path may stay on one node; 1 tolerates movements "
                  "down to half one's own speed, as max_skip = 2 tolerates twice it. 0: no limit (a path may stand "
                  "on one pose that resembles a whole movement's average, as a long varied clip has).", minimum=0),
        Parameter("max_distance", float, 0.03, "Mean eq. 1 distance (m) per sample above which the answer is "
                  "'unknown'. Must stay above the noise of the input (about 1.8 x its standard deviation).", minimum=0.0, length=True),
        Parameter("scale", float, 0.02, "Distance (m) at which confidence falls to 1/e.", minimum=1e-6, length=True),
        Parameter("spread", float, 0.0, "A movement with several takes is unknown beyond this many times its "
                  "spread between takes (each take's mean eq. 1 distance to the rest of the graph); 0: "
                  "max_distance for every movement (the paper).", minimum=0.0),
        Parameter("separation", float, 0.0, "A movement is unknown beyond this share of its separation from the "
                  "repertoire's other movements (the median over its takes of the take's mean eq. 1 distance to the "
                  "best path through the other movements' nodes): 0.5 accepts a demonstration nearer to the movement "
                  "than halfway to its nearest neighbour; with spread, the smaller limit holds; 0: max_distance (the "
                  "paper).", minimum=0.0),
        Parameter("spread_quantile", float, 0.5, "Which quantile of a movement's take distances (each take's mean "
                  "eq. 1 distance to the rest of the graph) is its spread: 0.5 the median take, 1 the take farthest "
                  "from the others, so with spread = 1 a new take is accepted as far as the repertoire's own most "
                  "different take lies.", minimum=0.0, maximum=1.0),
        Parameter("still_spread", bool, False, "With posture = 'still', measure the spreads and separations as "
                  "matches are compared: each take about the same share of its parts' postures as its own stillness "
                  "asks for (false: with every posture kept, as built)."),
        Parameter("attention", float, 0.0, "How much the parts that move in the segment count over the still ones "
                  "(plugins.lib.attention): 0 is eq. 1's plain mean over the visible parts, 1 counts only what "
                  "moves.", minimum=0.0, maximum=1.0),
        Parameter("posture", str, "kept", "'removed': compare each movement about its own held posture, the "
                  "demonstration's poses centred on their mean over the segment and each node's on its take's mean "
                  "(plugins.lib.style), so a stooped or proud performer's stance cancels, and where a hand is held "
                  "with it; 'still': each part's mean removed, from the demonstration and from every take alike, as "
                  "far as the part is still in the demonstration (plugins.lib.style's stillness), so the stance "
                  "cancels and where the moving parts go still counts; 'kept': eq. 1 on the poses as they are (the "
                  "paper).", choices=("kept", "removed", "still")),
        Parameter("amplitude", float, 0.0, "Compare movements' shapes at a common size: the demonstration and each "
                  "take are scaled about their mean posture to the repertoire's median take amplitude (RMS distance "
                  "of the parts from the mean posture, plugins.lib.style), by at most this factor either way, so an "
                  "exaggerated or timid style compares close; 0: as performed (the paper).", minimum=0.0,
                  check=lambda v: None if v == 0 or v >= 1 else "0 (off) or a factor of at least 1"),
        Parameter("travel", float, 0.0, "Seconds over which where the body goes counts as one more part: the root's "
                  "displacement over this time, in the body's frame (plugins.lib.travel); 0: root-relative poses "
                  "only (the paper).", minimum=0.0, maximum=10.0),
        Parameter("candidates", int, 0, "Ranked candidates to report besides the best (B&B Fig. 13): each is the "
                  "best path through the other movements' nodes (a search with the movements found so far left "
                  "out), with its mean eq. 3 distance; 0: the best only (one search).", minimum=0, maximum=10),
        Parameter("learn", bool, False, "Add an unknown movement's path to the posegraph as a new movement."),
        Parameter("learn_prefix", str, "learned", "Name prefix of learned movements (learned-1, learned-2...)."),
    )

    def attach(self, owner: Any) -> None:
        super().attach(owner)
        provides(owner.motor, PoseGraph, needed_by="path-search", what="a posegraph motor system",
                 expected=" or ".join(f'[motor] plugin = "{name}"' for name in self.motor_systems))
        self.motor = owner.motor
        if self.params["travel"] > 0:
            provides(owner.motor, Travelling, needed_by="path-search's travel", what="a posegraph that knows where "
                     "its nodes travel", key=("travel",), expected="travel = 0, or a motor system with node_travel "
                     "(posegraph)")
            import scipy.ndimage  # noqa: F401  (travel's filter: imported at set-up, not in the first match)
        if self.params["spread"] > 0:
            provides(owner.motor, Takes, needed_by="path-search's spread", what="a posegraph that knows its takes",
                     key=("spread",), expected="spread = 0, or a motor system with takes() (posegraph)")
        self._cache_version = -1
        self._refresh()  # the tables of the graph as composed, now rather than at the first match (rebuilt on learning)

    def _refresh(self) -> None:
        """(Re)build the successor and predecessor tables after the graph changed (learning)."""
        motor = self.motor
        n = motor.graph.number_of_nodes()
        if n == self._cache_version:
            return
        nodes = motor.nodes
        index = {node: i for i, node in enumerate(nodes)}
        self.node_names = nodes
        self.labels = np.array([motor.movement_of(nd) or "" for nd in nodes], dtype=object)
        self._label_names, self.label_ids = np.unique(self.labels.astype(str), return_inverse=True)  # a number per
        # movement, in the order of the names (so np.unique over numbers ranks as over names); hubs' "" comes first
        self._hub_id = 0 if len(self._label_names) and self._label_names[0] == "" else -1
        self._by_label = np.argsort(self.label_ids, kind="stable")  # the nodes grouped by movement, in node order
        self._label_starts = np.flatnonzero(np.diff(self.label_ids[self._by_label], prepend=-1))
        self._label_sizes = np.diff(self._label_starts, append=len(nodes))
        self.nodes_compared = self._styled_nodes(motor.node_root_relative, index)
        if self.params["travel"] > 0:  # travel: one more part of every node
            self.nodes_compared = np.concatenate(
                [self.nodes_compared, travel_part(motor.node_travel, self.params["travel"])[:, None]], axis=1)
        self.succ = _fan(motor.graph, nodes, index, self.params["max_skip"], forward=True)
        self.pred = _fan(motor.graph, nodes, index, self.params["max_skip"], forward=False)
        self._nodes_kept = self.nodes_compared
        self._cache_version = n
        self._index = None  # the spatial index of the nodes, built by the first search that uses it
        self._scan = PoseScan(self.nodes_compared)  # the scan of every node (the planes, built once per graph)
        self.take_distances = {}
        self.spreads = self._spreads(index) if self.params["spread"] > 0 else {}
        self.separations = self._separations(index) if self.params["separation"] > 0 else {}

    def _styled(self) -> bool:
        return self.params["posture"] != "kept" or self.params["amplitude"] > 0

    def _styled_nodes(self, poses: np.ndarray, index: dict[str, int]) -> np.ndarray:
        """The nodes' poses as compared (:mod:`plugins.lib.style`): each about its take's mean posture, removed with
        ``posture = "removed"``, scaled by ``amplitude`` to the repertoire's median take amplitude
        (:attr:`reference_amplitude`). The poses as they are when neither is set (the paper). With ``"still"`` the
        posture is kept here and each match removes the share the demonstration asks for (:meth:`_still_nodes`)."""
        self.reference_amplitude = 0.0
        if not self._styled():
            return poses
        takes = [take for clips in self._takes(index).values() for take in clips]
        posture, size = take_means(poses, takes)
        self._take_posture = posture
        sizes = [size[t[0]] for t in takes if len(t)]
        self.reference_amplitude = float(np.median(sizes)) if sizes else 0.0
        factor = np.ones(len(poses))
        if self.params["amplitude"] > 0:
            factor = np.array([rescale(z, self.reference_amplitude, self.params["amplitude"]) for z in size])
        base = 0.0 if self.params["posture"] == "removed" else posture
        return base + (poses - posture) * factor[:, None, None]

    def _styled_samples(self, poses: np.ndarray, visible: np.ndarray) -> np.ndarray:
        """The demonstration's sampled poses as compared: about their own mean posture over the segment, as
        :meth:`_styled_nodes` treats each take."""
        if not self._styled():
            return poses
        posture = mean_posture(poses, visible)
        posture = np.where(np.isfinite(posture), posture, 0.0)  # a part never seen is hidden in every sample
        factor = 1.0
        if self.params["amplitude"] > 0:
            factor = rescale(extent(poses, visible, posture), self.reference_amplitude, self.params["amplitude"])
        base = {"kept": posture, "removed": 0.0}.get(self.params["posture"])
        if base is None:  # still: each part's posture removed as far as the part is still in the segment
            self._stillness = stillness(poses, visible, posture)
            base = posture * (1.0 - self._stillness)[:, None]
        return base + (poses - posture) * factor

    def _still_nodes(self) -> np.ndarray:
        """``posture = "still"``: the nodes as compared with the demonstration just sampled, each part's take posture
        removed as far as the part is still in the demonstration (:attr:`_stillness`), as it is from the
        demonstration. The nodes as built (:attr:`_nodes_kept`, posture kept) stay for the spreads and
        separations."""
        nodes = self._nodes_kept.copy()
        body = self._take_posture.shape[1]
        nodes[:, :body] -= self._stillness[None, :, None] * self._take_posture
        return nodes

    def _takes(self, index: dict[str, int]) -> dict[str, list[np.ndarray]]:
        """Movement -> the node indices of each of its takes (``takes()``, the :class:`Takes` protocol; without it
        each movement is one take)."""
        if callable(getattr(self.motor, "takes", None)):
            return {m: [np.array([index[n] for n in take], dtype=np.intp) for take in takes]
                    for m, takes in self.motor.takes().items()}
        return {m: [np.flatnonzero(self.labels == m)] for m in self.motor.movements()}

    def _take_distance(self, own: np.ndarray, exclude: np.ndarray) -> float:
        """The mean eq. 1 distance of the take of nodes ``own`` to the best path through the graph that avoids the
        nodes ``exclude`` (NaN when there is none). With ``posture = "still"`` the take is compared as a
        demonstration is (``still_spread``): its own stillness removes the same share of each part's posture from it
        and from every take, so a spread is measured in the units the matches are."""
        kept = self._nodes_kept
        nodes = kept
        if self.params["posture"] == "still" and self.params["still_spread"]:
            body = self._take_posture.shape[1]
            share = stillness(kept[own][:, :body], np.ones(kept[own].shape[:2], dtype=bool)[:, :body],
                              self._take_posture[own[0]])
            nodes = kept.copy()
            nodes[:, :body] -= share[None, :, None] * self._take_posture
        obs, vis = nodes[own], np.ones(nodes[own].shape[:2], dtype=bool)
        self.nodes_compared = nodes
        try:
            path, _, evidence = self.search(obs, vis, None, exclude)
        finally:
            self.nodes_compared = kept
        return np.nan if path is None else path_distance(obs, nodes[path], vis) / max(evidence, 1)

    def _spreads(self, index: dict[str, int]) -> dict[str, float]:
        """Each movement's spread between takes (movements of several takes only): the ``spread_quantile`` (0.5: the
        median) over its takes of the take's mean eq. 1 distance to the best path through the graph without that
        take's nodes. Each movement's take distances are kept in :attr:`take_distances`."""
        out = {}
        for movement, takes in self._takes(index).items():
            if len(takes) < 2:
                continue
            distances = []
            for own in takes:
                if not len(own):
                    continue
                exclude = np.zeros(len(self.nodes_compared), dtype=bool)
                exclude[own] = True
                distances.append(self._take_distance(own, exclude))
            finite = [d for d in distances if np.isfinite(d)]
            if len(finite) >= 2:
                self.take_distances[movement] = tuple(float(d) for d in finite)
                out[movement] = float(np.quantile(finite, self.params["spread_quantile"]))
        return out

    def _separations(self, index: dict[str, int]) -> dict[str, float]:
        """Each movement's separation from the rest of the repertoire: the median over its takes of the take's mean
        eq. 1 distance to the best path through the graph without any of the movement's nodes (movements with
        another movement beside them only)."""
        out = {}
        for movement, takes in self._takes(index).items():
            exclude = self.labels == movement
            if not (self.labels[~exclude] != "").any():
                continue
            distances = [self._take_distance(own, exclude) for own in takes if len(own)]
            finite = [d for d in distances if np.isfinite(d)]
            if finite:
                out[movement] = float(np.median(finite))
        return out

    def threshold(self, movement: str) -> float:
        """The mean eq. 3 distance up to which ``movement`` is accepted: the smaller of ``spread`` times its spread
        between takes and ``separation`` times its separation from the other movements, where each is set and
        known; else ``max_distance`` (one take, or both 0: the paper)."""
        limits = []
        if movement in self.spreads:
            limits.append(self.params["spread"] * self.spreads[movement])
        if movement in self.separations:
            limits.append(self.params["separation"] * self.separations[movement])
        return min(limits) if limits else self.params["max_distance"]

    # -- matching ----------------------------------------------------------------------------

    def samples(self, motion: Motion, styled: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """The observed motion (in the observer's own parts) at the posegraph's node rate (with the posegraph's
        ``tempo``, at the node rate times the motion's own frequency over the repertoire's median clip frequency, as
        each clip of the graph is sampled): poses (n, P, 3), visible (n, P); with ``travel``, the travel as one more
        part (n, P + 1, 3), hidden where the motion has no world positions. ``styled``: about the segment's own
        posture and amplitude as ``posture`` and ``amplitude`` say (False: the poses as performed, which learning
        keeps)."""
        if motion.parts != self.owner.body.parts:
            raise ValueError(f"path-search matches motions of the observer's own parts {list(self.owner.body.parts)}, "
                             f"not {list(motion.parts)} (Motion.onto maps them by name)")
        rate = self.motor.node_rate
        if getattr(self.motor, "reference_frequency", 0.0) > 0:  # the graph's clips sampled at their own tempo
            at = np.unique(_sample_frames(motion, rate))
            rate = rate * self.motor.tempo_factor(self.motor.frequency(at, motion.positions, motion.visible))
        idx = _sample_frames(motion, rate)
        poses, visible = motion.positions[idx], motion.visible[idx]
        if styled:
            poses = self._styled_samples(poses, visible)
        if self.params["travel"] <= 0:
            return poses, visible
        if motion.world is None:
            velocity = np.full((len(idx), 3), np.nan)
        else:
            velocity = body_velocity(motion.world, motion.positions, motion.visible, self.owner.body.root_index,
                                     motion.fps, frames=idx)
        known = np.isfinite(velocity).all(axis=1)
        part = np.where(known[:, None], travel_part(velocity, self.params["travel"]), 0.0)
        return np.concatenate([poses, part[:, None]], axis=1), np.concatenate([visible, known[:, None]], axis=1)

    def match(self, motion: Motion) -> Match:
        if motion.n_frames == 0 or not motion.visible.any():
            return Match.unknown("nothing visible", details={"reason": "nothing visible"})
        self._refresh()
        obs, vis = self.samples(motion)
        if self.params["posture"] == "still":  # the same share of each part's posture removed from the nodes
            self.nodes_compared = self._still_nodes()
        weights = None
        if self.params["attention"] > 0:
            positions = ~self.owner.body.angle_mask
            if obs.shape[1] > len(positions):  # the travel part is a position too
                positions = np.append(positions, True)
            weights = movement_weights(obs, vis, self.params["attention"], positions)
        path, _, evidence = self.search(obs, vis, weights)  # the beam's eq. 3 cost: recomputed below by the one formula
        if path is None:
            return Match.unknown("nothing visible", details={"reason": "nothing visible"})
        ids = self.label_ids[path]
        voting = ids[ids != self._hub_id]  # the movements' numbers: hubs do not vote
        mean = path_distance(obs, self.nodes_compared[path], vis, weights) / max(evidence, 1)  # eq. 3 per sample
        details: dict[str, Any] = {"mean_distance": mean, "samples": len(path)}
        if voting.size == 0:
            return Match.unknown("only hub poses", score=mean, measure=MEASURE, details={
                "reason": "only hub poses", "path": tuple(self.node_names[i] for i in path), **details})
        counts = np.bincount(voting)  # np.unique(voting, return_counts=True): the numbers voted for, ascending
        numbers = counts.nonzero()[0]
        counts = counts[numbers]
        names = self._label_names[numbers]  # the names in their order, as np.unique over the names gives them
        best = int(np.argmax(counts))
        movement, share = str(names[best]), counts[best] / voting.size
        details["votes"] = {str(n): int(c) for n, c in zip(names, counts)}
        node_path = tuple(self.node_names[i] for i in path)
        if movement in self.spreads:
            details["spread"] = self.spreads[movement]
        if movement in self.separations:
            details["separation"] = self.separations[movement]
        limit = self.threshold(movement)
        if mean > limit:
            if self.params["learn"]:
                return self._learn(*self.samples(motion, styled=False), details) if self._styled() else \
                    self._learn(obs, vis, details)
            return Match(None, 0.0, None, node_path, {"reason": "too far from every path", "nearest": movement,
                                                      "max_distance": limit, **details},
                         reason="too far from every path", nearest=movement, score=mean, threshold=limit,
                         measure=MEASURE)
        confidence = float(np.exp(-mean / self.params["scale"]) * share)
        return Match(movement, confidence, None, node_path, details,
                     candidates=self._candidates(obs, vis, weights, movement, mean), score=mean, threshold=limit,
                     measure=MEASURE)

    def _candidates(self, obs: np.ndarray, vis: np.ndarray, weights: np.ndarray | None, movement: str,
                    mean: float) -> tuple[tuple[str, float], ...]:
        """The recognised movement and up to ``candidates`` runners-up (Fig. 13), by mean eq. 3 distance, best
        first: each the majority movement of the best path that leaves out the nodes of the movements found before
        it. Empty when ``candidates`` is 0."""
        if self.params["candidates"] <= 0:
            return ()
        found = [(movement, float(mean))]
        exclude = self.labels == movement
        for _ in range(self.params["candidates"]):
            path, cost, evidence = self.search(obs, vis, weights, exclude)
            if path is None or not np.isfinite(cost):  # no path through the movements left
                break
            voting = self.labels[path][self.labels[path] != ""]
            if voting.size == 0:
                break
            names, counts = np.unique(voting, return_counts=True)
            other = str(names[int(np.argmax(counts))])
            found.append((other, float(path_distance(obs, self.nodes_compared[path], vis, weights) / max(evidence, 1))))
            exclude = exclude | (self.labels == other)
        return (found[0], *sorted(found[1:], key=lambda c: c[1]))

    def search(self, obs: np.ndarray, vis: np.ndarray, weights: np.ndarray | None = None,
               exclude: np.ndarray | None = None) -> tuple[np.ndarray | None, float, int]:
        """The best path (node indices, one per sample), its eq. 3 cost and the number of samples with evidence.

        ``obs`` and ``vis`` are samples as :meth:`samples` gives them, compared with :attr:`nodes_compared` (with
        ``travel``, one part more than the body); ``weights``: attention to each of those parts (``None``: eq. 1's
        plain mean); ``exclude`` (N,): nodes no path may use."""
        has = vis.any(axis=1)
        if not has.any():
            return None, 0.0, 0
        n = len(obs)
        mid = n // 2
        ev = np.flatnonzero(has)
        mid = int(ev[np.argmin(np.abs(ev - mid))])  # the visible frame nearest the middle
        nodes = self.nodes_compared
        k = self.params["k"]
        indexed = weights is None and exclude is None and not self.params["per_movement"]
        if indexed and len(nodes) > self.index_min_nodes:
            if getattr(self, "_index", None) is None or self._index.poses is not nodes:
                self._index = PoseIndex(nodes)
            start, costs = self._index.nearest(obs[mid], vis[mid], k)  # the scan's k nearest, in its order
        else:
            every = weights is None and vis[mid].all()  # every part seen: eq. 1 over every part, as the beam's
            # score computes it (the same numbers as pose_distance: its masked sum over n parts is the mean)
            if every and (getattr(self, "_scan", None) is None or self._scan.poses is not nodes):
                self._scan = PoseScan(nodes)
            screened = self._screened(obs[mid], k) if every and exclude is None else None
            if screened is not None:
                start, costs = screened
            else:
                first = self._scan(obs[mid]) if every else pose_distance(nodes, obs[mid], vis[mid], weights)
                if exclude is not None:
                    first = np.where(exclude, np.inf, first)
                start = self._starts(first, k)
                costs = first[start]
        # beams: array of paths (B, length) and costs (B,)
        paths = start[:, None]
        paths, costs = self._extend(paths, costs, obs, vis, range(mid + 1, n), self.succ, weights, exclude, append=True)
        # the stays the forward half made on the middle node count toward the backward half's
        repeats = np.cumprod(paths == paths[:, :1], axis=1).sum(axis=1) - 1
        paths, costs = self._extend(paths, costs, obs, vis, range(mid - 1, -1, -1), self.pred, weights, exclude,
                                    append=False, stays=repeats)
        best = int(np.argmin(costs))
        return paths[best], float(costs[best]), int(has.sum())

    def _extend(self, paths, costs, obs, vis, frames, table, weights, exclude, *, append: bool, stays=None):
        nodes = self.nodes_compared
        if getattr(self, "_scan", None) is None or self._scan.poses is not nodes:
            self._scan = PoseScan(nodes)
        scan = self._scan
        k, limit = self.params["k"], self.params["max_stay"]
        # samples in a row each path has stayed on the end node it grows from
        stays = np.zeros(len(paths), dtype=int) if stays is None else stays
        ends = paths[:, -1] if append else paths[:, 0]
        steps = []  # per sample: each kept path's new node and the path it grew from (back-pointers)
        for t in frames:
            seen = vis[t]
            every = seen.all()

            def score(cand, t=t, seen=seen, every=every):
                if every and weights is None:  # the hot loop of the search: eq. 1 over every part, inline
                    return scan(obs[t], cand)  # (pose_distance's arithmetic without its checks: the same numbers)
                if every:
                    return pose_distance(nodes[cand], obs[t], None, weights)
                if seen.any():  # eq. 1 over the parts seen in this sample: the mask is the same for every candidate,
                    # so the seen parts are taken first and pose_distance needs no mask
                    return pose_distance(nodes[cand][:, seen], obs[t, seen], None,
                                         None if weights is None else weights[seen])
                return np.zeros(len(cand))

            beam, cand = _candidates(table, ends, costs, score)
            stay = np.where(cand == ends[beam], stays[beam] + 1, 0)
            step = score(cand)
            if exclude is not None:
                step = np.where(exclude[cand], np.inf, step)
            if limit > 0:
                step = np.where(stay > limit, np.inf, step)
            total = costs[beam] + step
            order = total.argsort(kind="stable")
            # k best, one path per end node (distinct hypotheses): the first time each end node comes in the order
            first = _firsts(cand[order])
            keep = self._best(order[np.sort(first)], cand, k)
            steps.append((cand[keep], beam[keep]))
            ends, costs, stays = cand[keep], total[keep], stay[keep]
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
        ``2e`` of the k-th smallest approximation, and, with ``per_movement``, its movement's nearest (or tied with
        it) only if within ``2e`` of its movement's smallest. Those few (every movement keeps at least its nearest
        by approximation) are measured again with the scan's arithmetic, and chosen among as :meth:`_starts`
        chooses among all: the k best by (distance, node), each movement's nearest (the lowest node on ties), the
        union ranked by (distance, node). Every other node is farther than each of those choices."""
        n = len(self.nodes_compared)
        if n <= k:
            return None
        screen = self._scan.approximate(query)
        if screen is None:
            return None
        near, error = screen
        margin = 2.0 * error
        wanted = near <= np.partition(near, k - 1)[k - 1] + margin
        if self.params["per_movement"]:
            grouped = near[self._by_label]
            least = np.minimum.reduceat(grouped, self._label_starts)
            wanted[self._by_label[grouped <= np.repeat(least + margin, self._label_sizes)]] = True
        rows = np.flatnonzero(wanted)  # ascending: node order
        first = self._scan(query, rows)
        kth = np.partition(first, k - 1)[k - 1]
        chosen = np.flatnonzero(first <= kth)  # positions in rows; the k best and the nodes tied with the k-th
        chosen = chosen[np.lexsort((chosen, first[chosen]))][:k]  # by (distance, node): rows ascend with positions
        if self.params["per_movement"]:
            labels = self.label_ids[rows]
            by = np.lexsort((rows, first, labels))  # by movement, then (distance, node): each movement's nearest first
            head = np.ones(len(by), dtype=bool)
            head[1:] = labels[by[1:]] != labels[by[:-1]]
            union = np.zeros(len(rows), dtype=bool)  # np.union1d of the two: the positions, ascending
            union[chosen] = True
            union[by[head]] = True
            chosen = union.nonzero()[0]
            chosen = chosen[np.lexsort((chosen, first[chosen]))]
        return rows[chosen], first[chosen]

    def _starts(self, first: np.ndarray, k: int) -> np.ndarray:
        """``_best(np.argsort(first, kind="stable"), np.arange(N), k)`` without sorting all N nodes: the start nodes
        of a search from every node's distance ``first`` (N,), best first (ties: the lower node).

        The k best are the nodes up to the k-th smallest distance (:func:`numpy.partition`), ranked by (distance,
        node) as the stable sort ranks them; with ``per_movement`` each movement's first node in that order is its
        nearest node (the lowest of its nearest on ties). With NaN distances (which the sort puts last) the sort
        itself answers."""
        n = len(first)
        if n <= k or np.isnan(first).any():
            return self._best(np.argsort(first, kind="stable"), np.arange(n), k)
        kth = np.partition(first, k - 1)[k - 1]
        chosen = np.flatnonzero(first <= kth)  # the k best and the nodes tied with the k-th: the first k by node
        if self.params["per_movement"]:
            grouped = first[self._by_label]
            least = np.repeat(np.minimum.reduceat(grouped, self._label_starts), np.diff(self._label_starts, append=n))
            at = np.where(grouped == least, np.arange(n), n)  # each movement's nearest nodes; the first of them:
            nearest = self._by_label[np.minimum.reduceat(at, self._label_starts)]
        ranked = chosen[np.lexsort((chosen, first[chosen]))][:k]
        if not self.params["per_movement"]:
            return ranked
        both = np.union1d(ranked, nearest)
        return both[np.lexsort((both, first[both]))]

    def _best(self, ranked: np.ndarray, cand: np.ndarray, k: int) -> np.ndarray:
        """The first ``k`` of ``ranked`` (indices into ``cand``, best first) and, with ``per_movement``, the first of
        each movement's nodes among them, in rank order."""
        if not self.params["per_movement"]:
            return ranked[:k]
        each = _firsts(self.label_ids[cand[ranked]])
        chosen = np.zeros(len(ranked), dtype=bool)
        chosen[:k] = True
        chosen[each] = True
        return ranked[chosen]

    def _learn(self, obs: np.ndarray, vis: np.ndarray, details: dict[str, Any]) -> Match:
        n = sum(1 for m in self.motor.movements() if m.startswith(self.params["learn_prefix"] + "-")) + 1
        name = f"{self.params['learn_prefix']}-{n}"
        parts = self.owner.body.n_parts  # the travel part, if any, is not a pose's
        path = self.motor.learn(name, obs[:, :parts], vis[:, :parts], source="path-search")
        self._refresh()
        return Match(name, 1.0, None, tuple(path), {"learned": True, **details})


def _reach(graph, nodes, index, max_skip: int, *, forward: bool) -> tuple[np.ndarray, np.ndarray]:
    """For every node, the nodes reachable in 0..max_skip steps along (or against) the edges, as a compressed
    table: node ``i`` reaches ``indices[indptr[i]:indptr[i + 1]]`` (sorted). networkx's breadth-first search
    bounded by ``cutoff`` finds each node's reach."""
    g = graph if forward else graph.reverse(copy=False)
    counts = np.empty(len(nodes), dtype=np.intp)
    found: list[Any] = []
    for i, node in enumerate(nodes):
        reached = nx.single_source_shortest_path_length(g, node, cutoff=max_skip)
        counts[i] = len(reached)
        found.extend(reached)
    indptr = np.zeros(len(nodes) + 1, dtype=np.intp)
    np.cumsum(counts, out=indptr[1:])
    # each row sorted at once: row i's indices offset by i * len(nodes), one sort, the offsets taken off again
    offset = np.repeat(np.arange(len(nodes), dtype=np.intp) * len(nodes), counts)
    ids = np.fromiter(map(index.__getitem__, found), dtype=np.intp, count=len(found))
    return indptr, np.sort(ids + offset) - offset


class Fan(NamedTuple):
    """The reach table of :func:`_reach` factored through the wide nodes (hubs), so that a beam step need not list
    every movement's first nodes once per path that reaches a hub.

    A node reaches (in 0..max_skip steps) its *local* nodes, found without passing through a wide node, and for
    each wide node ``h`` it reaches at distance ``j`` without passing through another, every node within
    ``max_skip - j`` steps of ``h``: the *rings* of ``h`` at distances 0..max_skip - j. (A shortest path to a node
    either meets no wide node, or meets a first one at the distance found without passing through another; so the
    union is exactly :func:`_reach`'s row.)"""

    full: tuple[np.ndarray, np.ndarray]
    """:func:`_reach`'s table: each node's whole reach, used for the nodes whose row is short."""
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
    """:func:`_reach`'s table factored through the wide nodes (:class:`Fan`)."""
    full = _reach(graph, nodes, index, max_skip, forward=forward)
    g = graph if forward else graph.reverse(copy=False)
    succ = [[index[m] for m in g.successors(node)] for node in nodes]
    wide_nodes = [i for i, s in enumerate(succ) if len(s) > WIDE]
    number = {h: w for w, h in enumerate(wide_nodes)}
    long = np.zeros(len(nodes), dtype=bool)
    if wide_nodes:
        long = np.diff(full[0]) > LONG_ROW
    local, first, dist = [], [], []
    for i in range(len(nodes)):
        if not long[i]:
            local.append([])
            first.append([])
            dist.append([])
            continue
        if i in number:  # a wide node reaches everything through itself
            local.append([i])
            first.append([number[i]])
            dist.append([0])
            continue
        found, frontier, hubs = {i}, [i], {}
        for depth in range(1, max_skip + 1):
            nxt = []
            for f in frontier:
                for m in succ[f]:
                    if m in found or m in hubs:
                        continue
                    if m in number:
                        hubs[m] = depth  # not passed through: its rings stand for what lies beyond
                    else:
                        found.add(m)
                        nxt.append(m)
            frontier = nxt
        local.append(list(found))
        first.append([number[h] for h in hubs])
        dist.append(list(hubs.values()))
    rings = []
    for h in wide_nodes:
        by_distance = [[] for _ in range(max_skip + 1)]
        for m, d in nx.single_source_shortest_path_length(g, nodes[h], cutoff=max_skip).items():
            by_distance[d].append(index[m])
        rings.extend(by_distance)
    indptr = np.zeros(len(nodes) + 1, dtype=np.intp)
    np.cumsum([len(r) for r in first], out=indptr[1:])
    wide = (indptr, np.array([w for r in first for w in r], dtype=np.intp),
            np.array([d for r in dist for d in r], dtype=np.intp))
    padded = None
    widths = np.diff(full[0])
    if not long.any() and widths.max(initial=0) <= LONG_ROW:
        padded = np.full((len(nodes), widths.max(initial=0)), -1, dtype=np.intp)
        padded[np.repeat(np.arange(len(nodes)), widths), np.arange(len(full[1])) - np.repeat(full[0][:-1], widths)] = \
            full[1]
    return Fan(full, long, _rows(local), wide, _rows(rings), max_skip, padded)


def _candidates(fan: Fan, ends: np.ndarray, costs: np.ndarray, score) -> tuple[np.ndarray, np.ndarray]:
    """The (beam index, node) pairs of a beam step, in the order of :func:`_gather` on :func:`_reach`'s table (by
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


def _sample_frames(motion: Motion, rate: float) -> np.ndarray:
    """The frames of ``motion`` taken ``rate`` times a second (at least one; the last frame repeated past its end)."""
    n = max(1, int(round(motion.duration * rate)))
    return np.minimum(np.round(np.arange(n) * motion.fps / rate).astype(int), motion.n_frames - 1)


@hookimpl
def likeme_register_matchers():
    return [PathSearch]
