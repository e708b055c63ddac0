"""Commitment, deviation and prediction again from the last correct node (Kopp & Graeser 2006, §4.4, Fig. 3).

When exactly one movement prevails (and enough of its path has been seen), the subsystem commits to it and it is
executed at once, well before the demonstration ends: *response facilitation*. While imitating, the observation keeps
being compared with the committed path; if they part by more than ``deviation`` the imitation is stopped, the edge
the demonstration was on is excluded for this segment, and the subsystem returns to the last correct node, the start
of that edge (the edges before it were right; §4.4: "the imitator returns into the last node at which accordance
with the demonstrated movement was found"). Fig. 3's loop goes on from there: the edges leaving that node, the
excluded ones left out, predict what has been seen since the demonstration passed it (:meth:`Commitment.repredict`).
One that prevails explains the rest (it is checked, and may deviate in turn); only what no edge explains is learned,
from the last correct node (:mod:`~plugins.matchers.forward_model.learning`). At the end of the demonstration a
commitment must end where the demonstration did (:meth:`Commitment.settle`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from plugins.matchers.forward_model.path_length import lengths as path_lengths
from plugins.matchers.forward_model.prediction import Predictions
from plugins.matchers.forward_model.tracks import Track
from toolkit import Match

if TYPE_CHECKING:
    from plugins.matchers.forward_model.matcher import ForwardModel

__all__ = ["Commitment"]

Path = tuple[str, ...]


class Commitment:
    """A followed subsystem's commitment to a path of commands, its check and what follows a deviation."""

    def __init__(self, model: ForwardModel) -> None:
        self.model = model

    def commit(self, track: Track, path: Path, along: np.ndarray, progress: float, n_observed: int,
               error: float) -> None:
        """Commit a subsystem to candidate ``path`` (the whole learned sequence it begins), at the speed seen."""
        m = self.model
        track.committed_path = m.motor.known_sequence(path)
        track.committed = m.motor.add_sequence(list(track.committed_path))
        track.committed_at = m.observation.memory.n
        track.speed = m.clock.speed(track, path, n_observed)
        track.progress = progress
        track.confidence = float(np.exp(-error / m.params["threshold"]))

    def deviate(self, track: Track, lengths: np.ndarray, memory: np.ndarray) -> Match | None:
        """The demonstration deviates from the committed path (Fig. 3): the edge it was on is excluded from this
        segment's predictions, the imitation is stopped (the first time; the subsystem returns to the last correct
        node), and the rest is predicted again from the last correct node (:meth:`repredict`).

        Returns a :class:`Match` with ``stop`` when an imitation under way was stopped.
        """
        track.deviated = True
        if track.deviated_at is None:
            track.deviated_at = len(memory)
        self.last_correct(track, lengths, memory)
        track.failed.append((track.committed, track.committed_path))
        stop = None
        if track.reported and not track.stopped:
            # stop the imitation; the others' commands were right and are completed by the motor system
            track.stopped, track.home, track.at = True, track.last_correct, len(track.right)
            self.model.motor.move_to(track.subsystem, track.last_correct)
            stop = Match(track.committed, 0.0, len(memory), stop=True, reason="deviation", details={
                "stop": True, "reason": "deviation", "subsystem": track.subsystem, "return_to": track.last_correct})
        self.repredict(track, memory)
        return stop

    def last_correct(self, track: Track, lengths: np.ndarray, memory: np.ndarray) -> None:
        """The node at which the demonstration last agreed with the committed path: the start of the edge it was on.

        That edge is excluded from the segment's predictions (Fig. 3); the edges before it were followed correctly
        and join ``right``. Predicting again, and learning, start from the frame the demonstration passed the node
        (:meth:`Clock.passed <plugins.matchers.forward_model.speed.Clock.passed>`).
        """
        m = self.model
        path = track.committed_path
        lead = m.tables.lead(path[0])
        observed = m.observation.observed(track, memory)
        clock = m.clock.along(track, path, lengths, len(observed))
        ends = np.cumsum([m.tables.edge(e).arcs[lead, -1] for e in path])
        joined = m.anchors.anchor(track, path[0])[lead]
        on = int(np.searchsorted(ends, clock[lead] + joined - 0.01 / track.scale))
        on = min(on, len(path) - 1)
        track.last_correct = m.motor.edge(path[on]).source
        track.excluded.add(path[on])
        if not on:
            return
        track.right = (*track.right, *path[:on])  # the part that was right
        row = m.clock.passed(track, path, on, observed, ends, joined)
        track.learn_from = track.onset + min(max(row, 0), len(observed) - 1)

    def repredict(self, track: Track, memory: np.ndarray) -> None:
        """Fig. 3's loop: "edges <- motor commands that can predict the observed movement", again, from the last
        correct node. A new :class:`~plugins.matchers.forward_model.tracks.Track` follows the subsystem from the row
        at which the demonstration passed that node, with the edges leaving it as candidates but those excluded; it
        keeps what the segment has established (the edges that were right, the excluded ones, whether the imitation
        was stopped, the trace). The rows seen since are followed again one by one, so a candidate drops out, or
        prevails and is committed to (and checked, and may deviate in turn), as if it had been followed from there.
        What no edge explains is learned at the end, and only that.
        """
        m = self.model
        node, name = track.last_correct, track.subsystem
        candidates = {(edge.name,): 0.0 for edge in m.motor.edges_from(name, node)
                      if edge.name not in track.excluded and m.tables.length(edge.name) * track.scale >
                      m.params["min_move"]}
        again = Track(name, track.scale, track.hand, node, track.learn_from, candidates, track.initial,
                      excluded=track.excluded, reported=track.reported, deviated=True, last_correct=node,
                      right=track.right, learn_from=track.learn_from, trace=track.trace,
                      committed_at=track.committed_at, deviated_at=track.deviated_at, stopped=track.stopped,
                      home=track.home or track.start_node, at=track.at, failed=track.failed,
                      begun=track.begun or track,
                      origin=track.onset if track.origin is None else track.origin)
        m.tracks[name] = again
        now = m.observation.memory.n
        for row in range(again.onset + 1, len(memory)):  # what has been seen since the node, frame by frame
            current, seen = m.tracks[name], len(track.trace)
            m.tracking.follow(current, memory[: row + 1])
            for k in range(seen, len(track.trace)):  # the frame each replayed prediction belongs to
                frame, errors = track.trace[k]
                if frame == now - 1:
                    track.trace[k] = (row, errors)
            current = m.tracks[name]
            if current.committed is not None and current.committed_at == now:
                current.committed_at = row + 1

    def settle(self, track: Track, memory: np.ndarray) -> Track:
        """At the end of the demonstration: a subsystem's commitment must end where the demonstration did; while
        it does not, it deviated (:meth:`deviate`: the last correct node, the edge excluded, the rest predicted
        again). Returns the subsystem's track as it is then."""
        m = self.model
        while track.committed is not None and not self.ended(track, memory):
            self.deviate(track, path_lengths(m.observation.observed(track, memory)), memory)
            track = m.tracks[track.subsystem]
        return track

    def ended(self, track: Track, memory: np.ndarray) -> bool:
        """Whether the demonstration ended (the last row of ``memory``) where the committed path does."""
        motor = self.model.motor
        end = motor.edge(track.committed_path[-1]).target
        expected = motor.state(track.subsystem, end)
        seen = memory[-1, motor.subsystems[track.subsystem]]
        return Predictions.distance(track, expected, seen) <= self.model.params["deviation"]
