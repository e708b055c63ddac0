"""What the per-movement search scores each take by: the motion comparison alone, or with the takes' strokes.

The motion comparison (:mod:`plugins.matchers.comparison`) sees where each part is and how it moves at each sample;
the per-movement search (:mod:`plugins.matchers.path_search.per_movement`) scores every take (a chain of the
posegraph) by it, at the take's tempo. ``comparison = "motion+strokes"`` adds each take's strokes as a second
evidence (Kopp & Graeser 2006, §4.1, §4.3), weighed by how well the repertoire's takes show each separates the
movements (:mod:`plugins.matchers.strokes_evidence`); a take's strokes come from the clip it was built from
(:meth:`Posegraph.take_motions`), else from its nodes played.

The strategy is chosen once, when the matcher is attached: :class:`MotionAlone` for ``comparison = "poses"`` or
``"motion"``, :class:`MotionAndStrokes` for ``"motion+strokes"``; the calibrated decision is calibrated on the takes
scored as the strategy scores a demonstration (:meth:`Evidence.calibration`).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, Any

import numpy as np

from plugins.matchers.decision import Calibration
from plugins.matchers.strokes_evidence import PLAYED_FPS, StrokesEvidence
from plugins.matchers.tempo import Paced, paced_scores
from plugins.matchers.warping import chain_calibration, chain_rows
from toolkit import Motion

if TYPE_CHECKING:
    from plugins.matchers.path_search.per_movement import EachMovement

__all__ = ["Evidence", "MotionAlone", "MotionAndStrokes"]


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
    """The motion comparison's scores and the takes' strokes', weighed as
    :class:`plugins.matchers.strokes_evidence.StrokesEvidence` weighs them."""

    def __init__(self, body: Any, known_rejected: float) -> None:
        self.mix = StrokesEvidence(body, known_rejected)

    @property
    def weights(self) -> np.ndarray:
        """The two evidences' weights (motion, strokes)."""
        return self.mix.weights

    def rebuild(self, search: EachMovement) -> None:
        m = search.matcher
        rows = chain_rows(m.comparison, search.takes, search.nodes, search.chains, paced_scores)
        self.mix.rebuild(rows, search.chains.movements, lambda: _chain_motions(m.motor))

    def scores(self, paced: Paced, motion: Motion) -> np.ndarray:
        return self.mix.scores(paced.scores, motion)

    def calibration(self, search: EachMovement) -> Calibration:
        return self.mix.calibration(search.chains.movements)


def _chain_motions(motor: Any) -> list[Motion | None]:
    """Each take of ``motor`` that has a node (as the chains keep them, in their order) as a motion: the clip it was
    built from, else its nodes played at :data:`plugins.matchers.strokes_evidence.PLAYED_FPS`."""
    played = motor.take_motions(fps=PLAYED_FPS)
    return [motion for movement, takes in motor.takes().items() for nodes, motion in zip(takes, played[movement])
            if nodes]
