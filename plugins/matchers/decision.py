"""Whether the nearest movement is near enough: a matcher's *decision* for "unknown".

Every matcher ranks its own movements by how near each comes to the demonstration (its comparison and search);
the decision says whether the nearest is near enough to be that movement, or whether the demonstration is a
movement the observer does not know (Buchsbaum & Blumberg 2005, §5.2.3 and §7.3: what is unknown can then be
learned; Kopp & Graeser 2006, §4.3: true imitation learning of what no forward model predicts). Two decisions,
chosen once when a matcher is attached (``decision = "distance"`` or ``"calibrated"``), shared by ``path-search``,
``forward-model`` and ``dtw``:

:class:`Distance` (the papers)
    Unknown beyond a fixed distance in the comparison's own unit (B&B's ``max_distance`` of eq. 3, metres on one's
    own body; K&G's drop-out ``threshold``). Right for the papers' characters, who watch bodies like their own;
    a length does not carry over to another data set, skeleton or performer.

:class:`Calibrated` (real people, the observer template's)
    Calibrated from the repertoire itself, so the same setting holds for one take of each movement, two, or
    fourteen, on any skeleton. The score is unit-free (:func:`relative_scores`): the distance to the nearest
    movement over the larger of the demonstration's distance to standing still
    (:meth:`plugins.matchers.comparison.Comparison.still`) and that movement's take's, the share of the larger of
    the two motions the pair leaves unexplained. The matcher measures, with its own comparison and
    search, two sets of scores on its repertoire (:class:`Calibration`):

    - *own*: each take of a movement of several takes, against the movement's other takes (leave one take out):
      how far performances of one movement lie from each other;
    - *other*: each take against the repertoire without its movement (leave one movement out): how near a
      movement the repertoire does not hold comes to the nearest it does hold.

    A demonstration is unknown when its score is above the threshold (:meth:`Calibrated.threshold`), never above 1
    (a movement that explains a demonstration no better than standing still does not stand for it). The meaning a
    user sets is ``known_rejected``, a share, read both ways as the repertoire allows:

    - *the repertoire shows a gap*: all but ``known_rejected`` of the own scores lie below all but
      ``known_rejected`` of the other scores (several takes of each movement, each nearer its own movement than
      any other movement comes). Any threshold in the gap calls at most that share of a known movement's
      performances unknown and takes at most that share of movements like the repertoire's own for known, as far
      as the repertoire shows; the threshold is the gap's far side (the ``known_rejected`` quantile of the other
      scores), because takes recorded one after another lie nearer each other than performances in other styles
      or by other people do;
    - *no gap, several takes* (takes that lie as far apart as movements do: performed by different people, or
      in different styles): the ``1 - known_rejected`` quantile of the own scores, split-conformal: all but that
      share of a known movement's performances score below it, as far as its takes show how they vary;
    - *one take of each movement* (no own scores): the ``1 - known_rejected`` quantile of the other scores. One take
      shows nothing of how far a performance may lie, so the repertoire's movements stand for it: a performance of
      a movement is taken to lie no farther from it than the repertoire's movements lie from their nearest
      neighbours, all but ``known_rejected`` of them. A movement the repertoire does not hold is unknown where it
      lies farther than that; one as near to a known movement as the repertoire's own movements are to each other
      cannot be told from a performance of it.

    The same setting holds with one take of each movement, two, or fourteen (``docs/matchers.md`` has the figures).

A movement that holds still (a pose held, B&B §5.2.1's hub; a command with no guiding stroke, K&G §4.1) cannot be
judged by a score relative to standing still: it *is* standing still, so every demonstration scores 1 against it
whether it stands or waves. :class:`Stillness` judges it by how much the demonstration moves instead.

The decision's answer, with the score and the threshold it was decided on, goes into the typed fields of
:class:`toolkit.Match` (``score``, ``threshold``, ``nearest``, ``measure``), which ``likeme observe`` prints for
every "unknown".
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["Calibrated", "Calibration", "DECISIONS", "Decision", "Distance", "Stillness", "Verdict", "relative_scores"]


@dataclass(frozen=True)
class Calibration:
    """Scores a matcher measured on its own repertoire (see the module), each a demonstration's distance to its
    nearest movement over its distance to standing still.

    Attributes
    ----------
    own : tuple of float
        Leave one take out: each take of a movement of several takes against the movement's other takes.
    other : tuple of float
        Leave one movement out: each take against the repertoire without its movement.
    """

    own: tuple[float, ...] = ()
    other: tuple[float, ...] = ()

    @classmethod
    def of(cls, own: Sequence[float], other: Sequence[float]) -> Calibration:
        """The finite scores of ``own`` and ``other``."""
        return cls(tuple(float(x) for x in own if np.isfinite(x)), tuple(float(x) for x in other if np.isfinite(x)))

    @classmethod
    def of_rows(cls, rows: np.ndarray, movements: Sequence[str]) -> Calibration:
        """From every take's scores against every take, ``rows[c, d]`` (C, C), take ``c`` itself left out (its own
        column ignored), and each take's movement: own, the nearest of a take's movement's other takes; other, the
        nearest take of another movement."""
        movements = np.asarray(movements, dtype=object)
        own, other = [], []
        for c, row in enumerate(np.asarray(rows, dtype=float)):
            mine = movements == movements[c]
            others = mine.copy()
            others[c] = False
            for out, chosen in ((own, others), (other, ~mine)):
                if chosen.any():
                    out.append(float(row[chosen].min()))
        return cls.of(own, other)


@dataclass(frozen=True)
class Verdict:
    """What a decision says of the nearest movement: the movement (``None``: unknown), the nearest one, the score
    the verdict was decided on and the threshold it was held to (in :attr:`Decision.measure`)."""

    movement: str | None
    nearest: str | None
    score: float
    threshold: float


class Decision(ABC):
    """Known or unknown, from each movement's distance to a demonstration."""

    name: str
    relative: bool
    """Whether the score is relative to standing still (:class:`Calibrated`) rather than a distance."""

    @property
    @abstractmethod
    def measure(self) -> str:
        """What :attr:`Verdict.score` and :attr:`Verdict.threshold` are, for people."""

    @abstractmethod
    def threshold(self) -> float:
        """The largest score accepted as a known movement."""

    def decide(self, nearest: str | None, distance: float, still: float = 1.0) -> Verdict:
        """The verdict on the ``nearest`` movement at ``distance`` (in the comparison's unit) from the
        demonstration; ``still``: the demonstration's distance to standing still, which a relative decision divides
        by. No nearest movement (nothing came near): unknown."""
        limit = self.threshold()
        if nearest is None or not np.isfinite(distance):
            return Verdict(None, nearest, float("inf"), limit)
        score = self.score(distance, still)
        return Verdict(nearest if score <= limit else None, nearest, score, limit)

    def score(self, distance: float, still: float) -> float:
        """The score a distance is decided on."""
        if not self.relative:
            return float(distance)
        return float(distance / still) if still > 0 else (0.0 if distance <= 0 else float("inf"))


