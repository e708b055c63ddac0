"""The ``path-search`` matcher: a comparison, a search through the posegraph and a decision (B&B 2005, §5.2).

The observed segment is sampled at the posegraph's node rate (one sample per node of one's own movement at one's
own speed), each sample turned into frames by the comparison (:mod:`plugins.matchers.comparison`), and the
search finds the path through one's own posegraph nearest to them (eq. 3): the paper's k-best beam from the
middle frame (:mod:`~plugins.matchers.path_search.kbest`), or every movement's own best path
(:mod:`~plugins.matchers.path_search.per_movement`). The decision (:mod:`plugins.matchers.decision`) says whether
the nearest movement is near enough; what is not may be learned as a new movement (§5.2.3, §7.3). Each of the
three is chosen once, when the matcher is attached; the papers' settings are the defaults, the observer template
chooses those for real people (``characters/observers/recordings.toml``, ``docs/matchers.md``).
"""

from __future__ import annotations

from typing import Any, Protocol

import networkx as nx
import numpy as np

from plugins.lib.compiled import one_thread
from plugins.lib.learned_names import learned_name
from plugins.matchers.comparison import Comparison, Frames, comparison
from plugins.matchers.comparison import Motion as MotionComparison
from plugins.matchers.decision import Calibrated, Decision, Distance
from plugins.matchers.path_search.evidence import Evidence, MotionAlone, MotionAndStrokes
from plugins.matchers.path_search.kbest import INDEX_MIN_NODES, Beam
from plugins.matchers.path_search.per_movement import EachMovement
from plugins.matchers.path_search.search import Search
from toolkit import ConfigError, Match, Matcher, Motion, Parameter
from toolkit.components import provides

__all__ = ["PathSearch", "Played", "PoseGraph", "Takes"]


