"""The takes' strokes as a second evidence beside a motion comparison, weighed by what the repertoire shows.

A comparison of samples (:mod:`plugins.matchers.comparison`) sees where each part is and how it moves at each
sample. What separates a wave of one hand from a raise of it held at the same height is the swings, which such a
comparison barely sees: the wave's swings against the raise's one stroke up and down (issue 34). Kopp & Graeser 2006
(§4.1, §4.3) represent a movement by its guiding strokes; this module adds that as a second evidence, for any
matcher that scores takes relative to the demonstration's distance to standing still (path search's per-movement
search, :mod:`plugins.matchers.path_search.evidence`; the forward model's answer at the end,
:mod:`plugins.matchers.forward_model.answer`):

- :class:`TakeStrokes`: each take's strokes, from the clip it was learned from (else its movement played), cut
  where a part turns back and scaled to shares of their total length, so that they show what the parts do and not
  at what size (:class:`plugins.matchers.stroke_warping.PartStrokes`), the root's travel among them
  (:class:`TravelStrokes`: a walk backwards is not a walk forwards, a turn to the right not one to the left, where
  the motions carry their world positions), and a demonstration's warped
  against every take's at once (:func:`plugins.matchers.stroke_warping.stroke_distances`): the share of the
  demonstration's stroke length a take leaves unexplained, a relative score like the motion comparison's;
- :func:`evidence_weights`: the two scores mixed per take, each evidence weighed by how well the repertoire's own
  takes show it separates the movements: by the log of how much farther the nearest other movement lies than the
  movement's own other takes (medians over the takes), over that distance to the nearest other movement, so a score
  is first measured in the evidence's own spacing of movements. The strokes, an evidence added to the matcher's own
  comparison, count only where they separate the movements *where the decision draws its line*: where the nearest
  of the other movements but ``known_rejected`` of them lies farther than the farthest of the own takes but that
  share (the quantiles the calibrated decision reads). Strokes whose takes of one movement lie, at those tails, as
  far apart as movements do count for nothing, however well they separate them on the whole: the decision would
  still call the one a performance of the other. A repertoire of one take per movement shows nothing of how far
  performances of one movement lie: there the motion comparison decides alone (and no stroke is computed);
- :class:`StrokesEvidence`: the mix, and the takes scored alike against each other, on which the calibrated
  decision (:mod:`plugins.matchers.decision`) is calibrated. A demonstration with no stroke at all (it moves less
  than a stroke's ``reversal``) is scored by the motion alone, and so is a take with none: the strokes say nothing
  of it.

The mixed score is still a share of the demonstration left unexplained (a weighted mean of two such shares), so the
calibrated decision takes it as it is.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from plugins.lib.travel import bridged_rows, travelled
from plugins.matchers.decision import Calibration
from plugins.matchers.dtw import position_parts
from plugins.matchers.stroke_warping import (
    REVERSAL,
    SMOOTH,
    PartStrokes,
    Strokes,
    flat_strokes,
    stroke_distances,
    strokes_still,
)
from toolkit import Motion

__all__ = ["MOST_SEPARATION", "PLAYED_FPS", "StrokesEvidence", "TakeStrokes", "TravelStrokes", "evidence_weights"]

PLAYED_FPS = 30.0
"""Frames per second at which a take with no clip of its own (a learned movement, key poses, a take restored from
a saved state) is played for its strokes."""

MOST_SEPARATION = float(np.log(1000.0))
"""The most an evidence's separation counts: takes a thousand times nearer each other than movements are (two
copies of one clip are infinitely near, and would leave the other evidence nothing)."""


class TravelStrokes(PartStrokes):
    """Every position part's strokes and the root's travel's, as one more path: where the root went since the
    first frame, in the body's frame at that frame (:func:`plugins.lib.travel.travelled`), cut like a part's. A walk
    forwards and one backwards make the same strokes of the limbs, root-relative, and opposite strokes of the root;
    a turn to the left and one to the right, strokes of the root that curve to either side."""

    def paths(self, rel: np.ndarray, track: np.ndarray | None) -> np.ndarray:
        """The chosen parts' root-relative paths and ``track`` (none known: the root held where it is)."""
        track = np.zeros((len(rel), 3)) if track is None else track
        return np.concatenate([rel[:, self.parts], track[:, None]], axis=1)

    @property
    def count(self) -> int:
        return len(self.parts) + 1


class TakeStrokes:
    """Every take's strokes, with the defaults of :mod:`plugins.matchers.stroke_warping` and the root's travel
    (:class:`TravelStrokes`), and a demonstration's relative score against each."""

    def __init__(self, body: Any) -> None:
        parts, sized = position_parts(body, [])
        self.features = TravelStrokes(parts, body.root_index, sized, REVERSAL, SMOOTH)
        self.templates: list[Strokes] = []
        self.flat, self.starts = flat_strokes([])
        self.still = np.zeros(0)

    def rebuild(self, motions: Sequence[Motion | None]) -> None:
        """The strokes of each take, one motion each in the matcher's order of takes (``None``: a take that does not
        move, with no stroke)."""
        self.templates = [self.series(m) if m is not None else self.features.none() for m in motions]
        self.flat, self.starts = flat_strokes(self.templates)
        self.still = np.array([strokes_still(t) for t in self.templates])

    def series(self, motion: Motion) -> Strokes:
        """A motion's strokes (hidden parts held where last seen, :meth:`toolkit.Motion.filled`; the root's travel
        from its world positions, :attr:`toolkit.Motion.world`, bridged where it is not seen; none known: none)."""
        if motion.n_frames < 2 or not motion.visible.any():
            return self.features.none()
        positions = np.asarray(motion.positions, dtype=float) if motion.visible.all() else motion.filled().positions
        return self.features.series(positions, motion.fps, _track(motion, self.features.root))

    def scores(self, series: Strokes, still: float) -> np.ndarray:
        """Each take's stroke length left unexplained by ``series`` over its own (``still`` > 0), (C,)."""
        return stroke_distances(series, self.flat, self.starts) / still

    def rows(self) -> np.ndarray:
        """Each take against every take but itself (``inf``), (C, C); a take with no stroke scores ``inf``."""
        rows = np.full((len(self.templates), len(self.templates)), np.inf)
        for c, (series, still) in enumerate(zip(self.templates, self.still)):
            if still > 0:
                rows[c] = self.scores(series, still)
            rows[c, c] = np.inf
        return rows


