"""True imitation: what no edge predicts is learned by the inverse model (Kopp & Graeser 2006, §4.3, Fig. 3 top).

When no edge predicts the demonstration, the motor command graph learns it (``learn_observed``): the working memory of
the segment since the last correct node is cut into strokes at the break points of the stroke analysis
(:mod:`plugins.lib.strokes`, with the matcher's ``[strokes]`` table: ``drop`` and ``angle``), each stroke becomes a
guiding stroke by the inverse model (:mod:`plugins.lib.inverse_model`), and the strokes become new edges and nodes
leading from the last correct node (ending in the hub when the demonstration returns there). A hand's movement is
learned as one edge whose key postures are the angular-velocity minima and direction changes. Whether anything is
learned is chosen once, by ``learn``.

Following real people (``comparison = "motion"``, :mod:`~plugins.matchers.forward_model.following`), the candidates
are whole takes, and so is what is learned (:class:`TakeLearning`): a demonstration no take predicts becomes a take
of a new movement, ``learned-1``, ``learned-2``..., through the same inverse model
(:meth:`MotorCommandGraph.learn_take <plugins.motor.motor_command_graph.MotorCommandGraph.learn_take>`), and is a
candidate from the next demonstration on.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from plugins.lib.clip_repertoire import root_relative_motion
from plugins.lib.learned_names import learned_name
from plugins.lib.strokes import StrokeCriteria
from plugins.matchers.forward_model.tracks import Track
from toolkit import Match, Motion

if TYPE_CHECKING:
    from plugins.matchers.forward_model.matcher import ForwardModel

__all__ = ["InverseModel", "TakeLearning"]


class InverseModel:
    """Learning new edges from what was observed (the strategy ``learn = true`` chooses)."""

    def __init__(self, model: ForwardModel, criteria: StrokeCriteria) -> None:
        self.model = model
        self.criteria = criteria

    def learn(self, track: Track, memory: np.ndarray) -> list[str]:
        """Cut a subsystem's working memory (``memory``, the segment in the motor frame) since its last correct node
        into strokes, one edge each, chained from it; the new edges' names.

        A subsystem followed from a later onset than the first is learned up to where it came to rest.
        """
        m = self.model
        observed = memory[track.learn_from:, m.motor.subsystems[track.subsystem]]
        if (track.onset if track.origin is None else track.origin) > 0 and len(observed) > 3:
            # it may have stopped before the others did
            away = np.linalg.norm(observed - observed[-1], axis=-1).max(axis=1) * track.scale
            moving = np.flatnonzero(away > 0.25 * m.params["min_move"])
            observed = observed[: (int(moving[-1]) + 2 if len(moving) else len(observed))]
        if len(observed) < 3:
            return []
        return m.motor.learn_observed(track.subsystem, track.last_correct, observed, m.fps, criteria=self.criteria)


class TakeLearning:
    """Learning a demonstration no take predicts as a take of a new movement (the strategy ``learn = true`` chooses
    when following real people).

    Parameters
    ----------
    motor : MotorCommandGraph
        Learns the take (:meth:`learn_take`).
    body : Body
        The observer's body: the demonstration's frame is found again over the whole segment, as for the clips a
        repertoire is built from (:func:`plugins.lib.clip_repertoire.root_relative_motion`).
    """

    def __init__(self, motor: Any, body: Any) -> None:
        self.motor, self.body = motor, body

    def learn(self, motion: Motion, answer: Match) -> Match:
        """``answer`` (an unknown) for the demonstration ``motion`` (the segment, root-relative with its world
        positions): a :class:`Match` of the movement it was learned as (``details["learned"]``), or ``answer``
        when nothing moved enough to be a stroke."""
        world = motion.world if motion.world is not None else motion.positions
        take = root_relative_motion(Motion(world, motion.fps, motion.parts, motion.visible), self.body)
        name = learned_name(self.motor.movements())
        edges = self.motor.learn_take(name, take, source="forward model")
        if not edges:
            return answer
        return Match(name, 1.0, None, edges, {"learned": True, "nearest": answer.nearest, "score": answer.score,
                                              "threshold": answer.threshold})
