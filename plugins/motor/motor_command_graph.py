"""Motor system ``motor-command-graph``: one graph of motor commands per motor subsystem (Kopp & Graeser 2006, §4.2).

Nodes are motor states of a subsystem (the positions of its parts in the body
frame, e.g. where the left wrist is); *hub nodes* are the rest states in which
movements start and end. Edges are motor commands that lead from one state to
another: for wrist subsystems, guiding strokes (:mod:`plugins.lib.guiding_stroke`),
one per part of the subsystem; for hand subsystems, whose parts are the
fingers of a hand and whose states are their joint angles, hand transitions
through key postures (:mod:`plugins.lib.hand_transition`), one per finger with
shared timing. Every hand of the body gets a subsystem of its own (``hands``),
so Max and Moritz have the paper's four graphs: left and right wrist, left and
right hand. Several edges may join the same two nodes
(a :class:`networkx.MultiDiGraph`). At every moment each subsystem is in its
*active node* (or on an edge between two).

A learner starts with the hub nodes only and learns edges and nodes by watching
(:meth:`MotorCommandGraph.learn`, used by the ``forward-model`` matcher's inverse
model). Performing an edge (its name is a movement of this motor system) moves
the subsystem's parts along the edge's strokes from the rest of the body's
pose; elbows follow by two-link inverse kinematics with the elbow hanging down
and out (the swivel heuristic of §3, simplified).

Subsystems are configurable (``subsystems = { left_wrist = ["left_wrist"], ... }``),
including one whole-body subsystem with every part; a subsystem moves either
positions or finger joint angles, never both.

Clips (:mod:`plugins.lib.clip_repertoire`): with ``clips`` and ``profile`` the graph
is learned from labelled motion-capture clips by the inverse model, as if the
character had watched each one: the rest state is the first hub found from the
clips, the default subsystem is the whole body (every part but the root, no
arm inverse kinematics), every clip becomes a chain of edges from the hub, and
the chain is a named movement (the clip's sub-folder name; several clips of one
movement share it, :meth:`MotorCommandGraph.label`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from plugins.lib.clip_repertoire import CLIP_PARAMETERS, example_name, repertoire_for
from plugins.lib.guiding_stroke import GuidingStroke, progress
from plugins.lib.hand_transition import HandTransition
from plugins.lib.inverse_model import commands_from_segment
from plugins.lib.strokes import STROKE_PARAMETERS, StrokeCriteria, breaks
from plugins.lib.travel import body_velocity, turned
from plugins.motor.key_poses import parse_poses
from toolkit import ConfigError, Motion, MotorSystem, Parameter, hookimpl
from toolkit.motion import fill_hidden

__all__ = ["MotorCommandGraph", "Edge", "place_elbows", "command_from_dict", "clip_travel", "clip_turn"]

Command = GuidingStroke | HandTransition


@dataclass(frozen=True, eq=False)
class Edge:
    """A motor command of one subsystem's graph, leading from motor state ``source`` to ``target`` (K&G §4.2).

    ``commands`` holds one guiding stroke per part of a wrist subsystem, or one hand transition per finger of a
    hand (they share their timing); ``name`` is the movement it is performed and recognised as
    (``left_wrist:e3``); ``origin`` says where it was learned (a clip file, ``"inverse model"``, ``"loaded"``).

    ``shown`` is the piece of the demonstration the command was learned from, when it was learned by watching: the
    parts' positions (a hand: joint angles), (m, k, 3), at ``shown_fps`` frames per second. It keeps the speed the
    command "was demonstrated at first" (K&G §4.4): the forward model measures how much faster or slower a familiar
    movement is performed against it. ``None`` (a command written by hand, or saved without it): the commands'
    own timing stands for it. :meth:`MotorCommandGraph.get_state` saves it for edges learned by watching, not for
    those learned from clips (rebuilt from the clips; a loaded edge keeps the clip's).

    ``travel`` (issue 18; not in the paper): where the demonstrator's body went while the command was shown, the
    root's velocity in the body's own frame (m/s, +z forward, +x the body's left; :mod:`plugins.lib.travel`), one
    row per frame of ``shown`` (m, 3). The commands move parts relative to the root (B&B §5.1's root-relative
    coordinates, which both papers use), so they say nothing of where the body goes; a take of a walk to the left
    and one to the right give the same strokes. The forward model (``forward-model``'s ``travel``) predicts the
    travel at the point of the command it predicts the parts at (K&G §4.1's forward model, extended to the root as
    the correspondence problem of K&G §6 and B&B §7.1 asks). ``None``: not known (no world positions were seen);
    the command is then taken as performed on the spot.

    ``turn``: how far the demonstrator's body had turned about +y since the command began (radians), one per frame of
    ``shown`` (n,): a walk that turns left and one that turns right have alike strokes and travel, and differ by it
    (:func:`plugins.lib.travel.turned`). ``None``: not known.
    """

    name: str
    subsystem: str
    source: str
    target: str
    commands: tuple[Command, ...]
    origin: str = ""
    shown: np.ndarray | None = None
    shown_fps: float = 0.0
    travel: np.ndarray | None = None
    turn: np.ndarray | None = None

    @property
    def duration(self) -> float:
        """Seconds the edge takes: its longest command's."""
        return max(c.duration for c in self.commands)


def clip_travel(motion: Motion, root: int) -> np.ndarray | None:
    """Where the body of a clip went at each frame (F, 3): the root's velocity in the body's own frame, m/s
    (:func:`plugins.lib.travel.body_velocity`), frames where it is not known at rest (0); ``None`` without world
    positions (:attr:`Motion.world`)."""
    if motion.world is None:
        return None
    return np.nan_to_num(body_velocity(motion.world, motion.positions, motion.visible, root, motion.fps))


def clip_turn(motion: Motion, root: int) -> np.ndarray | None:
    """How far the body of a clip had turned at each frame since its first (F,), radians
    (:func:`plugins.lib.travel.turned`), frames where it is not known as the last known; ``None`` without world
    positions."""
    if motion.world is None:
        return None
    turn = turned(motion.world, motion.positions, motion.visible, root)
    known = np.isfinite(turn)
    if not known.any():
        return None
    return np.interp(np.arange(len(turn)), np.flatnonzero(known), turn[known])


def command_from_dict(entry: dict[str, Any]) -> GuidingStroke | HandTransition:
    """A motor command from its ``to_dict()``: a hand transition (it has key postures) or a guiding stroke."""
    return HandTransition(**entry) if "keys" in entry else GuidingStroke(**entry)


def place_elbows(shoulder: np.ndarray, wrist: np.ndarray, upper: float, fore: float, outward: np.ndarray) -> np.ndarray:
    """Elbow positions (F, 3) for shoulders and wrists (F, 3) by two-link IK, bending towards ``outward`` and down."""
    d_vec = wrist - shoulder
    d = np.linalg.norm(d_vec, axis=-1, keepdims=True)
    d_safe = np.clip(d, 1e-6, upper + fore - 1e-6)
    u = d_vec / np.maximum(d, 1e-9)
    along = (upper**2 - fore**2 + d_safe**2) / (2 * d_safe)
    h = np.sqrt(np.clip(upper**2 - along**2, 0.0, None))
    pole = outward + np.array([0.0, -1.0, 0.0])
    v = pole - np.sum(pole * u, axis=-1, keepdims=True) * u
    v = v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-9)
    return shoulder + along * u + h * v


class MotorCommandGraph(MotorSystem):
    """Per-subsystem graphs of motor states and guiding-stroke commands; learns edges by watching (K&G §4.2)."""

    name = "motor-command-graph"
    parameters = (
        Parameter("rest", str, "rest", "The pose every subsystem's hub node is taken from."),
        Parameter("poses", dict, {}, "Named poses (at least the rest pose), as for keyframe. Not needed with clips."),
        Parameter("subsystems", dict, {"left_wrist": ["left_wrist"], "right_wrist": ["right_wrist"]},
                  "Motor subsystems: name = [parts it moves]."),
        Parameter("hands", bool, True, "Give every hand of the body a subsystem of its own, named as the hand, that "
                  "moves its fingers (the paper's hand motor command graphs)."),
        Parameter("tolerance", float, 0.04, "Metres within which two wrist states are the same node.", minimum=0.0),
        Parameter("hand_tolerance", float, 0.15, "Radians of finger joint angle within which two hand configurations "
                  "are the same node (and a hand movement has come back to its hub).", minimum=0.0),
        Parameter("arms", list, [["left_shoulder", "left_elbow", "left_wrist"], ["right_shoulder", "right_elbow", "right_wrist"]],
                  "Shoulder, elbow, wrist triples whose elbow follows the wrist by inverse kinematics."),
        *CLIP_PARAMETERS,
        Parameter("strokes", doc="With clips: how each clip is cut into guiding strokes, one command each (K&G "
                  "§4.3; plugins.lib.strokes).", parameters=STROKE_PARAMETERS),
    )

    def attach(self, owner: Any) -> None:
        import networkx as nx

        super().attach(owner)
        body = owner.body
        self.body = body
        self.clips = clips = repertoire_for(self.params, owner)
        if clips is not None:
            self.rest = clips.hubs[0].copy()
            defaults = {p.name: p.default for p in self.parameters}
            if self.params["subsystems"] == defaults["subsystems"]:  # the whole body unless told otherwise
                self.params = {**self.params, "subsystems": {"body": [p for p in body.parts if p != body.root]}}
            if self.params["arms"] == defaults["arms"]:
                self.params = {**self.params, "arms": []}
        else:
            poses = parse_poses(self.params["poses"], body)
            if self.params["rest"] not in poses.names:
                raise ConfigError(f"unknown pose {self.params['rest']!r}", key=("rest",), expected="a declared pose",
                                  available=poses.names)
            self.rest = poses[self.params["rest"]]
        self.subsystems: dict[str, np.ndarray] = {}
        declared = dict(self.params["subsystems"])
        if self.params["hands"]:
            declared.update({name: list(hand.fingers) for name, hand in body.hands.items() if name not in declared})
        angles = body.angle_mask
        for name, parts in declared.items():
            if not isinstance(parts, list) or not parts:
                raise ConfigError("invalid", key=("subsystems", name), expected="a non-empty list of part names")
            self.subsystems[name] = np.array([body.index(p, key=("subsystems", name)) for p in parts])
            if 0 < angles[self.subsystems[name]].sum() < len(parts):
                raise ConfigError("a subsystem mixes fingers and position parts", key=("subsystems", name),
                                  expected="only fingers (a hand) or only position parts",
                                  available=[f"fingers: {', '.join(body.angle_parts)}"])
        self.arms = []
        for i, triple in enumerate(self.params["arms"]):
            if not isinstance(triple, list) or len(triple) != 3:
                raise ConfigError("invalid", key=("arms", i), expected="[shoulder, elbow, wrist]")
            s, e, w = (body.index(p, key=("arms", i)) for p in triple)
            upper = float(np.linalg.norm(self.rest[e] - self.rest[s]))
            fore = float(np.linalg.norm(self.rest[w] - self.rest[e]))
            outward = np.sign(self.rest[s, 0] - self.rest[body.root_index, 0]) * np.array([1.0, 0.0, 0.0])
            self.arms.append((s, e, w, upper, fore, outward))
        self.graphs: dict[str, nx.MultiDiGraph] = {}
        self.active: dict[str, str] = {}
        for name, idx in self.subsystems.items():
            g = nx.MultiDiGraph()
            g.add_node("hub", state=self.rest[idx].copy(), hub=True)
            self.graphs[name] = g
            self.active[name] = "hub"
        self._edges: dict[str, Edge] = {}  # by movement name; the graphs' edges are keyed by it too
        self.sequences: dict[str, list[str]] = {}  # a learned path of several edges, performed as one movement
        self.together: dict[str, list[str]] = {}  # movements of several subsystems performed at once
        self._counter = 0
        self._state = self.rest.copy()
        self.labels: dict[str, str] = {}  # sequence name -> movement, for sequences learned from labelled clips
        self._takes: dict[str, list[tuple[tuple[str, ...], str, np.ndarray | None, float]]] = {}  # its clips
        if clips is not None:
            self._learn_clips(clips)

    def _learn_clips(self, clips: Any) -> None:
        """Every clip through the inverse model into a chain of edges from the hub, named by its movement."""
        for clip in clips.clips:
            self.learn_take(clip.movement, clip.motion, source=str(clip.source))

    def learn_take(self, movement: str, motion: Motion, *, source: str = "") -> tuple[str, ...]:
        """One performance of ``movement`` (root-relative, in the body's frame, with its world positions where it
        travels: :func:`plugins.lib.clip_repertoire.root_relative_motion`) through the inverse model into a chain of
        edges from the hub, one guiding stroke each (K&G §4.3), remembered as one of the movement's takes
        (:meth:`takes`) and performed under its name. A labelled clip at composition; a demonstration no take
        predicted when the forward model learns it (true imitation). Returns the new edges' names (none: nothing
        moved enough to be a stroke)."""
        (subsystem, idx), = list(self.subsystems.items())[:1]
        criteria = StrokeCriteria(drop=self.params["strokes"]["drop"], angle=self.params["strokes"]["angle"])
        observed = fill_hidden(motion.positions[:, idx], motion.visible[:, idx], default=self.rest[idx])
        names = self.learn_observed(subsystem, "hub", observed, motion.fps, criteria=criteria, origin=source,
                                    hub_tolerance=self.params["hub_radius"], refine=False,
                                    travel=clip_travel(motion, self.body.root_index),
                                    turn=clip_turn(motion, self.body.root_index))
        if not names:
            return ()
        n = sum(1 for label in self.labels.values() if label == movement)
        self.add_sequence(names, name=example_name(movement, n), label=movement)
        self._takes.setdefault(movement, []).append((tuple(names), subsystem, observed, motion.fps))
        self.move_to(subsystem, "hub")
        return tuple(names)

    def takes(self) -> dict[str, list[tuple[tuple[str, ...], str, np.ndarray | None, float]]]:
        """The takes of each movement learned from labelled clips or by watching (:meth:`learn_take`): per movement,
        one ``(edges, subsystem, observed, fps)`` per performance: the chain of edges (names) it became, the
        subsystem it moves, and its own positions of that subsystem's parts (n, k, 3) at ``fps``, as the inverse
        model was given them (``None`` and 0 for a take restored from a saved state, which keeps its edges only).
        The forward model following real people predicts with every take (:mod:`plugins.matchers.forward_model.
        following`)."""
        return {movement: list(takes) for movement, takes in self._takes.items()}

    def examples(self, fps: float = 30.0) -> list[tuple[str, Motion]]:
        """The clips the graphs were learned from, by movement; else one performance of each movement."""
        if self.clips is not None:
            return [(c.movement, c.motion) for c in self.clips.clips]
        return super().examples(fps)

    def play_take(self, edges: tuple[str, ...], subsystem: str, fps: float = 30.0) -> list[np.ndarray]:
        """A take's edges played by their commands (each from its start to its duration, at ``fps``), the subsystem's
        parts where the commands put them and the other parts at rest: one array of frames (n, P, 3) per edge."""
        idx, pieces = self.subsystems[subsystem], []
        for name in edges:
            edge = self.edge(name)
            t = np.arange(0.0, edge.duration + 0.5 / fps, 1.0 / fps)
            frames = np.repeat(self.rest[None], len(t), axis=0)
            frames[:, idx] = np.stack([c.position(t) for c in edge.commands], axis=1)
            pieces.append(frames)
        return pieces

    def take_motions(self, fps: float = 30.0) -> dict[str, list[Motion | None]]:
        """Movement -> each of its takes (in the order of :meth:`takes`) as a motion: the positions the inverse model
        was given (its subsystem's parts, the others at rest), else (a take restored from a saved state) its commands
        played at ``fps`` (:meth:`play_take`); ``None`` for a take with no frame."""
        out: dict[str, list[Motion | None]] = {}
        for movement, takes in self._takes.items():
            for edges, subsystem, observed, rate in takes:
                if observed is not None:
                    frames = np.repeat(self.rest[None], len(observed), axis=0)
                    frames[:, self.subsystems[subsystem]] = observed
                else:
                    pieces = self.play_take(edges, subsystem, fps)
                    frames, rate = (np.concatenate(pieces) if pieces else np.zeros((0, len(self.body.parts), 3))), fps
                out.setdefault(movement, []).append(Motion(frames, rate, self.body.parts) if len(frames) else None)
        return out

    # -- the graph ------------------------------------------------------------------------------

    def edges(self, subsystem: str) -> list[Edge]:
        """Every edge of a subsystem's graph."""
        return [data["edge"] for _, _, data in self.graphs[subsystem].edges(data=True)]

    def edges_from(self, subsystem: str, node: str) -> list[Edge]:
        """Every edge leaving ``node``: the candidates of the forward model."""
        return [data["edge"] for _, _, data in self.graphs[subsystem].out_edges(node, data=True)]

    def state(self, subsystem: str, node: str) -> np.ndarray:
        """The motor state of ``node``: the positions (or a hand's joint angles) of the subsystem's parts (k, 3)."""
        return self.graphs[subsystem].nodes[node]["state"]

    def active_node(self, subsystem: str) -> str:
        """The node the subsystem is in (where its last movement ended)."""
        return self.active[subsystem]

    def is_hand(self, subsystem: str) -> bool:
        """Whether the subsystem moves fingers (its states are joint angles) rather than positions."""
        return bool(self.body.angle_mask[self.subsystems[subsystem]].all())

    def tolerance(self, subsystem: str) -> float:
        """How close (metres, or radians for a hand) two states of the subsystem must be to be the same node."""
        return self.params["hand_tolerance"] if self.is_hand(subsystem) else self.params["tolerance"]

    def learn(self, subsystem: str, start: str, commands: list[Command], *, end: str | None = None,
              origin: str = "", shown: np.ndarray | None = None, shown_fps: float = 0.0,
              travel: np.ndarray | None = None, turn: np.ndarray | None = None) -> str:
        """Add an edge of ``commands`` (one per part of the subsystem) from node ``start``; returns its movement name.

        Guiding strokes for a wrist subsystem, hand transitions for a hand. The edge ends in ``end`` if given
        (a hub, say), else in the node at the commands' targets (an existing one within :meth:`tolerance`, or a new one).
        ``shown`` and ``shown_fps``: the piece of the demonstration it was learned from (:attr:`Edge.shown`);
        ``travel``: where the body went meanwhile, one row per frame of ``shown`` (:attr:`Edge.travel`); ``turn``:
        how far it turned since the edge began, one per frame (:attr:`Edge.turn`).
        """
        if travel is not None:
            travel = np.array(travel, dtype=float)
            if shown is None or travel.shape != (len(shown), 3):
                raise ValueError(f"an edge's travel needs one [x, y, z] per frame of its demonstration, not shape "
                                 f"{travel.shape}")
        if turn is not None:
            turn = np.array(turn, dtype=float)
            if shown is None or turn.shape != (len(shown),):
                raise ValueError(f"an edge's turn needs one angle per frame of its demonstration, not shape "
                                 f"{turn.shape}")
        if end is None:
            target = np.stack([c.target for c in commands])
            end = self._near_node(subsystem, target) or self._new_node(subsystem, target)
        self._counter += 1
        edge = Edge(f"{subsystem}:e{self._counter}", subsystem, start, end, tuple(commands), origin,
                    None if shown is None else np.array(shown, dtype=float), float(shown_fps) if shown is not None else 0.0,
                    travel, turn)
        self._add(edge)
        if self.owner is not None:
            self.owner.announce("likeme_movement_learned", character=self.owner, movement=edge.name,
                                details={"subsystem": subsystem, "from": start, "to": end, "commands": len(commands)})
        return edge.name

    def _add(self, edge: Edge) -> None:
        self.graphs[edge.subsystem].add_edge(edge.source, edge.target, key=edge.name, edge=edge)
        self._edges[edge.name] = edge

    def learn_observed(self, subsystem: str, start: str, observed: np.ndarray, fps: float, *,
                       criteria: StrokeCriteria = StrokeCriteria(), origin: str = "inverse model",
                       hub_tolerance: float = 0.05, refine: bool = True,
                       travel: np.ndarray | None = None, turn: np.ndarray | None = None) -> list[str]:
        """True imitation (K&G §4.3): an observed movement of the subsystem's parts becomes new edges from ``start``.

        ``observed`` (n, k, 3) holds the positions (a hand: the fingers' joint angles) of the subsystem's k parts.
        It is cut into strokes at the break points of :func:`plugins.lib.strokes.breaks` (``criteria``), the
        inverse model turns each into a command (:func:`plugins.lib.inverse_model.commands_from_segment`), and
        the commands become a chain of edges from ``start``; the last ends in the hub when the movement came back
        within ``hub_tolerance`` metres of it (a hand: within :meth:`tolerance`). Each edge keeps its piece of the
        demonstration (:attr:`Edge.shown`) and, with ``travel`` (n, 3: the root's velocity in the body's frame at
        each frame of ``observed``), where the body went meanwhile (:attr:`Edge.travel`), and with ``turn`` (n,: how
        far it had turned at each frame) how far it turned during each edge (:attr:`Edge.turn`). Returns the new
        edges' names.
        """
        n, k, _ = observed.shape
        hand = self.is_hand(subsystem)
        cuts = breaks(observed.reshape(n, k * 3), fps, criteria)
        home = np.linalg.norm(observed[-1] - self.state(subsystem, "hub"), axis=-1).max() <= (
            self.tolerance(subsystem) if hand else hub_tolerance)
        pieces = commands_from_segment(observed, fps, cuts, hand=hand, refine=refine)
        # the frames of each piece, as commands_from_segment cuts them: one piece for a hand, else one per stroke
        # between break points, pieces shorter than two frames left out
        ends = [0, *cuts, n - 1]
        spans = [(0, n - 1)] if hand else [(a, b) for a, b in zip(ends, ends[1:]) if b - a >= 2]
        names, node = [], start
        for (commands, last), (a, b) in zip(pieces, spans):
            name = self.learn(subsystem, node, commands, end="hub" if last and home else None, origin=origin,
                              shown=observed[a: b + 1], shown_fps=fps,
                              travel=None if travel is None else travel[a: b + 1],
                              turn=None if turn is None else turn[a: b + 1] - turn[a])
            names.append(name)
            node = self.edge(name).target
        return names

    def _new_node(self, subsystem: str, state: np.ndarray) -> str:
        g = self.graphs[subsystem]
        name = f"n{sum(1 for n in g.nodes if n != 'hub') + 1}"
        g.add_node(name, state=np.asarray(state, dtype=float), hub=False)
        return name

    def _near_node(self, subsystem: str, state: np.ndarray) -> str | None:
        """An existing node within :meth:`tolerance` (every part) of ``state``: the same motor state."""
        tolerance = self.tolerance(subsystem)
        for node, data in self.graphs[subsystem].nodes(data=True):
            if np.linalg.norm(data["state"] - state, axis=-1).max() <= tolerance:
                return node
        return None

    def edge(self, movement: str) -> Edge:
        """The edge a movement (edge) name stands for."""
        return self._edges[movement]

    # -- the motor system interface -------------------------------------------------------------

    def add_sequence(self, edges: list[str], *, name: str | None = None, label: str | None = None) -> str:
        """Name a path of edges (a movement learned as several strokes) so it can be performed as one movement.

        ``label`` is the movement it is an example of (a clip's movement); ``name`` defaults to a new number.
        """
        if len(edges) == 1 and name is None:
            return edges[0]
        for known_name, known in self.sequences.items():
            if known == list(edges) and name is None:
                return known_name
        subsystem = self._edges[edges[0]].subsystem
        name = name or f"{subsystem}:m{len(self.sequences) + 1}"
        self.sequences[name] = list(edges)
        if label is not None:
            self.labels[name] = label
        return name

    def add_together(self, movements: list[str]) -> str:
        """Name movements of different subsystems performed at once (a hand-arm movement, §4.2); one is itself."""
        if len(movements) == 1:
            return movements[0]
        subsystems = [self.subsystem_of(m) for m in movements]
        if len(set(subsystems)) < len(subsystems):
            raise ValueError(f"movements performed together need subsystems of their own, not {subsystems}")
        name = "+".join(movements)
        self.together[name] = list(movements)
        return name

    def subsystem_of(self, movement: str) -> str:
        """The subsystem an edge or a path of edges moves."""
        return self._edges[self.sequences.get(movement, [movement])[0]].subsystem

    def label(self, movement: str) -> str:
        return self.labels.get(movement, movement)

    def known_sequence(self, path: tuple[str, ...]) -> tuple[str, ...]:
        """The whole learned command sequence that ``path`` begins, else ``path`` itself."""
        for edges in self.sequences.values():
            if tuple(edges[: len(path)]) == tuple(path):
                return tuple(edges)
        return tuple(path)

    def label_of_path(self, path: tuple[str, ...]) -> str | None:
        """The labelled movement (clip repertoires) ``path`` stands for; ``None`` if none or several.

        The labelled sequences that agree with ``path`` longest (their first edges are its first edges) decide:
        a path that runs through a whole clip and on, or that leaves a clip's edges for an edge of another
        (nodes of different clips can be shared), is the movement whose edges it followed first and longest.
        Unlabelled sequences (a path the forward model committed to, one learned by watching) do not count.
        """
        path = tuple(path)
        labelled = [(tuple(edges), self.labels[n]) for n, edges in self.sequences.items() if n in self.labels]
        for k in range(len(path), 0, -1):
            labels = {label for edges, label in labelled if edges[:k] == path[:k]}
            if labels:
                return labels.pop() if len(labels) == 1 else None
        return None

    def movements(self) -> list[str]:
        if self.labels:
            return list(dict.fromkeys(self.labels.values()))
        return [*self._edges, *self.sequences, *self.together]

    def rest_pose(self) -> np.ndarray:
        return self.rest

    def _paths(self, movement: str) -> list[list[str]]:
        """The edge paths a movement runs, one per subsystem, all at once."""
        if movement not in self.sequences and movement not in self.together and movement in self.labels.values():
            movement = next(n for n, label in self.labels.items() if label == movement)  # a clip movement's first clip
        if movement in self.together:
            return [path for part in self.together[movement] for path in self._paths(part)]
        if movement in self.sequences:
            return [list(self.sequences[movement])]
        if movement in self._edges:
            return [[movement]]
        raise ConfigError(f"unknown movement {movement!r}", expected="a learned motor command", available=self.movements())

    def perform(self, movement: str, *, speed: float = 1.0, fps: float = 30.0) -> Motion:
        """Execute an edge, a path of edges or subsystems' movements together, from the current posture.

        Each subsystem runs its path while the others hold their state (and go on holding once their own path
        has ended); the active nodes become the paths' ends.
        """
        tracks = []
        for path in self._paths(movement):
            pieces = []
            for name in path:
                edge = self.edge(name)
                subsystem, end = edge.subsystem, edge.target
                commands = [c.retimed(c.duration / speed) for c in edge.commands]
                duration = max(c.duration for c in commands)
                t = np.linspace(0.0, duration, max(2, int(round(duration * fps)) + 1))
                pieces.append(np.stack([c.position(t) for c in commands], axis=1))
            tracks.append((self.subsystems[subsystem], np.concatenate(pieces)))
            self.active[subsystem] = end
        frames = np.repeat(self._state[None], max(len(p) for _, p in tracks), axis=0)
        for idx, positions in tracks:
            frames[: len(positions), idx] = positions
            frames[len(positions):, idx] = positions[-1]
        self._place_elbows(frames)
        self._state = frames[-1].copy()
        return Motion(frames, fps, self.body.parts)

    def _place_elbows(self, frames: np.ndarray) -> None:
        for s, e, w, upper, fore, outward in self.arms:
            frames[:, e] = place_elbows(frames[:, s], frames[:, w], upper, fore, outward)

    def interrupt(self, frame: int, pose: np.ndarray, *, fps: float = 30.0) -> Motion | None:
        """The body's way from ``pose``, where an imitation was stopped at ``frame`` of its motion, to the motor state.

        The matcher that stopped the imitation has put the deviating subsystem back in its last correct node
        (:meth:`move_to`, K&G §4.4, Fig. 3); the other subsystems of the motion were right and go on to the end
        of their commands. The way is straight, with a bell-shaped velocity profile, and takes as long as the
        stopped motion had run (at least a fifth of a second). ``None`` when the body is there already.
        """
        pose = np.asarray(pose, dtype=float)
        target = self._state.copy()
        self._place_elbows(target[None])
        if np.allclose(pose, target, atol=1e-9):
            return None
        u = np.linspace(0.0, 1.0, max(int(round(0.2 * fps)), frame) + 1)
        frames = pose + progress(u, 0.5, 0.0)[:, None, None] * (target - pose)
        self._place_elbows(frames)
        self._state = frames[-1].copy()
        return Motion(frames, fps, self.body.parts)

    def reset(self) -> None:
        """Every subsystem back in its hub node, the body at rest."""
        for name in self.subsystems:
            self.move_to(name, "hub")

    def move_to(self, subsystem: str, node: str, *, posture: bool = True) -> None:
        """Put a subsystem in ``node``: back at its hub, back in the last correct node after a deviation (§4.4), or
        where a demonstration a matcher followed ended.

        With ``posture`` the body's posture of the subsystem's parts goes to the node's state too (what the next
        movement starts from); without, only the active node changes (the body stays where performing the
        commands left it, within :meth:`tolerance` of the node).
        """
        self.active[subsystem] = node
        if posture:
            self._state[self.subsystems[subsystem]] = self.state(subsystem, node)

    def describe(self) -> dict[str, Any]:
        return {
            "movements": len(self._edges),
            "subsystems": {n: {"nodes": g.number_of_nodes(), "edges": g.number_of_edges(), "active": self.active[n],
                               "commands": [f"{e.source} -> {e.target} ({e.name.split(':')[-1]})" for e in self.edges(n)]}
                           for n, g in self.graphs.items()},
        }

    def get_state(self) -> dict[str, Any]:
        """Learned nodes, edges, sequences and the movement labels of clip sequences, per subsystem."""
        state = {}
        for name, g in self.graphs.items():
            sequences = {m: e for m, e in self.sequences.items() if self.subsystem_of(m) == name}
            state[name] = {
                "nodes": {n: d["state"].round(6).tolist() for n, d in g.nodes(data=True) if n != "hub"},
                "edges": [{"from": e.source, "to": e.target, "name": e.name, "commands": [c.to_dict() for c in e.commands],
                           **({"shown": e.shown.round(6).tolist(), "shown_fps": e.shown_fps}
                              if e.shown is not None and e.origin in ("inverse model", "loaded") else {}),
                           **({"travel": e.travel.round(6).tolist()}
                              if e.travel is not None and e.shown is not None
                              and e.origin in ("inverse model", "loaded") else {}),
                           **({"turn": e.turn.round(6).tolist()}
                              if e.turn is not None and e.shown is not None
                              and e.origin in ("inverse model", "loaded") else {})}
                          for e in self.edges(name)],
                "sequences": sequences,
                "labels": {m: label for m, label in self.labels.items() if m in sequences},
                "together": {m: parts for m, parts in self.together.items() if self.subsystem_of(parts[0]) == name},
            }
        return state

    def set_state(self, state: dict[str, Any], *, check: bool = False) -> None:
        """Add the saved nodes, edges, sequences, labels and movements performed together, per subsystem.

        Everything is checked first (types, shapes, finite values, edges between known nodes, sequences of known
        edges); a saved edge replaces one of the same name built already (from clips, say).
        """
        if not isinstance(state, dict):
            raise ConfigError("invalid motor command graph state", expected="a table of subsystems")
        keys = ("nodes", "edges", "sequences", "labels", "together")

        def bad(problem: str, key: tuple, expected: str) -> ConfigError:
            return ConfigError(problem, key=key, expected=expected)

        def names(value: Any, key: tuple, known: set) -> list[str]:
            if not (isinstance(value, list) and value and all(isinstance(v, str) and v in known for v in value)):
                raise bad(f"invalid list {value!r}"[:200], key, "a non-empty list of known edge or movement names")
            return list(value)

        nodes, edges = {}, {}
        for name, entry in state.items():
            if name not in self.graphs:
                raise ConfigError(f"unknown subsystem {name!r}", key=(name,), expected="a subsystem", available=list(self.graphs))
            if not isinstance(entry, dict):
                raise bad("invalid subsystem state", (name,), "a table of " + ", ".join(keys))
            for k in entry:
                if k not in keys:
                    raise ConfigError(f"unknown key {k!r}", key=(name, k), expected="a subsystem state key",
                                      available=keys)
            table = entry.get("nodes", {})
            if not isinstance(table, dict):
                raise bad("invalid nodes", (name, "nodes"), "a table of node = state")
            k = len(self.subsystems[name])
            for node, value in table.items():
                try:
                    array = np.asarray(value, dtype=float)
                except (TypeError, ValueError, OverflowError):
                    array = np.zeros(0)
                if node == "hub" or array.shape != (k, 3) or not np.isfinite(array).all() or np.abs(array).max() >= 1e6:
                    raise bad(f"invalid node {node!r}", (name, "nodes", node),
                              f"a node other than the hub with a state of shape ({k}, 3) of finite numbers")
                nodes[(name, node)] = array
            known_nodes = set(self.graphs[name].nodes) | {n for (s, n) in nodes if s == name}
            items = entry.get("edges", [])
            if not isinstance(items, list):
                raise bad("invalid edges", (name, "edges"), "a list of edges")
            for i, e in enumerate(items):
                key = (name, "edges", i)
                what = "an edge written by get_state: {from, to, name, commands}"
                if not isinstance(e, dict) or not all(isinstance(e.get(x), str) for x in ("from", "to", "name")):
                    raise bad("invalid edge", key, what)
                number = e["name"].removeprefix(f"{name}:e")
                if number == e["name"] or not number.isascii() or not number.isdigit() or len(number) > 9:
                    raise bad(f"invalid edge name {e['name']!r}", (*key, "name"), f"{name}:e<number>")
                if e["name"] in edges:
                    raise bad(f"edge {e['name']!r} twice", (*key, "name"), "each edge once")
                for end in ("from", "to"):
                    if e[end] not in known_nodes:
                        raise ConfigError(f"unknown node {e[end]!r}", key=(*key, end),
                                          expected="a node of the subsystem", available=sorted(known_nodes))
                commands = e.get("commands", e.get("strokes"))
                if not isinstance(commands, list) or not commands or not all(isinstance(c, dict) for c in commands):
                    raise bad("invalid commands", key, "a non-empty list of commands written by get_state")
                try:
                    built = tuple(command_from_dict(c) for c in commands)
                except (TypeError, ValueError, KeyError, OverflowError) as exc:
                    raise bad(f"invalid edge ({exc})"[:300], key, "an edge written by get_state") from None
                values = [v for c in built for k, v in c.to_dict(arrays=True).items() if k != "shape"]
                if not all(np.isfinite(np.asarray(v, dtype=float)).all() and np.abs(v).max() < 1e6 for v in values):
                    raise bad("invalid edge (a number that is not finite, or beyond 1e6)", key,
                              "an edge written by get_state")
                if not all(0 < c.duration <= 3600 for c in built):
                    raise bad("invalid edge (a command longer than an hour)", key, "an edge written by get_state")
                shown, shown_fps = e.get("shown"), e.get("shown_fps", 0.0)
                if shown is not None:
                    try:
                        shown = np.asarray(shown, dtype=float)
                    except (TypeError, ValueError, OverflowError):
                        shown = np.zeros(0)
                    if (shown.shape[1:] != (len(built), 3) or len(shown) < 2 or not np.isfinite(shown).all()
                            or np.abs(shown).max() >= 1e6):
                        raise bad("invalid shown", (*key, "shown"), f"the demonstration's frames, at least two, "
                                  f"each [x, y, z] of its {len(built)} parts, finite")
                    if not (isinstance(shown_fps, (int, float)) and 0 < shown_fps <= 1000):
                        raise bad(f"invalid shown_fps {shown_fps!r}"[:200], (*key, "shown_fps"),
                                  "frames per second of shown, above 0 and at most 1000")
                travel = e.get("travel")
                if travel is not None:
                    try:
                        travel = np.asarray(travel, dtype=float)
                    except (TypeError, ValueError, OverflowError):
                        travel = np.zeros(0)
                    if (shown is None or travel.shape != (len(shown), 3) or not np.isfinite(travel).all()
                            or np.abs(travel).max() >= 1e6):
                        raise bad("invalid travel", (*key, "travel"), "where the body went at each frame of shown "
                                  "(an edge with shown): one [x, y, z] of finite m/s per frame")
                turn = e.get("turn")
                if turn is not None:
                    try:
                        turn = np.asarray(turn, dtype=float)
                    except (TypeError, ValueError, OverflowError):
                        turn = np.zeros(0)
                    if (shown is None or turn.shape != (len(shown),) or not np.isfinite(turn).all()
                            or np.abs(turn).max() >= 1e6):
                        raise bad("invalid turn", (*key, "turn"), "how far the body turned at each frame of shown "
                                  "(an edge with shown): one finite angle (radians) per frame")
                edges[e["name"]] = (Edge(e["name"], name, e["from"], e["to"], built, "loaded", shown,
                                           float(shown_fps) if shown is not None else 0.0, travel, turn), int(number))
        known_edges = set(self._edges) | set(edges)
        sequences, labels, together = {}, {}, {}
        for name, entry in state.items():
            for k, out in (("sequences", sequences), ("labels", labels), ("together", together)):
                if not isinstance(entry.get(k, {}), dict):
                    raise bad(f"invalid {k}", (name, k), "a table of movement = ...")
            for movement, value in entry.get("sequences", {}).items():
                sequences[movement] = names(value, (name, "sequences", movement), known_edges)
        known_sequences = set(self.sequences) | set(sequences)
        for name, entry in state.items():
            for movement, label in entry.get("labels", {}).items():
                if movement not in known_sequences or not isinstance(label, str) or not label:
                    raise bad(f"invalid label of {movement!r}", (name, "labels", movement), "sequence = movement name")
                labels[movement] = label
            for movement, value in entry.get("together", {}).items():
                together[movement] = names(value, (name, "together", movement), known_edges | known_sequences)
        if check:
            return
        for (name, node), array in nodes.items():
            self.graphs[name].add_node(node, state=array, hub=False)
        for edge, number in edges.values():
            if edge.name in self._edges:  # the same command built already (from clips, say): the saved one replaces it
                known = self._edges[edge.name]
                self.graphs[known.subsystem].remove_edge(known.source, known.target, known.name)
                if edge.shown is None and known.shown is not None:  # a clip's demonstration is not saved: kept,
                    # and the edge is still the clip's
                    edge = Edge(edge.name, edge.subsystem, edge.source, edge.target, edge.commands, known.origin,
                                known.shown, known.shown_fps, known.travel, known.turn)
            self._add(edge)
            self._counter = max(self._counter, number)
        self.sequences.update(sequences)
        self.labels.update(labels)
        self.together.update(together)
        taken = {edges for takes in self._takes.values() for edges, *_ in takes}
        for sequence, label in labels.items():  # a take learned by watching, saved: a take again
            edges = tuple(self.sequences[sequence])
            if edges and edges not in taken:
                self._takes.setdefault(label, []).append((edges, self.subsystem_of(sequence), None, 0.0))


@hookimpl
def likeme_register_motor_systems():
    return [MotorCommandGraph]