class PoseGraph(Protocol):
    """A posegraph: whole-body poses as nodes, movements as paths between hubs (Buchsbaum & Blumberg 2005, §4.1).

    What the paper's path search needs of a motor system: ``plugins.motor.posegraph`` provides it (and
    :class:`Takes`).
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
    """A posegraph that knows its takes and how its nodes move: what the per-movement search, the motion comparison
    and the calibrated decision need besides :class:`PoseGraph`."""

    node_motion: np.ndarray
    """How each part was moving at each node (velocity relative to the root, m/s), (N, P, 3)."""
    node_travel: np.ndarray
    """The root's velocity in the body's frame at each node (m/s), (N, 3)."""
    node_heading: np.ndarray
    """How far the body had turned at each node since its take began (radians; NaN: not known), (N,)."""
    node_noise: np.ndarray
    """The tracker's jitter each node keeps from its clip: the mean over the parts of the squared noise of a position
    (m^2) and of a velocity ((m/s)^2) (:func:`plugins.lib.jitter.feature_noise`; 0 where none is known), (N, 2)."""

    def takes(self) -> dict[str, list[list[str]]]:
        """Movement -> the node names of each of its takes (hubs left out)."""


class Played(Protocol):
    """A posegraph that gives each of its takes as a motion: what ``comparison = "motion+strokes"`` cuts into
    strokes (:mod:`plugins.matchers.path_search.evidence`)."""

    def take_motions(self, fps: float = 30.0) -> dict[str, list[Motion | None]]:
        """Movement -> each take (in the order of ``takes()``) as a motion, ``None`` for one that does not move."""


SEARCHES: dict[str, type[Search]] = {"k-best": Beam, "per-movement": EachMovement}
"""The search strategies by the name the ``search`` parameter takes."""


class PathSearch(Matcher):
    """The observed movement as the nearest path through one's own posegraph (B&B §5.2)."""

    name = "path-search"
    motor_systems = ("posegraph",)
    report_details = ("learned",)
    index_min_nodes = INDEX_MIN_NODES
    """Above this many nodes the k-best search's start poses come from the spatial index (tests set it to force the
    index on or off)."""
    parameters = (
        Parameter("comparison", str, "poses", "What a sample is compared by (plugins.matchers.comparison): 'poses', "
                  "eq. 1 on root-relative positions in metres (the paper); 'motion', each part's shape, motion and "
                  "carry in body sizes, for real people (needs search = 'per-movement'); 'motion+strokes', that and "
                  "each take's strokes (K&G §4.1), each weighed by how well the takes show it separates the "
                  "movements (plugins.matchers.path_search.evidence).",
                  choices=("poses", "motion", "motion+strokes")),
        Parameter("search", str, "k-best", "How the nearest path is found: 'k-best', the k best paths from the poses "
                  "nearest the middle frame (§5.2, the paper); 'per-movement', every movement's own best path, "
                  "exactly, by dynamic time warping (it cannot lose the true movement).",
                  choices=("k-best", "per-movement")),
        Parameter("decision", str, "distance", "When the nearest movement is 'unknown' (plugins.matchers.decision): "
                  "'distance', beyond [matcher.distance] max_distance (the paper); 'calibrated', beyond a threshold "
                  "calibrated on the repertoire's own takes ([matcher.calibrated]).",
                  choices=("distance", "calibrated")),
        Parameter("beam", doc="The beam of search = 'k-best'.", parameters=(
            Parameter("k", int, 8, "Number of start poses and of paths kept at every step (the beam width). "
                      "Larger is more robust to noise and occlusion, and slower.", minimum=1),
            Parameter("max_skip", int, 2, "Most nodes a path may advance per observed sample (0 = stay is always "
                      "allowed); 2 tolerates movements up to twice as fast as one's own.", minimum=1, maximum=5),
        )),
        Parameter("distance", doc="The limit of decision = 'distance'.", parameters=(
            Parameter("max_distance", float, 0.03, "Mean eq. 1 distance (m) per sample above which the answer is "
                      "'unknown'. Must stay above the noise of the input (about 1.8 x its standard deviation).",
                      minimum=0.0, length=True),
            Parameter("scale", float, 0.02, "Distance (m) at which confidence falls to 1/e.", minimum=1e-6,
                      length=True),
        )),
        Parameter("calibrated", doc="The calibration of decision = 'calibrated'.", parameters=(
            Parameter("known_rejected", float, 0.05, "The share of a known movement's performances that may be "
                      "called unknown, as far as the repertoire's takes of one movement show how they vary.",
                      minimum=0.0, maximum=1.0),
        )),
        Parameter("candidates", int, 0, "Ranked candidates to report besides the best (B&B Fig. 13): with 'k-best' "
                  "each is the best path through the other movements' nodes (one more search each), with its mean "
                  "eq. 3 distance; with 'per-movement' the next nearest movements, each with the decision's score "
                  "(relative to standing still with the calibrated decision). 0: the best only.",
                  minimum=0, maximum=10),
        Parameter("learn", bool, False, "Add an unknown movement's path to the posegraph as a new movement."),
        Parameter("learn_prefix", str, "learned", "Name prefix of learned movements (learned-1, learned-2...)."),
    )

    def attach(self, owner: Any) -> None:
        super().attach(owner)
        provides(owner.motor, PoseGraph, needed_by="path-search", what="a posegraph motor system",
                 expected=" or ".join(f'[motor] plugin = "{name}"' for name in self.motor_systems))
        self.motor = owner.motor
        for key, value in (("search", "per-movement"), ("comparison", "motion"), ("comparison", "motion+strokes"),
                           ("decision", "calibrated")):
            if self.params[key] == value:
                provides(owner.motor, Takes, needed_by=f"path-search's {key} = '{value}'",
                         what="a posegraph that knows its takes and how its nodes move", key=(key,),
                         expected="a motor system with takes(), node_motion, node_travel and node_heading (posegraph)")
        if self.params["comparison"] == "motion+strokes":
            provides(owner.motor, Played, needed_by="path-search's comparison = 'motion+strokes'",
                     what="a posegraph that plays each of its takes", key=("comparison",),
                     expected="a motor system with take_motions() (posegraph)")
        if self.params["comparison"] != "poses" and self.params["search"] == "k-best":
            raise ConfigError("search = 'k-best' compares poses (eq. 1)", key=("search",),
                              expected="search = 'per-movement' with comparison = 'motion', or comparison = 'poses'")
        if self.params["comparison"] != "poses" and self.params["decision"] == "distance":
            raise ConfigError("decision = 'distance' holds eq. 1 to max_distance in metres, and comparison = "
                              f"'{self.params['comparison']}' measures in body sizes", key=("decision",),
                              expected="decision = 'calibrated' with comparison = 'motion', or comparison = 'poses'")
        self.comparison: Comparison = comparison("poses" if self.params["comparison"] == "poses" else "motion")
        self.evidence: Evidence = MotionAndStrokes(owner.body, self.params["calibrated"]["known_rejected"]) \
            if self.params["comparison"] == "motion+strokes" else MotionAlone()
        self.searcher: Search = SEARCHES[self.params["search"]](self)
        if self.params["decision"] == "calibrated":
            self.decision: Decision = Calibrated(self.params["calibrated"]["known_rejected"])
        else:
            self.decision = Distance(self.params["distance"]["max_distance"], "mean pose distance along the path (eq. 3)")
        self._version = -1
        self._refresh()  # the tables of the graph as composed, now rather than at the first match

    def _refresh(self) -> None:
        """(Re)build the node tables, the search and the calibration after the graph changed (learning)."""
        motor = self.motor
        n = motor.graph.number_of_nodes()
        if n == self._version:
            return
        self.node_names = motor.nodes
        index = {node: i for i, node in enumerate(self.node_names)}
        self.labels = np.array([motor.movement_of(nd) or "" for nd in self.node_names], dtype=object)
        self.label_names, self.label_ids = np.unique(self.labels.astype(str), return_inverse=True)  # a number per
        # movement, in the order of the names (np.unique over numbers ranks as over names); hubs' "" comes first
        self.hub_id = 0 if len(self.label_names) and self.label_names[0] == "" else -1
        self.take_nodes = {m: [np.array([index[nd] for nd in take], dtype=np.intp) for take in takes if take]
                           for m, takes in motor.takes().items()} if callable(getattr(motor, "takes", None)) else {}
        self._version = n
        with one_thread():
            self.searcher.rebuild()
            if isinstance(self.decision, Calibrated):
                self.decision.calibrate(self.searcher.calibration())

    def take_frames(self, nodes: np.ndarray) -> Frames:
        """The frames of one take's nodes (in their order): as the comparison sees a demonstration, about the take's
        own mean and in its own body size, with its parts' motion, travel, turn and jitter as the posegraph keeps
        them."""
        motor = self.motor
        poses = motor.node_root_relative[nodes]
        heading = motor.node_heading[nodes]
        first = heading[np.isfinite(heading)][:1]
        return self.comparison.frames(poses, np.ones(poses.shape[:2], dtype=bool), motor.node_rate,
                                      velocity=motor.node_motion[nodes], travel=motor.node_travel[nodes],
                                      heading=heading - (first[0] if len(first) else 0.0),
                                      noise=motor.node_noise[nodes][:, None, :])

    def samples(self, motion: Motion) -> tuple[Frames, tuple[np.ndarray, np.ndarray]]:
        """The observed motion (in the observer's own parts) at the posegraph's node rate: its frames as the
        comparison sees them, and the sampled poses (n, P, 3) and masks (n, P) as observed (what learning keeps)."""
        if motion.parts != self.owner.body.parts:
            raise ValueError(f"path-search matches motions of the observer's own parts {list(self.owner.body.parts)}, "
                             f"not {list(motion.parts)} (Motion.onto maps them by name)")
        idx = _sample_frames(motion, self.motor.node_rate)
        poses, visible = motion.positions[idx], motion.visible[idx]
        if isinstance(self.comparison, MotionComparison):
            return self.comparison.of_motion(motion, self.owner.body, idx, self.motor.node_rate), (poses, visible)
        return self.comparison.frames(poses, visible, self.motor.node_rate), (poses, visible)

    def match(self, motion: Motion) -> Match:
        with one_thread():
            return self._match(motion)

    def _match(self, motion: Motion) -> Match:
        if motion.n_frames == 0 or not motion.visible.any():
            return Match.unknown("nothing visible", details={"reason": "nothing visible"})
        self._refresh()
        samples, raw = self.samples(motion)
        evidence = samples.seen.any(axis=1)
        if not evidence.all():  # a sample with no part seen (its root hidden, say) carries no evidence: left out,
            samples = samples.take(evidence)  # not a free step the warping could stretch along a long take
        found = self.searcher.find(samples, motion)
        if found is None:
            return Match.unknown("nothing visible", details={"reason": "nothing visible"})
        node_path = tuple(self.node_names[i] for i in found.path)
        details = dict(found.details)
        verdict = self.decision.decide(found.movement, found.distance, found.still)
        measure = self.decision.measure
        if found.movement is None:
            return Match.unknown("only hub poses", score=details.get("mean_distance"), measure=measure, details={
                "reason": "only hub poses", "path": node_path, **details})
        candidates = found.ranked[: self.params["candidates"] + 1] if self.params["candidates"] else ()
        if verdict.movement is None:
            if self.params["learn"]:
                return self._learn(*raw, details)
            return Match(None, 0.0, None, node_path, {"reason": "too far from every path", "nearest": verdict.nearest,
                                                      "max_distance": verdict.threshold, **details},
                         candidates=candidates, reason="too far from every path", nearest=verdict.nearest,
                         score=verdict.score, threshold=verdict.threshold, measure=measure)
        if isinstance(self.decision, Distance):
            confidence = float(np.exp(-verdict.score / self.params["distance"]["scale"]) * found.share)
        else:
            confidence = float(max(0.0, 1.0 - verdict.score / verdict.threshold) * found.share) \
                if np.isfinite(verdict.threshold) and verdict.threshold > 0 else found.share
        return Match(verdict.movement, confidence, None, node_path, details, candidates=candidates,
                     score=verdict.score, threshold=verdict.threshold, measure=measure)

    def _learn(self, obs: np.ndarray, vis: np.ndarray, details: dict[str, Any]) -> Match:
        name = learned_name(self.motor.movements(), self.params["learn_prefix"])
        path = self.motor.learn(name, obs, vis, source="path-search")
        self._refresh()
        return Match(name, 1.0, None, tuple(path), {"learned": True, **details})


def _sample_frames(motion: Motion, rate: float) -> np.ndarray:
    """The frames of ``motion`` taken ``rate`` times a second (at least one; the last frame repeated past its end)."""
    n = max(1, int(round(motion.duration * rate)))
    return np.minimum(np.round(np.arange(n) * motion.fps / rate).astype(int), motion.n_frames - 1)
