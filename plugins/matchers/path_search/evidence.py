"""What the per-movement search scores each take by: the motion comparison alone, or with the takes' strokes.

The motion comparison (:mod:`plugins.matchers.comparison`) sees where each part is and how it moves at each sample;
the per-movement search (:mod:`plugins.matchers.path_search.per_movement`) scores every take (a chain of the
posegraph) by it, at the take's tempo. What separates a wave of one hand from a raise of it held at the same height
is the swings, which a comparison of samples barely sees: the wave's swings against the raise's one stroke up and
down (issue 34). ``comparison = "motion+strokes"`` adds that as a second evidence, after Kopp & Graeser 2006
(§4.1, §4.3), who represent a movement by its guiding strokes:

- :class:`TakeStrokes`: each take's strokes, from the clip it was built from (:meth:`Posegraph.take_motions`), cut
  where a part turns back (:class:`plugins.matchers.stroke_warping.PartStrokes`), and a demonstration's warped
  against every take's at once (:func:`plugins.matchers.stroke_warping.stroke_distances`): the share of the
  demonstration's stroke length a take leaves unexplained, a relative score like the motion comparison's;
- :func:`evidence_weights`: the two scores mixed per take, each evidence weighed by how well the repertoire's own
  takes show it separates the movements: by the log of how much farther the nearest other movement lies than
  the movement's own other takes (medians over the takes), over that distance to the nearest other movement, so a
  score is first measured in the evidence's own spacing of movements. An evidence whose takes of one movement lie
  as far apart as movements do counts for nothing. A repertoire of one take per movement shows nothing of how far
  performances of one movement lie: there the motion comparison decides alone, as it does without strokes;
- a demonstration with no stroke at all (it moves less than a stroke's ``reversal``) is scored by the motion alone,
  and so is a take with none in the calibration: the strokes say nothing of it.

The mixed score is still a share of the demonstration left unexplained (a weighted mean of two such shares), so
the calibrated decision (:mod:`plugins.matchers.decision`) takes it as it is, calibrated on the takes scored alike
(:meth:`Evidence.calibration`). The strategy is chosen once, when the matcher is attached: :class:`MotionAlone` for
``comparison = "poses"`` or ``"motion"``, :class:`MotionAndStrokes` for ``"motion+strokes"``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

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
from plugins.matchers.tempo import Paced, paced_scores
from plugins.matchers.warping import chain_calibration, chain_rows
from toolkit import Motion

if TYPE_CHECKING:
    from plugins.matchers.path_search.per_movement import EachMovement

__all__ = ["Evidence", "MotionAlone", "MotionAndStrokes", "TakeStrokes", "evidence_weights"]

PLAYED_FPS = 30.0
"""Frames per second at which a take with no clip of its own (a learned movement, key poses) is played for its
strokes."""


class Evidence(ABC):
    """How the per-movement search scores the takes, and calibrates its decision on them alike."""

    def rebuild(self, search: EachMovement) -> None:
        """Build what it needs of the posegraph's takes as they are now (``search``'s chains and take frames)."""

    @abstractmethod
    def scores(self, paced: Paced, motion: Motion) -> np.ndarray:
        """Each take's relative score (C,) for a demonstration ``motion``, whose motion comparison gave ``paced``."""

    @abstractmethod
    def calibration(self, search: EachMovement) -> Calibration:
        """Leave one take out and leave one movement out, the takes scored as :meth:`scores` scores them."""


class MotionAlone(Evidence):
    """The motion comparison's scores at each take's tempo (``comparison = "poses"`` or ``"motion"``)."""

    def scores(self, paced: Paced, motion: Motion) -> np.ndarray:
        return paced.scores

    def calibration(self, search: EachMovement) -> Calibration:
        m = search.matcher
        return chain_calibration(m.comparison, search.takes, search.nodes, search.chains, paced_scores)


