"""The subsystems followed during a demonstration: their candidates and the drop-out (K&G §4.1, §4.2, §4.4, Fig. 3).

"The motor subsystems that are moving are under consideration" (§4.1): every subsystem whose parts move more than
``min_move`` during the demonstration is followed by a :class:`Track` with its own candidates, the edges leaving its
active node (§4.2: "multiple graphs at once in order to account for the possibly concurrent execution of submovements
in different motor subsystems within a complex hand-arm-motion"). One that starts later is followed from when it
started. Which subsystems are followed is a strategy chosen once by ``together``: every one that moves
(:class:`EveryMoving`), or only the first to move (:class:`FirstToMove`).

Each frame (:meth:`Tracking.follow`) the candidates predict the demonstration in parallel; a candidate whose
prediction error exceeds ``threshold`` drops out; when every candidate left stands for one movement, and enough of it
has been seen, the subsystem commits to it (:mod:`~plugins.matchers.forward_model.commitment`); while committed, the
committed path is checked against the demonstration.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from plugins.matchers.forward_model.path_length import norms
from toolkit import Match

if TYPE_CHECKING:
    from plugins.matchers.forward_model.matcher import ForwardModel

__all__ = ["EveryMoving", "FirstToMove", "Following", "Track", "Tracking"]

Path = tuple[str, ...]


@dataclass
class Track:
    """One motor subsystem under consideration during a demonstration (K&G §4.1): its candidates, commitment, errors.

    ``onset`` is the row of the segment's working memory from which the subsystem is followed (0 for the first
    subsystem to move; a subsystem that starts later is followed from when it started). After a deviation,
    ``last_correct`` is the node where the demonstration last agreed with the committed path, ``right`` the
    edges before it that were followed correctly, ``excluded`` the edges that failed, and ``learn_from`` the row
    from which the rest is predicted again (Fig. 3's loop: the subsystem is then followed by a new track from
    ``last_correct``, ``onset`` = ``learn_from``) and, if no edge explains it, learned. ``trace`` holds, per
    frame, the prediction error of every candidate path evaluated (dropped ones at the frame they drop); while
    imitating, the committed path's error. ``committed_at`` and ``deviated_at`` count the segment's frames seen.
    """

    subsystem: str
    scale: float
    hand: bool
    start_node: str
    onset: int
    candidates: dict[Path, float]
    initial: list[str]
    excluded: set[str] = field(default_factory=set)
    committed: str | None = None
    committed_path: Path = ()
    confidence: float = 0.0
    speed: float = 1.0
    progress: float = 0.0
    reported: bool = False
    deviated: bool = False
    last_correct: str | None = None
    right: Path = ()
    learn_from: int = 0
    trace: list[tuple[int, dict[Path, float]]] = field(default_factory=list)
    committed_at: int | None = None
    deviated_at: int | None = None
    anchors: dict[str, np.ndarray] = field(default_factory=dict)
    first: np.ndarray | None = None
    """The subsystem's parts as seen at the onset (k, 3); ``None``: read from working memory."""
    stopped: bool = False
    """The imitation of a commitment was stopped at a deviation (once a segment; the body went back to ``home``)."""
    home: str | None = None
    """The node the subsystem's body is in, or goes back to, while it is followed: the start node (``None``), or
    the last correct node it returned to when its imitation was stopped."""
    at: int = 0
    """How many of the edges of ``right`` the body has performed (those up to ``home``)."""
    failed: list[tuple[str, Path]] = field(default_factory=list)
    """The commitments (movement, path) that deviated in this segment, in order."""
    origin: int | None = None
    """After a deviation, predicted again from the last correct node (Fig. 3): the row from which the subsystem was
    followed first (``onset`` is then the row it passed the last correct node)."""
    begun: Track | None = None
    """After a deviation, predicted again: the segment's first track of the subsystem (what
    :meth:`ForwardModel.inspect <plugins.matchers.forward_model.matcher.ForwardModel.inspect>` shows of the
    segment's start)."""
    placed: tuple[dict[str, int], np.ndarray] | None = None
    """The anchors placed at once when the track began (:meth:`Anchors.anchor
    <plugins.matchers.forward_model.anchors.Anchors.anchor>`): each command's row in them and the array (C, k) whose
    rows are those of ``anchors``."""