class Distance(Decision):
    """Unknown beyond ``max_distance`` in the comparison's unit (the papers; 0: never unknown)."""

    name = "distance"
    relative = False

    def __init__(self, max_distance: float, measure: str = "mean distance (m)") -> None:
        self.max_distance = float(max_distance)
        self._measure = measure

    @property
    def measure(self) -> str:
        return self._measure

    def threshold(self) -> float:
        return self.max_distance if self.max_distance > 0 else float("inf")


class Calibrated(Decision):
    """Unknown beyond a threshold calibrated on the repertoire's own takes (see the module)."""

    name = "calibrated"
    relative = True

    def __init__(self, known_rejected: float = 0.05) -> None:
        if not 0.0 <= known_rejected <= 1.0:
            raise ValueError(f"known_rejected must be in [0, 1], not {known_rejected!r}")
        self.known_rejected = float(known_rejected)
        self.calibrate(Calibration())

    @property
    def measure(self) -> str:
        return "distance to the nearest movement over the larger motion, its or the demonstration's"

    def calibrate(self, calibration: Calibration) -> None:
        """Take the scores measured on the repertoire (:class:`Calibration`)."""
        self.calibration = calibration
        self._threshold = self._limit()

    def threshold(self) -> float:
        return self._threshold

    def _limit(self) -> float:
        """At most :data:`STILL` (1: no better than standing still), and :data:`STILL` while the repertoire has
        neither two movements nor two takes of one:

        - where the repertoire shows a gap (the ``1 - known_rejected`` quantile of the own scores at most the
          ``known_rejected`` quantile of the other scores), the gap's far side, the ``known_rejected`` quantile of
          the other scores;
        - else, with own scores, their ``1 - known_rejected`` quantile;
        - else (one take of each movement) the ``1 - known_rejected`` quantile of the other scores."""
        rate = self.known_rejected
        own, other = np.asarray(self.calibration.own), np.asarray(self.calibration.other)
        if len(own) and len(other):
            unknown = float(np.quantile(other, rate))
            if float(np.quantile(own, 1.0 - rate)) <= unknown:
                return min(unknown, STILL)
        for scores in (own, other):
            if len(scores):
                return min(float(np.quantile(scores, 1.0 - rate)), STILL)
        return STILL


