"""How path search looks for the nearest path: the strategy its ``search`` parameter chooses, once.

:class:`Search` is what :class:`~plugins.matchers.path_search.matcher.PathSearch` asks of either strategy: to build
its tables from the posegraph, to find the nearest path to a demonstration (:class:`Found`), and to calibrate the
shared decision on the repertoire (:class:`plugins.matchers.decision.Calibration`). The strategies are
:class:`~plugins.matchers.path_search.kbest.Beam` (the paper's k best paths from the middle frame) and
:class:`~plugins.matchers.path_search.per_movement.EachMovement` (every movement's own best path, exactly).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from plugins.matchers.comparison import Frames
from plugins.matchers.decision import Calibration
from toolkit import Motion

if TYPE_CHECKING:
    from plugins.matchers.path_search.matcher import PathSearch

__all__ = ["Found", "Search"]


@dataclass
class Found:
    """What a search found for a demonstration: its answer (``None``: the best path holds only hubs), the node path
    of the answer, the share of that path's nodes that belong to it (hubs do not vote), the ranked movements with
    their distances, the answer first, and ``still``: what the decision divides those distances by
    (:meth:`plugins.matchers.decision.Decision.decide`): the demonstration's distance to standing still where they
    are distances and the decision is relative, 1 where the search ranked by the relative score itself or the
    decision is a distance."""

    movement: str | None
    path: np.ndarray
    share: float = 1.0
    ranked: tuple[tuple[str, float], ...] = ()
    details: dict[str, Any] = field(default_factory=dict)
    still: float = 1.0

    @property
    def distance(self) -> float:
        return self.ranked[0][1] if self.ranked else float("inf")


class Search(ABC):
    """A path search strategy, attached to its matcher."""

    def __init__(self, matcher: PathSearch) -> None:
        self.matcher = matcher

    @abstractmethod
    def rebuild(self) -> None:
        """Build what the search needs of the posegraph as it is now (at attach and after learning)."""

    @abstractmethod
    def find(self, samples: Frames, motion: Motion) -> Found | None:
        """The nearest path to the demonstration's ``samples`` (``None`` when nothing was seen); ``motion``: the
        demonstration as observed, for what is compared beyond the samples (:mod:`plugins.matchers.path_search.
        evidence`)."""

    @abstractmethod
    def calibration(self) -> Calibration:
        """Leave one take out and leave one movement out on the repertoire (:class:`Calibration`)."""
