"""The ``forward-model`` matcher: the component, its parameters and the watching loop's calls (K&G 2006, §4.4, Fig. 3).

It follows a segment frame by frame (``streaming``): the subsystems that move are followed
(:mod:`~plugins.matchers.forward_model.tracks`), their candidate edges predict the demonstration
(:mod:`~plugins.matchers.forward_model.prediction`), one that prevails is committed to and imitated at once, and a
deviation sends the subsystem back to its last correct node (:mod:`~plugins.matchers.forward_model.commitment`); at
the end what no edge predicts is learned (:mod:`~plugins.matchers.forward_model.learning`). The variants are chosen
once, from the parameters: the clock (``reparameterise``, :mod:`~plugins.matchers.forward_model.speed`), which
subsystems are followed (``together``) and whether to learn (``learn``). ``docs/forward-model.md`` says how it works.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

import numpy as np

from plugins.lib.strokes import STROKE_PARAMETERS, StrokeCriteria
from plugins.matchers.forward_model.anchors import Anchors
from plugins.matchers.forward_model.answer import FollowedAndStrokes
from plugins.matchers.forward_model.command_graphs import CommandGraphs
from plugins.matchers.decision import Calibrated
from plugins.matchers.forward_model.commitment import Commitment
from plugins.matchers.forward_model.following import Following, Streaming, Takes
from plugins.matchers.forward_model.learning import InverseModel, TakeLearning
from plugins.matchers.forward_model.observation import Observation
from plugins.matchers.forward_model.path_length import norms
from plugins.matchers.forward_model.prediction import Predictions
from plugins.matchers.forward_model.ranking import Ranking
from plugins.matchers.forward_model.speed import Elapsed, PathLength
from plugins.matchers.forward_model.tables import Tables
from plugins.matchers.forward_model.tracks import EveryMoving, FirstToMove, Track, Tracking
from toolkit import Match, Matcher, Motion, Parameter
from toolkit.components import provides
from toolkit.watching import WorkingMemory, follow

__all__ = ["ForwardModel"]


class ForwardModel(Matcher):
    """Edges of the active node predict the demonstration in parallel; the last one left is imitated at once (K&G §4.4)."""

    name = "forward-model"
    motor_systems = ("motor-command-graph",)
    parameters = (
        Parameter("comparison", str, "strokes", "What the forward models compare: 'strokes', each subsystem's "
                  "guiding strokes at the path length seen, the largest part's error in metres, dropped beyond "
                  "threshold (the paper); 'motion', every take learned from clips played by its commands and "
                  "followed by time warping with the comparison and the calibrated decision the matchers share "
                  "(plugins.matchers.forward_model.following; real people); 'motion+strokes', the same, and the "
                  "answer at the end mixes in the takes' strokes over the whole demonstration, weighed by how well "
                  "the takes show they separate the movements (plugins.matchers.forward_model.answer).",
                  choices=("strokes", "motion", "motion+strokes")),
        Parameter("calibrated", doc="The calibration of comparison = 'motion' (plugins.matchers.decision).",
                  parameters=(
                      Parameter("known_rejected", float, 0.05, "The share of a known movement's performances that "
                                "may be called unknown, as far as the repertoire shows how they vary.",
                                minimum=0.0, maximum=1.0),
                  )),
        Parameter("threshold", float, 0.05, "Prediction error (m) above which a candidate edge drops out.",
                  minimum=0.0, length=True),
        Parameter("deviation", float, 0.05, "Error (m) between the imitated edge and the demonstration that stops the "
                  "imitation (also checked at the end: the demonstration must end where the edge does).",
                  minimum=0.0, length=True),
        Parameter("min_progress", float, 0.2, "Share of the edge's path that must be seen before committing.",
                  minimum=0.0, maximum=1.0),
        Parameter("min_move", float, 0.02, "Displacement (m) of a subsystem that makes it one under consideration.",
                  minimum=0.0, length=True),
        Parameter("angle_scale", float, 0.25, "Metres one radian of finger joint angle counts as when a hand "
                  "subsystem's errors and movement are compared with threshold, deviation and min_move "
                  "(0.25: the 0.05 m threshold is 0.2 rad, 11 degrees).", minimum=1e-6, length=True),
        Parameter("max_candidates", int, 24, "Most candidate command paths followed at once (the best predictions).",
                  minimum=1),
        Parameter("together", bool, True, "Follow every subsystem that moves during a demonstration, each with its "
                  "own candidates, and imitate them at once (a hand-arm movement, §4.2); off: only the first to move."),
        Parameter("learn", bool, True, "Learn new edges by the inverse model when no edge predicts the demonstration "
                  "(comparison = 'motion': the demonstration as the take of a new movement, learned-1, learned-2...)."),
        Parameter("reparameterise", bool, True, "Speed re-parameterisation (K&G §4.4): an edge predicts the "
                  "demonstration at the time its command covers the path length seen, so a familiar movement "
                  "performed faster or slower still fits, and is imitated at the speed measured. Off (the paper's "
                  "baseline): an edge predicts at the time elapsed, at the speed it was learned, so a familiar "
                  "movement at another speed is learned as new."),
        Parameter("strokes", doc="How a movement learned by watching is cut into strokes, one edge each (K&G §4.3; "
                  "plugins.lib.strokes).", parameters=STROKE_PARAMETERS),
    )

    streaming = True
    report_details = ("candidates", "learned", "speed", "deviated")

    def attach(self, owner: Any) -> None:
        super().attach(owner)
        motor = owner.motor
        provides(motor, CommandGraphs, needed_by="forward-model", what="a motor command graph",
                 expected=" or ".join(f'[motor] plugin = "{name}"' for name in self.motor_systems))
        self.motor = motor
        if self.params["comparison"] != "strokes":  # the real people's forward model, chosen once: it answers the
            # watching loop's calls in place of the paper's mechanism below (K&G §4.4 with the shared comparison)
            provides(motor, Takes, needed_by=f"forward-model's comparison = '{self.params['comparison']}'",
                     what="a motor command graph that knows the takes it learned from clips", key=("comparison",),
                     expected="a motor system with takes(), play_take(), take_motions(), subsystems and body "
                              "(motor-command-graph with clips)")
            known_rejected = self.params["calibrated"]["known_rejected"]
            answer = FollowedAndStrokes(owner.body, known_rejected) \
                if self.params["comparison"] == "motion+strokes" else None
            following = Following(motor, owner.body, Calibrated(known_rejected), self.params["min_progress"],
                                  TakeLearning(motor, owner.body) if self.params["learn"] else None, answer)
            stream = Streaming(following)
            for name in ("begin", "observe", "replay", "settled", "conclude", "inspect"):
                setattr(self, name, getattr(stream, name))
            self.match = following.match
            return
        # observed root-relative positions are placed at the observer's own root height; finger angles stay as they are
        self.observation = Observation(motor, np.where(owner.body.angle_mask[:, None], 0.0,
                                                       motor.rest_pose()[owner.body.root_index]))
        self.tables = Tables(motor)
        self.anchors = Anchors(self.tables, self.observation.first)
        self.predictions = Predictions(motor, self.tables, self.anchors, self.observation)
        self.ranking = Ranking(motor)
        self.tracking = Tracking(self)
        self.commitment = Commitment(self)
        self._choose()
        self.tracks: dict[str, Track] = {}
        self.reported = False
        every = getattr(motor, "edges", None)  # optional (not in CommandGraphs): every edge of a subsystem
        if callable(every):  # the repertoire's tables once, at composition; learned edges' when first met
            for subsystem in motor.subsystems:
                for edge in every(subsystem):
                    self.tables.edge(edge.name)

    def _choose(self) -> None:
        """The variants the parameters choose: the clock (``reparameterise``), which subsystems are followed
        (``together``) and the learning (``learn``). Chosen when attached, and again when a segment begins after
        the parameters were replaced."""
        params = self.params
        self.clock = PathLength(self) if params["reparameterise"] else Elapsed(self)
        self.tracking.following = EveryMoving() if params["together"] else FirstToMove()
        strokes = StrokeCriteria(drop=params["strokes"]["drop"], angle=params["strokes"]["angle"])
        self.learning = InverseModel(self, strokes) if params["learn"] else None
        self._chosen = params

    # -- streaming ------------------------------------------------------------------------------

    def begin(self, memory: WorkingMemory) -> None:
        if self._chosen is not self.params:
            self._choose()
        self.observation.begin(memory)
        self.fps = memory.fps
        self.tracks = {}  # in the order the subsystems began to move
        self.reported = False  # a commitment to the tracks decided so far has been announced
        self._settled = False  # nothing more can happen in this segment (:meth:`_quiet`)
        self._settled_at: tuple[int, int] | None = None  # (frames, revision) when it settled (:meth:`settled`)

    @property
    def main(self) -> Track | None:
        """The first subsystem to move, as the views and single-subsystem users see it."""
        return next(iter(self.tracks.values()), None)

    def inspect(self) -> Mapping[str, Any]:
        """The segment followed last: for its first subsystem to move (and, under ``tracks``, for each) the start
        node, the candidate paths still alive, the initial candidates, the commitment and when it came, whether and
        when it deviated, the per-frame prediction errors (``trace``) and the anchors; read-only snapshots."""
        def view(track: Track | None) -> dict[str, Any]:
            if track is None:
                return {"subsystem": None, "start_node": None, "candidates": {}, "initial": [], "committed": None,
                        "committed_path": (), "deviated": False, "trace": (), "committed_at": None,
                        "deviated_at": None, "anchors": {}}
            # after a deviation predicted again without a new commitment: the commitment that deviated
            committed, path = (track.committed, track.committed_path) if track.committed is not None or \
                not track.failed else track.failed[-1]
            begun = track.begun or track
            return {"subsystem": track.subsystem, "start_node": begun.start_node,
                    "candidates": dict(track.candidates), "initial": list(track.initial), "committed": committed,
                    "committed_path": tuple(path), "deviated": track.deviated,
                    "trace": tuple(track.trace), "committed_at": track.committed_at, "deviated_at": track.deviated_at,
                    "anchors": {k: v.copy() for k, v in {**begun.anchors, **track.anchors}.items()}}
        memory = self.observation.memory
        return MappingProxyType({**view(self.main), "frames": 0 if memory is None else memory.n,
                                 "threshold": self.params["threshold"], "deviation": self.params["deviation"],
                                 "measure": "prediction error of the guiding strokes", "unit": " m",
                                 "predicting": "the edges of the active node",
                                 "tracks": {name: view(track) for name, track in self.tracks.items()}})

    def observe(self, memory: WorkingMemory) -> Match | None:
        if memory is not self.observation.memory:
            self.begin(memory)
        elif self._settled:  # every subsystem followed, none with a candidate or a commitment: as below, no work
            return None
        local = self.observation.local()
        tracking = self.tracking
        tracking.start(local)
        if not self.tracks:
            return None
        stop = None
        for track in self.tracks.values():
            stop = tracking.follow(track, local) or stop
        if stop is not None:
            return stop
        tracks = list(self.tracks.values())
        if self._quiet(tracks):
            self._settled = True
            self._settled_at = (memory.n, memory.revision)
            return None
        if self.reported or not all(t.committed is not None and not t.deviated for t in tracks) or \
                tracking.joining(local):
            return None
        self.reported = True  # every subsystem under consideration has one prevailing command: imitate them at once
        for t in tracks:
            t.reported = True
        movement = self.motor.add_together([t.committed for t in tracks])
        labels = [self.motor.label_of_path(t.committed_path) or self.motor.label(t.committed) for t in tracks]
        main = tracks[0]
        details = {"candidates": [c for t in tracks for c in t.initial], "speed": main.speed,
                   "progress": main.progress}
        if len(tracks) > 1:
            details["subsystems"] = {t.subsystem: {"candidates": t.initial, "path": list(t.committed_path),
                                                    "speed": t.speed, "progress": t.progress} for t in tracks}
        return Match(labels[0] if len(tracks) == 1 else movement, min(t.confidence for t in tracks), memory.n,
                     path=tuple(e for t in tracks for e in t.committed_path), details=details,
                     candidates=self.ranking.ranked(main, labels[0], main.committed_path) if len(tracks) == 1 else ())

    def replay(self, memory: WorkingMemory, stop: int) -> list[tuple[int, Match]]:
        """:meth:`Matcher.replay <toolkit.components.Matcher.replay>`: the rows up to ``stop`` given at once, with the
        answers and the state of :meth:`observe` after each. Two runs of rows are given without it, because after
        each of them it would return ``None`` and change nothing but the rows the observation places, which it
        places when next asked (each row by the same addition, alone or in a batch):

        - once the segment settled (:meth:`_quiet`), every row to ``stop``;
        - while no subsystem is followed, the rows before the first at which one has moved more than ``min_move``
          since the onset (:meth:`_unmoved`: the test of :meth:`Tracking.start
          <plugins.matchers.forward_model.tracks.Tracking.start>` for all those rows at once).

        The rows from the first that starts a track until the segment settles are observed one by one.
        ``tests/plugins/matchers/forward_model/test_replay.py`` compares it with the rows fed one at a time."""
        events: list[tuple[int, Match]] = []
        row = memory.start + memory.n
        if row < stop and memory is not self.observation.memory:  # as observe's first row would
            self.begin(memory)
        while row < stop:
            if self._settled:
                break
            if not self.tracks:
                row = self._unmoved(memory, row, stop)
                if row >= stop:
                    break
            memory.feed(row + 1)
            match = self.observe(memory)
            if match is not None:
                events.append((row, match))
            row += 1
        memory.feed(stop)
        return events

    def _unmoved(self, memory: WorkingMemory, row: int, stop: int) -> int:
        """The first of rows ``row`` .. ``stop - 1`` after which :meth:`Tracking.start
        <plugins.matchers.forward_model.tracks.Tracking.start>` would start a track while no subsystem is followed
        (one whose parts are farther than ``min_move`` from where they were at the onset, as :meth:`Tracking.moved
        <plugins.matchers.forward_model.tracks.Tracking.moved>` measures it, row by row: the same values), else
        ``stop``. Reads the rows up to ``stop`` without giving them: ``memory`` is left as it was."""
        given = memory.start + memory.n
        memory.feed(stop)
        try:
            local = memory.positions + self.observation.root_height  # what local() places, row by row
        finally:
            memory.feed(given)
        far = norms(local[row - memory.start :] - local[0])  # (rows, P): moved's distances for each row
        moved = np.zeros(len(far), dtype=bool)
        for name, idx in self.motor.subsystems.items():
            moved |= np.fmax.reduce(far[:, idx], axis=1) * self.tracking.scale_of(name) > self.params["min_move"]
        hits = np.flatnonzero(moved)
        return row + int(hits[0]) if len(hits) else stop

    def settled(self) -> int | None:
        """After how many frames of the segment followed nothing more changed, if it settled: every subsystem
        followed, none with a candidate or a commitment (:meth:`_quiet`), and the rows given not rewritten since
        (:attr:`WorkingMemory.revision <toolkit.watching.WorkingMemory.revision>` the same). Else ``None``.

        Following the same rows from the same start up to any frame from then on leaves the same state as now (every
        later frame returned at once; the rows not yet placed are placed when next needed, each by the same
        addition), so a watching loop that must match the first ``m`` rows of what it followed (the first stroke of
        a movement the segmenter split) may conclude this state for them, its working memory cut to ``m`` rows,
        when ``m`` is at least this; ``tests/toolkit/test_watching_settled.py`` compares it with feeding them again."""
        kept, memory = self._settled_at, self.observation.memory
        if not self._settled or kept is None or memory is None or kept[1] != memory.revision:
            return None
        return kept[0]

    def _quiet(self, tracks: list[Track]) -> bool:
        """Whether the rest of the segment can change nothing: no subsystem is left to start (every one is followed,
        or only the first to move is) and no track has a candidate or a commitment (:meth:`Tracking.follow
        <plugins.matchers.forward_model.tracks.Tracking.follow>` returns at once). Every later frame would then
        return ``None`` without a change but the rows the observation places, which it places when next asked (each
        row by the same addition, alone or in a batch: the same values); :meth:`observe` skips them."""
        if self.tracking.waiting():
            return False
        return all(t.committed is None and not t.candidates for t in tracks)

    # -- the end of the demonstration ------------------------------------------------------------

    def conclude(self, motion: Motion) -> Match | None:
        """The demonstration has ended: check each subsystem's commitment against where it ended, learn the rest.

        A subsystem whose committed path ended where the demonstration did is in the path's end node. One that
        deviated (now, or while imitating) goes back to its last correct node and the rest of its movement is
        learned by the inverse model (true imitation, §4.3), as is the movement of a subsystem no edge predicted.
        Whatever was not yet imitated is returned as one movement (several subsystems: performed together).
        """
        if self.observation.memory is None:  # concluded without having followed the segment: follow it now
            return follow(self, motion)[1]
        try:
            return self._conclude()
        finally:
            self.observation.memory = None  # the next segment begins anew

    def _conclude(self) -> Match | None:
        if not self.tracks:
            return Match.unknown("nothing moved", details={"reason": "nothing moved"})
        motor, observation = self.motor, self.observation
        memory = observation.local()
        perform, learned, paths, route = [], [], [], []  # route: every edge from the start node (the label's)
        first_from, first_to = None, None
        for name in list(self.tracks):
            track = self.commitment.settle(self.tracks[name], memory)
            if track.committed is not None and not track.deviated:  # its commitment held
                motor.move_to(track.subsystem, motor.edge(track.committed_path[-1]).target, posture=False)
                if not track.reported:  # recognised, but not imitated yet (recognised at the end, or another
                    # subsystem had to be learned): at the speed measured over the whole demonstration
                    track.speed = self.clock.speed(track, track.committed_path,
                                                   len(observation.observed(track, memory)))
                    perform.append(track.committed)
                    paths.extend(track.committed_path)
                    route.extend(track.committed_path)
                continue
            # it deviated (now, or while followed) or was never committed: from where the body is, the start node or
            # the last correct node it went back to, it performs what was right and not performed yet, then the
            # rest: along the edge that explains it when one does (Fig. 3's loop), else what is learned
            motor.move_to(track.subsystem, track.home or track.start_node)
            before = list(track.right[track.at:])
            names: list[str] = []
            if track.committed is not None:  # another known edge explains the rest: nothing is learned
                track.speed = self.clock.speed(track, track.committed_path, len(observation.observed(track, memory)))
                rest = list(track.committed_path)
            else:
                names = self.learning.learn(track, memory) if self.learning is not None else []
                if not names:
                    continue
                rest = names
                if track.right:  # the part that was right, then the new one
                    motor.add_sequence([*track.right, *names])
            edges = [*before, *rest]
            end = motor.edge(edges[-1]).target
            motor.move_to(track.subsystem, end, posture=False)
            perform.append(motor.add_sequence(edges))
            paths.extend(edges)
            route.extend([*track.right, *rest])
            learned.extend(names)
            if first_from is None:
                first_from, first_to = track.last_correct, end
        if not perform:
            if self.reported:
                return None  # already reported when it committed
            details = {"reason": "no edge predicts the demonstration", **self.ranking.nearest(self.main)}
            return Match(None, 0.0, None, (), details, candidates=self.ranking.ranked(self.main),
                         reason=details["reason"], nearest=details.get("nearest"),
                         score=details.get("error_when_dropped"),
                         measure="prediction error of the nearest when it was dropped")
        movement = motor.add_together(perform)
        main = self.main
        tracks = list(self.tracks.values())
        details: dict[str, Any] = {"candidates": [c for t in tracks for c in t.initial],
                                   "deviated": any(t.deviated for t in tracks)}
        if details["deviated"]:  # the edges that failed, excluded from the segment's predictions (Fig. 3)
            details["excluded"] = sorted(e for t in tracks for e in t.excluded)
        if learned:
            details.update({"learned": learned, "from": first_from, "to": first_to})
        else:  # recognised only at the end, or again from the last correct node after a deviation
            details.update({"speed": main.speed, "progress": main.progress})
            if first_from is not None:
                details.update({"from": first_from, "to": first_to})
        if len(perform) > 1:
            details["subsystems"] = {motor.subsystem_of(m): m for m in perform}
        label = movement if len(perform) > 1 else (motor.label_of_path(tuple(route)) or motor.label(movement))
        ranked = self.ranking.ranked(main, label, main.committed_path) if len(tracks) == 1 and not learned and \
            main.committed is not None else ()
        return Match(label, 1.0 if learned else min(t.confidence for t in tracks if t.committed),
                     None, tuple(paths), details=details, candidates=ranked)

    def match(self, motion: Motion) -> Match:
        """Batch use: the whole segment at once (no facilitation): followed frame by frame, then concluded."""
        early, late = follow(self, motion)
        return late or early or Match.unknown()