@dataclass(frozen=True)
class Stillness:
    """The repertoire's movements that hold still, and how little a demonstration must move to be one of them.

    Each movement's *motion* is the mean distance to standing still of its takes (the largest of them;
    :meth:`plugins.matchers.comparison.Comparison.still`, in the comparison's unit). A movement whose takes do not
    move at all (0, up to rounding) holds still. A demonstration that moves ``moved`` is such a movement when it
    moves at most half as much as the least moving of the other movements (:attr:`limit`): then, by the triangle
    inequality, no moving movement can come nearer to it than standing still does, so the still movement is the
    nearest there is and the relative score, which is 1 for it whatever the demonstration, has nothing to add. No
    still movement in the repertoire: nothing holds (:attr:`limit` 0).
    """

    still: frozenset[str] = frozenset()
    limit: float = 0.0

    ROUNDING = 1e-6
    """A take's motion at most this (in the comparison's unit, a body size or a metre: a micrometre or two) is no
    motion at all: rounding, and the ringing a clip's low-pass (:mod:`plugins.lib.lowpass`) leaves in a held pose
    from a movement at its edge (1e-9 body sizes in Max's ``stand``)."""

    @classmethod
    def of(cls, motion: dict[str, float]) -> Stillness:
        """From each movement's motion (the largest of its takes')."""
        still = frozenset(m for m, a in motion.items() if a <= cls.ROUNDING)
        moving = [a for m, a in motion.items() if m not in still]
        if not still:
            return cls()
        return cls(still, min(moving) / 2.0 if moving else float("inf"))

    @property
    def measure(self) -> str:
        return "the demonstration's distance to standing still, at most half the least moving movement's"

    def holds(self, nearest: str | None, moved: float) -> bool:
        """Whether a demonstration that moved ``moved`` and came nearest to ``nearest`` is that still movement."""
        return nearest in self.still and moved <= self.limit


def relative_scores(distances: np.ndarray, moving: np.ndarray, takes: np.ndarray) -> np.ndarray:
    """The calibrated decision's unit-free scores (..., C): each chain's ``distances`` over how much there is to
    explain, the larger of the demonstration's distance to standing still (``moving``, each chain's at its pace)
    and the nearest chain's take's own (``takes``, (C,)), one denominator for every chain of a row, so they rank as
    their distances over ``moving`` do; ``inf`` where the demonstration does not move.

    Over the demonstration's motion alone, a performance with less motion than the take (a wave held low, with a
    smaller lift and smaller swings: half the take's motion) lay twice as far as the same difference in a larger
    one, and a style that moves little read as unknown. Over the larger of the two, the share left unexplained is
    the same whichever of the pair moves more. A take that holds still (no motion) changes nothing."""
    distances = np.asarray(distances, dtype=float)
    moving = np.broadcast_to(np.asarray(moving, dtype=float), distances.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(moving > 0, distances / moving, np.inf)
        best = np.argmin(ratio, axis=-1)[..., None]
        own = np.take_along_axis(moving, best, axis=-1)
        larger = np.where(own > 0, np.maximum(1.0, np.asarray(takes, dtype=float)[best] / own), 1.0)
        return np.where(moving > 0, ratio / larger, np.inf)


STILL = 1.0
"""The largest calibrated threshold: a score of 1 is a demonstration its nearest movement explains no better than
standing still would (the larger of the pair's motions left unexplained)."""

DECISIONS = {"distance": Distance, "calibrated": Calibrated}
"""The decisions by the name a matcher's ``decision`` parameter takes."""