class StrokesEvidence:
    """A motion comparison's scores of the takes and the takes' strokes', weighed by :func:`evidence_weights`.

    :attr:`weights` are the two evidences' (motion, strokes); :attr:`rows` every take scored alike against every
    other take (:func:`plugins.matchers.warping.chain_rows`' shape), for :meth:`calibration`."""

    def __init__(self, body: Any, known_rejected: float) -> None:
        self.strokes = TakeStrokes(body)
        self.known_rejected = float(known_rejected)
        self.weights = np.array([1.0, 0.0])
        self.rows = np.zeros((0, 0))

    def rebuild(self, motion_rows: np.ndarray, movements: Sequence[str],
                motions: Callable[[], Sequence[Motion | None]]) -> None:
        """The weights and the mixed rows, from the motion comparison's rows of the takes (whose ``movements`` they
        are) and the takes as motions (``motions()``, asked for only where the takes can show a separation: not with
        one take of each movement, where the motion decides alone and no clip is cut into strokes)."""
        if len(set(movements)) == len(movements):
            self.weights, self.rows = np.array([1.0, 0.0]), motion_rows
            return
        self.strokes.rebuild(motions())
        stroke_rows = self.strokes.rows()
        self.weights = evidence_weights([motion_rows, stroke_rows], movements, self.known_rejected)
        self.rows = np.where(self.strokes.still[:, None] > 0, self._mixed(motion_rows, stroke_rows), motion_rows)

    def _mixed(self, motion: np.ndarray, strokes: np.ndarray) -> np.ndarray:
        """The weighted mean of the two evidences' scores (``inf`` where either is); the motion's alone while the
        strokes weigh nothing."""
        if self.weights[1] == 0:
            return motion
        finite = np.isfinite(motion) & np.isfinite(strokes)
        mixed = self.weights[0] * np.where(finite, motion, 0.0) + self.weights[1] * np.where(finite, strokes, 0.0)
        return np.where(finite, mixed, np.inf)

    def scores(self, motion_scores: np.ndarray, motion: Motion) -> np.ndarray:
        """Each take's mixed score (C,) for a demonstration ``motion`` the motion comparison scored
        ``motion_scores``; those as they are where the strokes weigh nothing or the demonstration has none."""
        if self.weights[1] == 0:
            return motion_scores
        series = self.strokes.series(motion)
        still = strokes_still(series)
        if not still > 0:  # no stroke: the strokes say nothing of it
            return motion_scores
        return self._mixed(motion_scores, self.strokes.scores(series, still))

    def calibration(self, movements: Sequence[str]) -> Calibration:
        """Leave one take out and leave one movement out, on the takes scored alike (:attr:`rows`)."""
        return Calibration.of_rows(self.rows, movements)


def _track(motion: Motion, root: int) -> np.ndarray | None:
    """Where ``motion``'s root went (:func:`plugins.lib.travel.travelled`), linearly bridged over the frames it was
    not seen in and held beyond them; ``None`` where the motion has no world positions or its facing is never
    known."""
    if motion.world is None:
        return None
    track = travelled(motion.world, motion.positions, motion.visible, root)
    seen = np.isfinite(track).all(axis=1)
    return bridged_rows(track, seen) if seen.any() else None


def evidence_weights(rows: Sequence[np.ndarray], movements: Sequence[str], known_rejected: float) -> np.ndarray:
    """Each evidence's weight (E,), summing to 1, from its scores of every take against every other (``rows``, each
    (C, C) as :func:`plugins.matchers.warping.chain_rows` gives them; the first the matcher's own comparison's) and
    the takes' ``movements``.

    An evidence's separation is ``log(other / own)``, at least 0, ``other`` the median score of each take's nearest
    other movement and ``own`` that of its movement's nearest other take (:meth:`Calibration.of_rows`); its weight is
    its separation over ``other``. An evidence beside the first counts only where it separates the movements where
    the calibrated decision draws its line (:class:`plugins.matchers.decision.Calibrated`): where the
    ``known_rejected`` quantile of the other scores lies beyond the ``1 - known_rejected`` quantile of the own ones;
    else it weighs nothing. Where no evidence shows a separation to weigh (no movement with two takes, no second
    movement, or every separation 0), the first evidence alone (weight 1)."""
    weights = np.zeros(len(rows))
    weights[0] = 1.0
    measured = []
    for k, row in enumerate(rows):
        calibration = Calibration.of_rows(row, movements)
        if not calibration.own or not calibration.other:
            return weights
        own, other = float(np.median(calibration.own)), float(np.median(calibration.other))
        if not other > 0 or not np.isfinite(other):
            return weights
        separation = np.log(other / own) if own > 0 else np.inf
        if k and not np.quantile(calibration.other, known_rejected) > np.quantile(calibration.own, 1 - known_rejected):
            separation = 0.0  # an added evidence that does not separate the movements where "unknown" is decided
        measured.append(min(max(separation, 0.0), MOST_SEPARATION) / other)
    total = float(np.sum(measured))
    return np.asarray(measured) / total if total > 0 else weights


