"""Motor system ``posegraph``: poses as nodes, movements as paths, transitions through hubs.

Buchsbaum & Blumberg 2005, §4.1. Source animation (here: the timed key poses of
the character file, see :mod:`plugins.motor.key_poses`) is broken into *poses*; the
poses of one *movement* are connected in order, and every movement starts and
ends in a *hub* pose (standing), which all movements share. Any movement the
character performs is a path through the graph, and a transition from one
movement to another passes through a hub.

Resolution: each movement is sampled into pose nodes at ``node_rate`` poses per
second (the "multi-resolution" of the paper's posegraph: the graph is as fine
as recognition needs, the played animation stays as smooth as its key poses).
All node poses sit in one contiguous array ``node_poses`` of shape (N, P, 3),
local frame, so the matcher searches the whole graph with one vectorised
distance; ``graph`` is a :class:`networkx.DiGraph` whose nodes carry their index
into that array, their movement and whether they are hubs. ``node_travel`` (N, 3)
holds each node's *travel*, the root's velocity in the body's own frame
(:mod:`plugins.lib.travel`; zero at the hubs), which the root-relative poses
leave out: a walk forwards and a walk backwards have nearly the same poses.
``node_motion`` (N, P, 3) holds how each part was moving at the node (its velocity
relative to the root, m/s, measured at the clip's own frame rate) and
``node_heading`` (N,) how far the body had turned since its movement began
(radians; NaN where not known): what a comparison that sees motion compares
(:mod:`plugins.matchers.comparison`), which the poses alone do not show.
``node_noise`` (N, 2) holds the tracker's jitter a clip's nodes keep (the mean over
the parts of the squared noise of a position, m^2, and of a velocity, (m/s)^2;
:mod:`plugins.lib.jitter`; 0 for key poses and what was learned by watching).

Learning (§5.2.3, §7.3): :meth:`Posegraph.learn` adds an observed path as a new
movement (new nodes from the observed poses, entered from and returning to the
hub), and :meth:`Posegraph.play_path` plays any path.

Learning from repeated demonstrations (§7.3: "The problem of distinguishing genuinely novel movements could be
lessened through repeated demonstration and observation. This would allow the observing character to develop a model
of the new movement, allowing for more reliable comparisons"): a learned movement keeps its *takes*, the
demonstrations it was learned from. Each later demonstration recognised as it (announced through the
``likeme_movement_recognised`` hook, :func:`likeme_movement_recognised`) is one more take, up to ``takes``; the
movement is then learned again from the takes together (:meth:`Posegraph.learn_takes`, also callable with several
takes at once): its path is their *mean*, the DTW barycentre of the takes (Petitjean et al. 2011,
:func:`dtaidistance.dtw_barycenter.dba_loop`, started from the take nearest the others), and each take stays in the
graph as a path of the same movement, so a demonstration is compared with the typical path and with the ways it was
seen performed, as clips of one movement are. Its *spread* is the mean eq. 1 distance of the takes from the mean
path, aligned. The movement is performed along the mean path. With ``takes = 1`` a movement is what its first
demonstration showed (the paper's learning).
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

from plugins.lib.clip_repertoire import CLIP_PARAMETERS, example_name, repertoire_for
from plugins.lib.compiled import one_thread
from plugins.lib.jitter import feature_noise
from plugins.lib.pose_distance import pose_distance
from plugins.lib.travel import body_velocity, turned
from plugins.lib.velocity import derivative
from plugins.motor.key_poses import REPERTOIRE_PARAMETERS, KeyPoses, interpolate, play, read_repertoire, sample
from toolkit import ConfigError, Motion, MotorSystem, Parameter, hookimpl

_OPTIONAL = {"poses": {}, "movements": {}}  # with clips, the key-pose repertoire is not needed
_TOGETHER = 256
"""Key-pose movements played and differentiated in one call at most (bounds the memory of a large repertoire)."""


class Posegraph(MotorSystem):
    """Key poses as graph nodes, movements as paths hub to hub; plays and learns paths (§4.1)."""

    name = "posegraph"
    parameters = (
        *(p if p.name not in _OPTIONAL else Parameter(p.name, p.type, _OPTIONAL[p.name], p.doc + " Not needed with clips.")
          for p in REPERTOIRE_PARAMETERS),
        *CLIP_PARAMETERS,
        Parameter("cycles", bool, True, "A clip that ends where it began (within hub_radius), away from every hub "
                  "(one cycle of a walk or a run, cropped from a longer recording), loops: an edge leads from its "
                  "last pose back to its first, so a path can follow the movement for as many cycles as it is seen "
                  "(false: every path leaves through a hub, the paper's posegraph)."),
        Parameter("node_rate", float, 10.0, "Pose nodes per second of movement: the graph's resolution. Higher "
                  "recognises finer timing at the cost of search time.", minimum=1.0, maximum=120.0),
        Parameter("takes", int, 3, "Demonstrations a learned movement is made from (§7.3): each later one recognised as "
                  "it is one more take, until this many, and its path is the takes' mean (DTW barycentre); 1: the "
                  "first demonstration alone (the paper's learning).", minimum=1, maximum=50),
    )

    def attach(self, owner: Any) -> None:
        super().attach(owner)
        self.body = owner.body
        self.clips = repertoire_for(self.params, owner)
        if self.clips is None:
            if not self.params["poses"]:
                raise ConfigError("no repertoire", key=("poses",), expected="poses and movements, or clips and profile")
            self.key_poses, self.hubs, self.repertoire = read_repertoire(self.params, self.body)
        else:
            names = tuple("hub" if i == 0 else f"hub{i + 1}" for i in range(len(self.clips.hubs)))
            self.key_poses, self.hubs, self.repertoire = KeyPoses(names, self.clips.hubs), names, {}
        self.learned: dict[str, dict[str, Any]] = {}
        self._build()

    # -- the graph -------------------------------------------------------------------------

    def _build(self) -> None:
        import networkx as nx

        n_parts = self.body.n_parts
        rows = _NodeRows()
        for hub in self.hubs:  # at rest in the hubs: no travel, no motion, no turn
            rows.add(self.key_poses[hub][None], np.zeros((1, 3)), np.zeros((1, n_parts, 3)), np.zeros(1))
        self.graph = nx.DiGraph()
        for i, hub in enumerate(self.hubs):
            self.graph.add_node(hub, index=i, movement=None, hub=True)
        self.paths: dict[str, list[str]] = {}
        self.paths_label: dict[str, str] = {}  # path name -> movement (several clips of one movement)
        self.path_clips: dict[str, Motion] = {}  # path name -> the clip it was built from (take_motions)
        played = self._played()
        for name, m in self.repertoire.items():
            sampled, travel, motion = played[name]
            self._add_path(name, m.poses[0], sampled[1:-1], m.poses[-1], rows, travel[1:-1], motion[1:-1],
                           np.zeros(len(sampled) - 2))
        clips = self.clips.clips if self.clips is not None else ()
        for clip in clips:
            self._add_clip(clip.movement, clip.motion, rows, clip.jitter)
        self._add_learned(getattr(self, "learned", {}), rows)  # what it learned by watching, again
        self._set_rows(rows)

    def _set_rows(self, rows: _NodeRows) -> None:
        """The node arrays from ``rows`` (one row per node, in node order)."""
        root = self.body.root_index
        self.node_poses, self.node_travel, self.node_motion, self.node_heading, self.node_noise = rows.arrays()
        self.node_root_relative = self.node_poses - self.node_poses[:, root : root + 1]

    def _sampled(self, motion: Motion, rate: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """A clip's frames kept at ``rate`` per second (default ``node_rate``) and its filled positions (hidden parts
        held, docs/conventions.md)."""
        rate = self.params["node_rate"] if rate is None else rate
        t = np.arange(motion.n_frames) / motion.fps
        keep = np.unique(np.clip(np.round(np.arange(0.0, t[-1] + 1e-9, 1.0 / rate) * motion.fps), 0,
                                 motion.n_frames - 1).astype(int))
        filled = motion.filled(default=self.rest_pose()).positions
        return keep, filled

    def _played(self, fps: float = 30.0) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """Each key-pose movement's nodes (n, P, 3), sampled at ``node_rate``, with their travel (n, 3) and the parts'
        motion (n, P, 3). Key poses are in the body's own frame, so the root's motion there is its travel, measured as
        an observer measures it (at ``fps``, then taken at the nodes' times); each part's motion is its velocity
        relative to the root. The movements of one key timing are played and differentiated together, up to
        :data:`_TOGETHER` at a time, with the numbers each gets alone (a character of thousands of movements loads in
        seconds)."""
        rate = self.params["node_rate"]
        root = self.body.root_index
        by_timing: dict[bytes, list[str]] = {}
        for name, m in self.repertoire.items():
            by_timing.setdefault(np.asarray(m.times, dtype=float).tobytes(), []).append(name)
        out = {}
        with one_thread():  # small least-squares fits (the derivative's ends) over many columns: threads only wait
            for names in by_timing.values():
                for first in range(0, len(names), _TOGETHER):
                    batch = names[first : first + _TOGETHER]
                    times = self.repertoire[batch[0]].times
                    keys = self.key_poses.array[[[self.key_poses.index[p] for p in self.repertoire[name].poses]
                                                 for name in batch]].swapaxes(0, 1)  # (K, M, P, 3)
                    sampled = sample(keys, times, fps=rate)
                    fine = sample(keys, times, fps=fps)
                    at = np.minimum(np.round(np.arange(len(sampled)) * fps / rate).astype(int), len(fine) - 1)
                    motion = derivative(fine - fine[:, :, root : root + 1], fps)[at]
                    seen = np.ones(fine.shape[:1] + fine.shape[2:3], dtype=bool)
                    for j, name in enumerate(batch):
                        travel = body_velocity(fine[:, j], fine[:, j], seen, root, fps, frames=at)
                        out[name] = (sampled[:, j], np.nan_to_num(travel), motion[:, j])
        return out

    def _add_clip(self, movement: str, motion: Motion, rows: _NodeRows, jitter: np.ndarray | None = None) -> None:
        """One example clip as a path between the hubs nearest its ends, sampled at ``node_rate``; its travel and
        turn from its world positions (none known: at rest, turn unknown), its parts' motion from its frames; the
        jitter its nodes keep from the tracker, through the clip's low-pass (:func:`plugins.lib.jitter.
        feature_noise`), from the clip's ``jitter`` (none given: none)."""
        keep, filled = self._sampled(motion)  # hidden parts held (docs/conventions.md)
        sampled = filled[keep]
        hub_rel = self.key_poses.array - self.key_poses.array[:, self.body.root_index : self.body.root_index + 1]
        root = self.body.root_index
        end_rel = [sampled[i] - sampled[i, root] for i in (0, -1)]
        to_hubs = [pose_distance(hub_rel, pose, True) for pose in end_rel]
        ends = [self.hubs[int(np.argmin(d))] for d in to_hubs]
        n = sum(1 for p in self.paths if self.paths_label.get(p) == movement)
        velocity = np.zeros((len(keep), 3))
        heading = np.full(len(keep), np.nan)
        if motion.world is not None:
            velocity = np.nan_to_num(body_velocity(motion.world, motion.positions, motion.visible, root,
                                                   motion.fps)[keep])
            heading = turned(motion.world, motion.positions, motion.visible, root)[keep]
        parts = derivative(filled - filled[:, root : root + 1], motion.fps)[keep]
        name = example_name(movement, n)
        noise = None if jitter is None else feature_noise(jitter, motion.fps, motion.n_frames, low_passed=True)
        self._add_path(name, ends[0], sampled[1:-1], ends[1], rows, velocity[1:-1], parts[1:-1], heading[1:-1],
                       label=movement, noise=noise)
        self.path_clips[name] = motion
        whole = filled[[0, -1]] - filled[[0, -1], root : root + 1]
        cycle = float(pose_distance(whole[0], whole[1], True))  # its very first and last frames
        radius = self.params["hub_radius"]
        if (self.params["cycles"] and len(sampled) > 3 and cycle <= radius
                and min(float(np.min(d)) for d in to_hubs) > radius):
            path = self.paths[name]
            self.graph.add_edge(path[-2], path[1], movement=movement, cycle=True)

    def _add_path(self, name: str, start: str, interior: np.ndarray, end: str, rows: _NodeRows,
                  travel: np.ndarray, motion: np.ndarray, heading: np.ndarray, *, label: str | None = None,
                  noise: np.ndarray | None = None) -> None:
        import networkx as nx

        label = label or name
        path = [start]
        first = rows.count
        for j in range(1, len(interior) + 1):
            node = f"{name}/{j}"
            self.graph.add_node(node, index=first + j - 1, movement=label, hub=False)
            path.append(node)
        rows.add(interior, travel, motion, heading, noise)
        path.append(end)
        nx.add_path(self.graph, path, movement=label)
        self.paths[name] = path
        self.paths_label[name] = label

    @property
    def node_rate(self) -> float:
        """Pose nodes per second of movement: the graph's resolution."""
        return float(self.params["node_rate"])

    @property
    def nodes(self) -> list[str]:
        """Node names in the order of ``node_poses``."""
        order = sorted(self.graph.nodes, key=lambda n: self.graph.nodes[n]["index"])
        return order

    def node_index(self, node: str) -> int:
        return int(self.graph.nodes[node]["index"])

    def movement_of(self, node: str) -> str | None:
        """The movement a node belongs to (``None`` for hubs, which all movements share)."""
        return self.graph.nodes[node]["movement"]

    # -- the motor system interface ----------------------------------------------------------

    def movements(self) -> list[str]:
        return list(dict.fromkeys(self.paths_label[p] for p in self.paths))

    def takes(self) -> dict[str, list[list[str]]]:
        """Movement -> the node names of each of its takes (one path per example clip), hubs left out."""
        out: dict[str, list[list[str]]] = {}
        for name, path in self.paths.items():
            out.setdefault(self.paths_label[name], []).append([n for n in path if not self.graph.nodes[n]["hub"]])
        return out

    def take_motions(self, fps: float = 30.0) -> dict[str, list[Motion | None]]:
        """Movement -> each of its takes (in the order of :meth:`takes`) as a motion: the clip it was built from,
        else its nodes played at ``fps`` (:meth:`play_path`; ``None`` for a take of one node, which does not move)."""
        out: dict[str, list[Motion | None]] = {}
        for name, path in self.paths.items():
            nodes = [n for n in path if not self.graph.nodes[n]["hub"]]
            clip = self.path_clips.get(name)
            if clip is None and len(nodes) > 1:
                clip = self.play_path(nodes, fps=fps)
            out.setdefault(self.paths_label[name], []).append(clip)
        return out

    def rest_pose(self) -> np.ndarray:
        return self.key_poses[self.hubs[0]]

    def examples(self, fps: float = 30.0) -> list[tuple[str, Motion]]:
        """The clips the graph was built from, by movement; else one performance of each movement."""
        if self.clips is not None:
            return [(c.movement, c.motion) for c in self.clips.clips]
        return super().examples(fps)

    def hub_poses(self) -> np.ndarray:
        return np.stack([self.key_poses[h] for h in self.hubs])

    def perform(self, movement: str, *, speed: float = 1.0, fps: float = 30.0) -> Motion:
        if movement in self.repertoire:
            return play(self.key_poses, self.repertoire[movement], self.body.parts, fps=fps, speed=speed)
        if movement in self.paths:
            return self.play_path(self.paths[movement], fps=fps, speed=speed)
        raise ConfigError(f"unknown movement {movement!r}", expected="a movement of this character", available=self.movements())

    def play_path(self, path: list[str], *, fps: float = 30.0, speed: float = 1.0) -> Motion:
        """Interpolate any path of nodes, one node every ``1 / node_rate`` seconds."""
        if len(path) < 2:
            raise ValueError("a path needs at least two nodes")
        for a, b in zip(path, path[1:]):
            if a != b and not self.graph.has_edge(a, b):
                raise ValueError(f"no edge {a} -> {b} in the posegraph")
        keys = self.node_poses[[self.node_index(n) for n in path]]
        times = np.arange(len(path)) / self.params["node_rate"]
        return interpolate(keys, times, self.body.parts, fps=fps, speed=speed)

    def learn(self, name: str, poses: np.ndarray, visible: np.ndarray | None = None, *, source: str = "",
              announce: bool = True) -> list[str]:
        """Add an observed movement as a new path through new nodes (§5.2.3, §7.3): its first take.

        Parameters
        ----------
        name : str
            The new movement's name (must be new).
        poses : array, shape (K, P, 3)
            Root-relative poses sampled at ``node_rate``; the first and last are taken as hub.
        visible : array of bool, shape (K, P), optional
            Hidden parts are filled from the nearest existing node over the visible ones.

        Returns the new path.
        """
        return self.learn_takes(name, [poses], None if visible is None else [visible], source=source, announce=announce)

    def learn_takes(self, name: str, takes: list[np.ndarray], visible: list[np.ndarray | None] | None = None, *,
                    source: str = "", announce: bool = True, mean: np.ndarray | None = None) -> list[str]:
        """Learn a new movement from several demonstrations at once (§7.3): its path is their mean, each stays a take.

        ``takes``: each an array (K_i, P, 3) as :meth:`learn` takes one (root-relative, at ``node_rate``, the first
        and last frames the hub); ``visible`` their masks. At most ``takes`` of them are kept (the first ones).
        ``mean``: the mean path's interior poses (M, P, 3), root-relative, when known (a saved state); else made from
        the takes. Returns the movement's (mean) path.
        """
        if name in self.paths or name in self.paths_label.values():
            raise ConfigError(f"movement {name!r} already exists", expected="a new movement name", available=self.movements())
        self._enter(name, takes, visible, source, mean)
        self._build()
        if announce and self.owner is not None:
            self.owner.announce("likeme_movement_learned", character=self.owner, movement=name,
                                details=self._learned_details(name))
        return self.paths[name]

    def _enter(self, name: str, takes: list[np.ndarray], visible: list[np.ndarray | None] | None, source: str,
               mean: np.ndarray | None) -> None:
        """Enter a learned movement's takes, mean path and spread, without making the graph again."""
        if not takes:
            raise ValueError("nothing to learn: no take")
        visible = list(visible) if visible is not None else [None] * len(takes)
        interiors = [self._interior(t, v) for t, v in zip(takes, visible)][: self.params["takes"]]
        entry = {"source": source, "takes": interiors}
        entry["mean"], entry["spread"] = mean_path(interiors, mean)
        self.learned[name] = entry

    def add_take(self, name: str, poses: np.ndarray, visible: np.ndarray | None = None, *, announce: bool = True
                 ) -> bool:
        """One more demonstration of the learned movement ``name`` (poses as :meth:`learn` takes them): it becomes a
        take and the movement's path the mean of its takes. False (nothing changes) when the movement already has
        ``takes`` takes, or this one shows nothing between the hubs."""
        entry = self.learned.get(name)
        if entry is None:
            raise ConfigError(f"no learned movement {name!r}", expected="a movement learned by watching",
                              available=sorted(self.learned))
        if len(entry["takes"]) >= self.params["takes"]:
            return False
        try:
            entry["takes"].append(self._interior(poses, visible))
        except ValueError:
            return False
        self._settle(name)
        if announce and self.owner is not None:
            self.owner.announce("likeme_movement_learned", character=self.owner, movement=name,
                                details=self._learned_details(name))
        return True

    def _interior(self, poses: np.ndarray, visible: np.ndarray | None) -> np.ndarray:
        """A demonstration's poses between its hub ends, root-relative, each hidden part filled from the nearest
        node over the visible ones (K, P, 3)."""
        poses = np.asarray(poses, dtype=float)
        if visible is None:
            visible = np.isfinite(poses).all(axis=-1)
        visible = np.asarray(visible, dtype=bool) & np.isfinite(poses).all(axis=-1)
        interior = []
        for pose, vis in zip(poses[1:-1], visible[1:-1]):
            if not vis.any():
                continue
            if not vis.all():
                nearest = int(np.nanargmin(pose_distance(self.node_root_relative, np.nan_to_num(pose), vis)))
                pose = np.where(vis[:, None], pose, self.node_root_relative[nearest])
            interior.append(pose)
        if not interior:
            raise ValueError("nothing to learn: no visible pose between the hubs")
        return np.stack(interior)

    def _settle(self, name: str, mean: np.ndarray | None = None) -> None:
        """The learned movement's mean path (made from its takes unless given) and spread, and the graph made again
        with them."""
        entry = self.learned[name]
        entry["mean"], entry["spread"] = mean_path(entry["takes"], mean)
        self._build()

    def _add_learned(self, learned: dict[str, dict[str, Any]], rows: _NodeRows) -> None:
        """Each learned movement's paths: its mean path (named as the movement), and with several takes each take
        (``NAME/take-K``), all labelled with the movement; from the hub and back, travelling nowhere, each node's
        parts' motion from the path's own poses, its turn not known. The motions are differentiated together,
        one call for the paths of each length (a saved state of thousands of movements loads in linear time)."""
        lift = self.rest_pose()[self.body.root_index]
        hub = self.hubs[0]
        root = self.body.root_index
        paths = []
        for name, entry in learned.items():
            if len(entry["takes"]) > 1:
                paths.extend((f"{name}/take-{k}", take, name) for k, take in enumerate(entry["takes"], 1))
            paths.append((name, entry["mean"], name))
        motions = _derivatives([poses - poses[:, root : root + 1] for _, poses, _ in paths], self.params["node_rate"])
        for (path, poses, label), motion in zip(paths, motions):
            self._add_path(path, hub, poses + lift, hub, rows, np.zeros((len(poses), 3)), motion,
                           np.full(len(poses), np.nan), label=label)

    def _learned_details(self, name: str) -> dict[str, Any]:
        entry = self.learned[name]
        return {"nodes": len(entry["mean"]), "source": entry["source"], "takes": len(entry["takes"]),
                "spread": round(float(entry["spread"]), 6)}

    def get_state(self) -> dict[str, Any]:
        """The learned movements: for each, where it came from and its takes (interior node poses, root-relative
        and lifted to the rest root as the graph holds them); the mean path and spread follow from the takes."""
        lift = self.rest_pose()[self.body.root_index]
        return {
            "learned": {
                name: {
                    "source": entry["source"],
                    "poses": (entry["mean"] + lift).round(6).tolist(),
                    "takes": [(take + lift).round(6).tolist() for take in entry["takes"]],
                }
                for name, entry in self.learned.items()
            }
        }

    def set_state(self, state: dict[str, Any], *, check: bool = False) -> None:
        """Learn the saved movements (new names only) from their takes (a state of one path only: that path, one
        take); every entry is checked before the first is learned."""
        if not isinstance(state, dict):
            raise ConfigError("invalid posegraph state", expected="a table {learned = ...}")
        for key in state:
            if key != "learned":
                raise ConfigError(f"unknown key {key!r}", key=(key,), expected="a posegraph state key", available=["learned"])
        learned = state.get("learned", {})
        if not isinstance(learned, dict):
            raise ConfigError("invalid learned movements", key=("learned",),
                              expected="a table of learned movements by name")
        known = set(self.paths) | set(self.movements())
        plans = []
        for name, entry in learned.items():
            key = ("learned", name)
            if not name or name in known:
                raise ConfigError(f"movement {name!r} already exists" if name else "empty movement name", key=key,
                                  expected="a movement the character does not know yet", available=sorted(known))
            if not isinstance(entry, dict) or not isinstance(entry.get("source", ""), str):
                raise ConfigError(f"invalid learned movement {name!r}", key=key,
                                  expected="{source = text, poses = ..., takes = [...]}")
            for k in entry:
                if k not in ("source", "poses", "takes"):
                    raise ConfigError(f"unknown key {k!r}", key=(*key, k), expected="a learned movement's key",
                                      available=["source", "poses", "takes"])
            poses = self._state_poses(entry.get("poses"), (*key, "poses"), name)
            takes = entry.get("takes")
            if takes is None:
                takes = [poses]
            elif not isinstance(takes, list) or not takes:
                raise ConfigError(f"invalid takes of learned movement {name!r}", key=(*key, "takes"),
                                  expected="a list of takes, each an array of poses")
            else:
                takes = [self._state_poses(t, (*key, "takes", i), name) for i, t in enumerate(takes)]
            plans.append((name, poses, takes, entry.get("source", "")))
        if check:
            return
        root = self.body.root_index
        hub = self.rest_pose() - self.rest_pose()[root]
        lift = self.rest_pose()[root]  # held lifted to the rest root, as the graph holds them
        for name, mean, takes, source in plans:  # every movement entered, then the graph made once: linear in size
            self._enter(name, [np.concatenate([[hub], t - lift, [hub]]) for t in takes], None, source, mean - lift)
        self._build()

    def _state_poses(self, value: Any, key: tuple, name: str) -> np.ndarray:
        shape = f"an array of shape (nodes >= 1, {self.body.n_parts}, 3) of finite numbers (metres, below 1e6)"
        try:
            poses = np.asarray(value, dtype=float)
        except (TypeError, ValueError, OverflowError):
            poses = np.zeros(0)
        if (poses.ndim != 3 or poses.shape[1:] != (self.body.n_parts, 3) or not len(poses)
                or not np.isfinite(poses).all() or np.abs(poses).max() >= 1e6):
            raise ConfigError(f"invalid poses of learned movement {name!r}", key=key, expected=shape)
        return poses

    def describe(self) -> dict[str, Any]:
        return {
            "movements": len(self.movements()),
            "clips": len(self.clips.clips) if self.clips is not None else 0,
            "nodes": self.graph.number_of_nodes(),
            "edges": self.graph.number_of_edges(),
            "hubs": list(self.hubs),
            "learned": sorted(self.learned),
            "takes": {name: len(entry["takes"]) for name, entry in self.learned.items()},
        }


class _NodeRows:
    """The posegraph's per-node arrays while it is built: poses, travel, motion, heading and the jitter (the mean over
    the parts of the squared noise of their positions and velocities, two numbers a node,
    :func:`plugins.lib.jitter.feature_noise`; 0 where none is known), a block per path."""

    def __init__(self) -> None:
        self.blocks: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        self.count = 0

    def add(self, poses: np.ndarray, travel: np.ndarray, motion: np.ndarray, heading: np.ndarray,
            noise: np.ndarray | None = None) -> None:
        """A path's rows; ``noise`` (P, 2): its parts' squared jitter, kept as their mean over the parts."""
        poses = np.asarray(poses, dtype=float)
        mean = np.zeros(2) if noise is None else np.asarray(noise, dtype=float).mean(axis=0)
        self.blocks.append((poses, np.asarray(travel, dtype=float), np.asarray(motion, dtype=float),
                            np.asarray(heading, dtype=float), np.broadcast_to(mean, (len(poses), 2))))
        self.count += len(poses)

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        return tuple(np.concatenate(column) for column in zip(*self.blocks))  # type: ignore[return-value]


@functools.cache
def _dtw_c() -> bool:
    """Whether dtaidistance's C library is there (its wheels have it): the same warping paths, a hundred times
    faster than its Python loops."""
    try:
        from dtaidistance import dtw_cc  # noqa: F401
    except ImportError:
        return False
    return True



def _derivatives(sequences: list[np.ndarray], fps: float) -> list[np.ndarray]:
    """:func:`~plugins.lib.velocity.derivative` of each sequence (n_i, ...), those of one length in one call."""
    by_length: dict[tuple, list[int]] = {}
    for i, values in enumerate(sequences):
        by_length.setdefault(values.shape, []).append(i)
    out: list[np.ndarray] = [np.empty(0)] * len(sequences)
    with one_thread():  # as in Posegraph._played
        for indices in by_length.values():
            together = derivative(np.stack([sequences[i] for i in indices], axis=1), fps)
            for j, i in enumerate(indices):
                out[i] = together[:, j]
    return out


def mean_path(takes: list[np.ndarray], mean: np.ndarray | None = None) -> tuple[np.ndarray, float]:
    """The mean of several takes of one movement (each (K_i, P, 3)), and their spread (m).

    The mean is the DTW barycentre of the takes (:func:`dtaidistance.dtw_barycenter.dba_loop`, every pose flattened
    to one vector), started from the take with the least summed DTW distance to the others (the medoid), so it has
    that take's length; or ``mean`` when given. The spread is the mean, over the takes, of the mean eq. 1 distance
    between each take's poses and the mean poses they are aligned with. One take is its own mean, of spread 0.
    """
    from dtaidistance import dtw_barycenter, dtw_ndim

    takes = [np.asarray(t, dtype=float) for t in takes]
    if len(takes) == 1 and mean is None:
        return takes[0].copy(), 0.0
    shape = takes[0].shape[1:]
    flat = [np.ascontiguousarray(t.reshape(len(t), -1)) for t in takes]
    if mean is None:
        total = [sum(dtw_ndim.distance(a, b) for b in flat) for a in flat]
        start = flat[int(np.argmin(total))]
        mean = np.asarray(dtw_barycenter.dba_loop(flat, c=start.copy(), max_it=10, use_c=False), dtype=float)
    else:
        mean = np.ascontiguousarray(np.asarray(mean, dtype=float).reshape(len(mean), -1))
    spreads = []
    for t in flat:
        if t.shape == mean.shape and np.array_equal(t, mean):  # a take that is the mean (a state's single take)
            spreads.append(0.0)
            continue
        pairs = np.array(dtw_ndim.warping_path(t, mean, use_c=_dtw_c()))
        spreads.append(float(np.mean(pose_distance(t[pairs[:, 0]].reshape(-1, *shape), mean[pairs[:, 1]].reshape(-1, *shape)))))
    return mean.reshape(-1, *shape), float(np.mean(spreads))


@hookimpl
def likeme_movement_recognised(world: Any, observer: Any, target: Any, segment: Any, match: Any) -> None:
    """A later demonstration of a movement the observer's posegraph learned by watching is one more take of it
    (§7.3, :meth:`Posegraph.add_take`): the segment's root-relative poses from working memory, sampled at the
    node rate. The demonstration that taught the movement (``details["learned"]``) is its first take already."""
    motor = getattr(getattr(observer, "character", None), "motor", None)
    if (not isinstance(motor, Posegraph) or segment is None or not match.known or match.movement not in motor.learned
            or match.details.get("learned") or observer.memory is None):
        return
    memory = observer.memory
    start, stop = max(segment.start, memory.offset), min(segment.end, memory.n)
    if stop - start < 3:
        return
    motion = memory.motion(start, stop)
    t = np.arange(motion.n_frames) / motion.fps
    keep = np.unique(np.clip(np.round(np.arange(0.0, t[-1] + 1e-9, 1.0 / motor.node_rate) * motion.fps), 0,
                             motion.n_frames - 1).astype(int))
    if len(keep) >= 3:
        motor.add_take(match.movement, motion.positions[keep], motion.visible[keep])


@hookimpl
def likeme_register_motor_systems():
    return [Posegraph]