class Following(ABC):
    """Which subsystems are followed (the strategy chosen by ``together``)."""

    @abstractmethod
    def waiting(self, tracks: Mapping[str, Track], subsystems: Mapping[str, Any]) -> list[str]:
        """The subsystems that may still begin to be followed, ``tracks`` being followed."""

    @abstractmethod
    def chosen(self, moved: list[str]) -> list[str]:
        """Of the subsystems that have moved (farthest first), those to follow now."""


class EveryMoving(Following):
    """Every subsystem that moves, each with its own candidates, imitated together (a hand-arm movement, §4.2)."""

    def waiting(self, tracks, subsystems):
        return [name for name in subsystems if name not in tracks]

    def chosen(self, moved):
        return moved


class FirstToMove(Following):
    """Only the subsystem that moves first (farthest, when several begin on the same frame)."""

    def waiting(self, tracks, subsystems):
        return [] if tracks else list(subsystems)

    def chosen(self, moved):
        return moved[:1]


class Tracking:
    """The forward model's subsystems under consideration: when each begins to be followed, from which node, and
    each frame's predictions, drop-out and commitment."""

    following: Following
    """Which subsystems are followed (chosen by the matcher from ``together``)."""

    def __init__(self, model: ForwardModel) -> None:
        self.model = model
        self._scales: dict[str, tuple[Any, float]] = {}

    def scale_of(self, subsystem: str) -> float:
        """Metres one unit of the subsystem's values counts as: ``angle_scale`` for a hand's radians, else 1 (kept
        per subsystem while its parts are the same)."""
        motor = self.model.motor
        parts = motor.subsystems.get(subsystem)
        kept = self._scales.get(subsystem)
        if kept is None or kept[0] is not parts:
            kept = self._scales[subsystem] = (parts, self.model.params["angle_scale"] if motor.is_hand(subsystem)
                                              else 1.0)
        return kept[1]

    def waiting(self) -> list[str]:
        """The subsystems that may still begin to be followed in this segment."""
        return self.following.waiting(self.model.tracks, self.model.motor.subsystems)

    def start(self, memory: np.ndarray) -> None:
        """Follow every subsystem not yet followed that has moved more than ``min_move`` since the onset (as
        :attr:`following` chooses).

        The first follows from the onset; one that starts later (three-frame means, against observation noise)
        from the last frame it was still within a quarter of ``min_move`` of where it was at the onset.
        """
        m = self.model
        waiting = self.waiting()
        if not waiting:  # every subsystem is followed
            return
        late = bool(m.tracks)
        if late:
            first = memory[:3].mean(axis=0)
            moved = self.moved(waiting, first, memory[-3:].mean(axis=0))
        else:
            moved = self.moved(waiting, memory[0], memory[-1])
        min_move = m.params["min_move"]
        moved = {name: d for name, d in moved.items() if d > min_move}
        for name in self.following.chosen(sorted(moved, key=moved.get, reverse=True)):
            onset = 0
            if late:
                idx = m.motor.subsystems[name]
                away = np.linalg.norm(memory[:, idx] - first[idx], axis=-1).max(axis=1) * self.scale_of(name)
                still = np.flatnonzero(away <= 0.25 * min_move)
                onset = int(still[-1]) if len(still) else 0
            self.track(name, onset)

    def moved(self, names: list[str], first: np.ndarray, last: np.ndarray) -> dict[str, float]:
        """How far (m; a hand's radians scaled) each subsystem's parts have moved at most from ``first`` to ``last``."""
        far = norms(last - first)  # every part at once (the same values as part by part)
        return {name: float(np.fmax.reduce(far[idx])) * self.scale_of(name)  # np.nanmax without its warning
                for name, idx in self.model.motor.subsystems.items() if name in names}

    def joining(self, memory: np.ndarray) -> bool:
        """Whether a subsystem not yet followed has begun to move (half of ``min_move``): the decision waits for it."""
        waiting = self.waiting()
        if not waiting:
            return False
        moved = self.moved(waiting, memory[:3].mean(axis=0), memory[-3:].mean(axis=0))
        return any(d > 0.5 * self.model.params["min_move"] for d in moved.values())

    def track(self, name: str, onset: int) -> None:
        """Follow subsystem ``name`` from row ``onset``: its candidates are the edges leaving the node it begins in
        (:meth:`where`)."""
        m = self.model
        scale = self.scale_of(name)
        start = self.where(name, m.observation.at(onset)[m.motor.subsystems[name]])
        # a command that moves no part farther than min_move (standing still) cannot be seen to begin
        candidates = {(edge.name,): 0.0 for edge in m.motor.edges_from(name, start)
                      if m.tables.length(edge.name) * scale > m.params["min_move"]}
        m.tracks[name] = Track(name, scale, m.motor.is_hand(name), start, onset, candidates,
                               sorted(p[0] for p in candidates), last_correct=start, learn_from=onset)

    def where(self, name: str, seen: np.ndarray) -> str:
        """The node a subsystem's demonstration begins in: the active node or the hub, whichever state is nearer
        to where the parts were seen at the onset (``seen``, (k, 3)).

        The active node is where the last movement the matcher followed ended; a demonstrator who went back to
        the hub without being followed (a movement that was not recognised, a posture that differed from the
        observer's own at its end) begins his next movement there.
        """
        motor = self.model.motor
        active = motor.active_node(name)
        if active == "hub" or not np.isfinite(seen).any():
            return active
        far = [self.distance_to(name, motor.state(name, n), seen) for n in (active, "hub")]
        return active if far[0] <= far[1] else "hub"

    def distance_to(self, name: str, state: np.ndarray, seen: np.ndarray) -> float:
        """How far the parts seen (k, 3) are from a state of subsystem ``name``: the largest part's distance (parts
        never seen left out)."""
        return float(np.nanmax(np.linalg.norm(state - seen, axis=-1) * self.scale_of(name)))

    def follow(self, track: Track, memory: np.ndarray) -> Match | None:
        """One frame of a subsystem's predictions (Fig. 3); a :class:`Match` with ``stop`` when its imitation deviates.

        ``memory``: the working memory in the motor frame up to this frame. A committed subsystem's path is checked
        (a deviation: :meth:`Commitment.deviate <plugins.matchers.forward_model.commitment.Commitment.deviate>`);
        else every candidate path predicts the frame, those off by more than ``threshold`` drop out (the best
        ``max_candidates`` are kept), and when the rest stand for one movement of which ``min_progress`` has been
        seen, the subsystem commits to the best."""
        if track.committed is None and not track.candidates:  # nothing left to predict (as below, without the work)
            return None
        m = self.model
        params, clock = m.params, m.clock
        observed = m.observation.observed(track, memory)
        lengths = m.observation.walked(track, observed)  # once per frame (incremental)
        last = observed[-1]
        frame = m.observation.memory.n - 1
        if track.committed is not None:
            path = track.committed_path
            error = m.predictions.error(track, path, clock.along(track, path, lengths, len(observed)), last)
            track.trace.append((frame, {path: error}))
            if error <= params["deviation"]:
                return None
            return m.commitment.deviate(track, lengths, memory)  # Fig. 3: stop, exclude the edge, predict again
        if not track.candidates:
            return None
        n = len(observed)
        paths = clock.extended(track, lengths, n)
        errors = clock.errors(track, paths, lengths, n, last)
        track.trace.append((frame, errors))
        alive = self.survivors(errors)
        if len(alive) > params["max_candidates"]:  # keep the best predictions
            alive = dict(sorted(alive.items(), key=lambda kv: kv[1])[: params["max_candidates"]])
        track.candidates = alive
        if alive and len({m.ranking.movement_key(p) for p in alive}) == 1:  # one first command (or movement) prevails
            path = min(alive, key=alive.get)
            along = m.anchors.along(track, path[0], clock.along(track, path, lengths, n))
            progress = m.tables.progress(path[0], along)
            if (progress >= params["min_progress"] or len(path) > 1) and clock.timed(track, observed):
                m.commitment.commit(track, path, along, progress, len(observed), alive[path])
        return None

    def survivors(self, errors: Mapping[Path, float]) -> dict[Path, float]:
        """The candidates (paths and their prediction errors this frame) that do not drop out: those whose
        prediction error is within ``threshold``."""
        threshold = self.model.params["threshold"]
        return {path: error for path, error in errors.items() if error <= threshold}
