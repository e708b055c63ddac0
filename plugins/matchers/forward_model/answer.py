"""The forward model's answer at the end of a demonstration: what the whole of it is scored by, and decided on.

Kopp & Graeser 2006, §4.4: the forward models predict a demonstration while it comes in, and one that prevails is
imitated at once (:mod:`plugins.matchers.forward_model.following`); when the demonstration is over, it must have
ended where the committed movement does, and what no forward model predicts is learned as new (§4.3). While a
demonstration comes in, only what can be compared sample by sample is known: each take's motion, followed by time
warping. When it has ended, all of it is there, and its guiding strokes (§4.1, §4.3) can be compared with each
take's: the swings of a wave against the one stroke up and down of a raise held at the same height, which a
comparison of samples barely tells apart (issue 34). The strategy is chosen once, when the matcher is attached:

- :class:`FollowedScores` (``comparison = "motion"``): each take's followed score at the end, decided by the very
  decision that commits (calibrated on the predictions followed alike);
- :class:`FollowedAndStrokes` (``comparison = "motion+strokes"``): each take's followed score and its strokes' score
  over the whole demonstration, mixed as path search mixes them
  (:class:`plugins.matchers.strokes_evidence.StrokesEvidence`: each evidence weighed by how well the repertoire's
  own takes show it separates the movements; with one take of each movement, the motion alone), and decided by a
  decision of its own, calibrated on the takes scored alike. The commitments made while the demonstration came in
  are unchanged; one stands at the end only when the answer on all of it is its movement.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from plugins.matchers.decision import Calibrated, Decision
from plugins.matchers.strokes_evidence import StrokesEvidence
from toolkit import Motion

__all__ = ["Answer", "FollowedAndStrokes", "FollowedScores"]


class Answer(ABC):
    """What the forward model scores the takes by at the end of a demonstration, and the decision it holds the
    nearest movement's score to."""

    decision: Decision

    @abstractmethod
    def rebuild(self, rows: np.ndarray, movements: Sequence[str], motions: Callable[[], list[Motion | None]]) -> None:
        """From the takes as they are now: ``rows``, every take's prediction followed as a demonstration against
        every take (:func:`plugins.matchers.warping.chain_rows`; the takes' ``movements``), and the takes as motions
        (``motions()``, asked for only if needed)."""

    @abstractmethod
    def scores(self, followed: np.ndarray, demonstration: Callable[[], Motion]) -> np.ndarray:
        """Each take's score (C,) on the whole demonstration, whose takes were followed to the scores ``followed``
        (``demonstration()``: the demonstration as a motion, asked for only if needed)."""


class FollowedScores(Answer):
    """The followed scores as they are, decided by the decision that commits (``comparison = "motion"``)."""

    def __init__(self, decision: Decision) -> None:
        self.decision = decision

    def rebuild(self, rows: np.ndarray, movements: Sequence[str], motions: Callable[[], list[Motion | None]]) -> None:
        """Nothing of its own: the decision that commits is calibrated on the same rows."""

    def scores(self, followed: np.ndarray, demonstration: Callable[[], Motion]) -> np.ndarray:
        return followed


class FollowedAndStrokes(Answer):
    """The followed scores and the takes' strokes, mixed, with a calibrated decision of its own
    (``comparison = "motion+strokes"``)."""

    def __init__(self, body: Any, known_rejected: float) -> None:
        self.mix = StrokesEvidence(body, known_rejected)
        self.decision = Calibrated(known_rejected)

    @property
    def weights(self) -> np.ndarray:
        """The two evidences' weights (motion, strokes)."""
        return self.mix.weights

    def rebuild(self, rows: np.ndarray, movements: Sequence[str], motions: Callable[[], list[Motion | None]]) -> None:
        self.mix.rebuild(rows, movements, motions)
        self.decision.calibrate(self.mix.calibration(movements))

    def scores(self, followed: np.ndarray, demonstration: Callable[[], Motion]) -> np.ndarray:
        if self.mix.weights[1] == 0:
            return followed
        return self.mix.scores(followed, demonstration())
