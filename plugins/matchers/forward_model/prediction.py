"""The forward models: where each candidate path of commands predicts the demonstrator's parts (K&G §4.4, Fig. 3).

"The edges of the active node predict the ongoing movement in parallel": each candidate is a path of edges from
the node the subsystem was in; its forward model places every part along the part's strokes, edge after edge, at a
path length (:mod:`~plugins.matchers.forward_model.speed` says which), from where the demonstration joined the first
command (:mod:`~plugins.matchers.forward_model.anchors`). The prediction error is the largest distance of a part from
its prediction, as K&G compare the wrist (radians of a hand's fingers counted through ``angle_scale``). A hand's
fingers share one transition function (§4.2): they are all predicted at the time at which the lead finger has covered
its path. A path whose commands have all been covered goes on along the edges of its end node but those excluded for
the segment (an edge that failed predicts no more, Fig. 3).

Cost: the one-command candidates of a positional subsystem (the common case) are predicted at once, their strokes'
rows gathered from the table of every stroke (:class:`~plugins.matchers.forward_model.tables.StrokeRows`); the same
arithmetic row by row, so the same values as one by one.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from plugins.matchers.forward_model.anchors import Anchors
from plugins.matchers.forward_model.path_length import norms
from plugins.matchers.forward_model.tables import Tables

if TYPE_CHECKING:
    from plugins.matchers.forward_model.observation import Observation
    from plugins.matchers.forward_model.tracks import Track

__all__ = ["Predictions"]

Path = tuple[str, ...]


class Predictions:
    """Every candidate path's prediction and prediction error for a followed subsystem."""

    def __init__(self, motor: Any, tables: Tables, anchors: Anchors, observation: Observation) -> None:
        self.motor = motor
        self.tables = tables
        self.anchors = anchors
        self.observation = observation

    def predict(self, track: Track, path: Path, lengths: np.ndarray) -> np.ndarray:
        """Where each part of the subsystem should be (k, 3) when it is ``lengths`` along ``path``: each part along
        its own strokes, edge after edge (:meth:`placed`).

        The fingers of a hand share their timing (one transition function, §4.2): they are all predicted at the
        time at which the lead finger has covered its observed path, so fingers that move in another order than
        the command's do not fit it.
        """
        tables = self.tables
        if track.hand:
            lead = tables.lead(path[0])
            left = lengths[lead]
            for i, name in enumerate(path):
                commands = tables.strokes_of(name)
                a = tables.table(commands[lead])[2]
                if left <= a[-1] or i == len(path) - 1:
                    t = tables.mapped_time(commands[lead], left)
                    return np.array([c.position(t) for c in commands])
                left -= a[-1]
        return tables.rows.along(*self.placed(path, lengths))

    @staticmethod
    def distance(track: Track, predicted: np.ndarray, observed: np.ndarray) -> float:
        """The prediction error: the largest of the per-part distances (k, 3 each; radians of a hand scaled), as K&G
        compare the wrist (§4.4)."""
        return float((norms(predicted - observed) * track.scale).max())

    def error(self, track: Track, path: Path, lengths: np.ndarray, last: np.ndarray) -> float:
        """Distance between the path's prediction, the parts having covered ``lengths`` since the demonstration joined
        it, and the parts' last observed positions ``last`` (k, 3) (:meth:`distance`)."""
        return self.distance(track, self.predict(track, path, self.anchors.along(track, path[0], lengths)), last)

    def errors(self, track: Track, paths: list[Path], lengths: np.ndarray, last: np.ndarray) -> dict[Path, float]:
        """:meth:`error` of every candidate path, in their order. The paths of a positional subsystem are predicted
        at once, their parts' points gathered from the table of every stroke: the one-command paths from their
        strokes stacked part by part (:meth:`stacked`), the longer ones each part on its edge (:meth:`placed`); the
        same arithmetic row by row, so the same values. A hand's paths one by one."""
        errors: dict[Path, float] = {}
        if not track.hand:
            k = len(lengths)
            one = [path for path in paths if len(path) == 1]
            if len(one) > 1:
                rows, totals, _, anchors = self.stacked(track, tuple(path[0] for path in one))
                along = np.minimum(lengths + anchors, totals)  # (C, k): Anchors.along, then predict's minimum
                predicted = self.tables.rows.along(rows, along.reshape(-1)).reshape(len(one), k, 3)
                d = norms(predicted - last) * track.scale
                errors = dict(zip(one, d.max(axis=1).tolist()))  # the largest part error of each
            longer = [path for path in paths if len(path) > 1]
            if longer:
                placed = [self.placed(path, self.anchors.along(track, path[0], lengths)) for path in longer]
                rows = np.concatenate([r for r, _ in placed])
                predicted = self.tables.rows.along(rows, np.concatenate([x for _, x in placed]))
                d = norms(predicted.reshape(len(longer), k, 3) - last) * track.scale
                errors.update(zip(longer, d.max(axis=1).tolist()))
        return {path: errors[path] if path in errors else self.error(track, path, lengths, last) for path in paths}

    def placed(self, path: Path, lengths: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Where each part of a positional subsystem ``lengths`` along ``path`` is predicted: its stroke's row in the
        table of every stroke (k,), on the first edge whose stroke is longer than what is left to place (the last
        edge for what is left past it), and how far along that stroke (k,), clipped to it."""
        tables = self.tables
        k = len(lengths)
        rows, x = np.empty(k, dtype=np.int64), np.empty(k)
        left = np.array(lengths, dtype=float)
        open_ = np.ones(k, dtype=bool)
        for i, name in enumerate(path):
            edge = tables.edge(name)
            total = edge.arcs[:, -1]
            here = open_ & ((left <= total) | (i == len(path) - 1))
            if here.any():
                rows[here] = tables.rows.rows(name, edge) + np.flatnonzero(here)
                x[here] = np.minimum(left[here], total[here])
                open_ &= ~here
            if not open_.any():
                break
            left = np.where(open_, left - total, left)
        return rows, x

    def stacked(self, track: Track, names: tuple[str, ...]) -> tuple[np.ndarray, ...]:
        """For commands ``names`` followed by ``track``: their strokes' rows in the table of every stroke (C * k),
        stroke lengths (C, k), lead parts (C,) (:meth:`Tables.stacked
        <plugins.matchers.forward_model.tables.Tables.stacked>`) and anchors (C, k), kept with the track until its
        set of candidates changes."""
        kept = self.observation.kept(track)
        cache = kept.stacked if kept is not None else None
        if cache is not None and cache[0] == names:
            return cache[1]
        strokes = self.tables.stacked(names)
        stacked = (*strokes, self.anchors.anchors(track, names))
        if kept is not None:
            kept.stacked = (names, stacked)
        return stacked

    def extended(self, track: Track, lengths: np.ndarray,
                 along: Callable[[Path], np.ndarray] | None = None) -> list[Path]:
        """Candidate paths whose commands have all been covered by the observation continue along every edge of
        their end node but those excluded for this segment (Fig. 3: an edge that failed predicts no more).

        ``lengths`` holds the observed path length of each part of the subsystem; ``along(path)``, how far along
        ``path`` the parts are predicted when that is not ``lengths`` (the paper's clock, elapsed time: path by
        path). On the path-length clock the one-command candidates of a positional subsystem go at once
        (:meth:`extended_at_once`)."""
        paths = list(track.candidates)
        if along is None and not track.hand and len(paths) > 1 and all(len(path) == 1 for path in paths):
            return self.extended_at_once(track, paths, lengths)
        tables = self.tables
        out = []
        for path in paths:
            lead = tables.lead(path[0])
            seen = self.anchors.along(track, path[0], lengths if along is None else along(path))[lead]
            total = sum(tables.edge(e).arcs[lead, -1] for e in path)
            out.extend(self.next(track, path) if seen > total + 0.01 / track.scale else [path])
        return out

    def extended_at_once(self, track: Track, paths: list[Path], lengths: np.ndarray) -> list[Path]:
        """:meth:`extended` of one-command paths (the common case) of a positional subsystem, at once, from the
        strokes stacked for :meth:`errors`: each path's lead part's observed length plus its anchor, against the
        lead's stroke length (the same values, element by element, as path by path)."""
        names = tuple(path[0] for path in paths)
        _, totals, leads, anchors = self.stacked(track, names)
        rows = np.arange(len(names))
        passed = lengths[leads] + anchors[rows, leads] > totals[rows, leads] + 0.01 / track.scale
        if not passed.any():
            return paths
        out = []
        for path, past in zip(paths, passed.tolist()):
            out.extend(self.next(track, path) if past else [path])
        return out

    def next(self, track: Track, path: Path) -> list[Path]:
        """A path whose commands have all been covered, continued along each edge of its end node that it does not
        hold and that is not excluded (itself when there is none)."""
        end = self.motor.edge(path[-1]).target
        nxt = [edge.name for edge in self.motor.edges_from(track.subsystem, end)]
        return [(*path, e) for e in nxt if e not in path and e not in track.excluded] or [path]