class MotionAndStrokes(Evidence):
    """The motion comparison's scores and the takes' strokes', weighed by :func:`evidence_weights`."""

    def __init__(self, body: Any) -> None:
        self.strokes = TakeStrokes(body)
        self.weights = np.array([1.0, 0.0])

    def rebuild(self, search: EachMovement) -> None:
        m = search.matcher
        motion_rows = chain_rows(m.comparison, search.takes, search.nodes, search.chains, paced_scores)
        if len(set(search.chains.movements)) == len(search.chains.movements):  # one take of each: the motion alone
            self.weights, self.rows = np.array([1.0, 0.0]), motion_rows
            return
        self.strokes.rebuild(m.motor)
        stroke_rows = self.strokes.rows()
        self.weights = evidence_weights([motion_rows, stroke_rows], search.chains.movements)
        self.rows = np.where(self.strokes.still[:, None] > 0, self._mixed(motion_rows, stroke_rows), motion_rows)

    def _mixed(self, motion: np.ndarray, strokes: np.ndarray) -> np.ndarray:
        """The weighted mean of the two evidences' scores (``inf`` where either is); the motion's alone while the
        strokes weigh nothing."""
        if self.weights[1] == 0:
            return motion
        finite = np.isfinite(motion) & np.isfinite(strokes)
        mixed = self.weights[0] * np.where(finite, motion, 0.0) + self.weights[1] * np.where(finite, strokes, 0.0)
        return np.where(finite, mixed, np.inf)

    def scores(self, paced: Paced, motion: Motion) -> np.ndarray:
        if self.weights[1] == 0:
            return paced.scores
        series = self.strokes.series(motion)
        still = strokes_still(series)
        if not still > 0:  # no stroke: the strokes say nothing of it
            return paced.scores
        return self._mixed(paced.scores, self.strokes.scores(series, still))

    def calibration(self, search: EachMovement) -> Calibration:
        return Calibration.of_rows(self.rows, search.chains.movements)


class TakeStrokes:
    """Every take's strokes (the posegraph's chains, in order: :func:`plugins.matchers.path_search.per_movement.
    posegraph_chains`), with the defaults of :mod:`plugins.matchers.stroke_warping`, and a demonstration's relative
    score against each."""

    def __init__(self, body: Any) -> None:
        parts, sized = position_parts(body, [])
        self.features = PartStrokes(parts, body.root_index, sized, REVERSAL, SMOOTH)
        self.templates: list[Strokes] = []
        self.flat, self.starts = flat_strokes([])
        self.still = np.zeros(0)

    def rebuild(self, motor: Any) -> None:
        """The strokes of every take of ``motor`` that has a node (as the chains keep them), from the clip it was
        built from, else from its nodes played at :data:`PLAYED_FPS`."""
        played = motor.take_motions(fps=PLAYED_FPS)
        self.templates = []
        for movement, takes in motor.takes().items():
            for nodes, motion in zip(takes, played[movement]):
                if nodes:
                    self.templates.append(self.series(motion) if motion is not None else self.features.none())
        self.flat, self.starts = flat_strokes(self.templates)
        self.still = np.array([strokes_still(t) for t in self.templates])

    def series(self, motion: Motion) -> Strokes:
        """A motion's strokes (hidden parts held where last seen, :meth:`toolkit.Motion.filled`)."""
        if motion.n_frames < 2 or not motion.visible.any():
            return self.features.none()
        positions = np.asarray(motion.positions, dtype=float) if motion.visible.all() else motion.filled().positions
        return self.features.series(positions, motion.fps)

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


def evidence_weights(rows: Sequence[np.ndarray], movements: Sequence[str]) -> np.ndarray:
    """Each evidence's weight (E,), summing to 1, from its scores of every take against every other (``rows``, each
    (C, C) as :func:`plugins.matchers.warping.chain_rows` gives them) and the takes' ``movements``.

    An evidence's separation is ``log(other / own)``, ``other`` the median score of a take's nearest other movement
    and ``own`` that of its movement's nearest other take (:meth:`Calibration.of_rows`), at least 0; its weight is
    its separation over ``other``. Where some evidence shows no separation to weigh (no movement with two takes, no
    second movement, or every separation 0), the first evidence alone (weight 1)."""
    weights = np.zeros(len(rows))
    weights[0] = 1.0
    measured = []
    for row in rows:
        calibration = Calibration.of_rows(row, movements)
        if not calibration.own or not calibration.other:
            return weights
        own, other = float(np.median(calibration.own)), float(np.median(calibration.other))
        if not other > 0:
            return weights
        separation = np.log(other / own) if own > 0 else np.inf
        measured.append(min(max(separation, 0.0), MOST_SEPARATION) / other)
    total = float(np.sum(measured))
    return np.asarray(measured) / total if total > 0 else weights


MOST_SEPARATION = float(np.log(1000.0))
"""The most an evidence's separation counts: takes a thousand times nearer each other than movements are (two
copies of one clip are infinitely near, and would leave the other evidence nothing)."""
