"""What the forward model needs of the motor system: motor command graphs (Kopp & Graeser 2006, §4.2).

One graph per motor subsystem (a wrist, a hand's fingers): nodes are motor states, edges are motor commands (guiding
strokes of the parts, or a hand's transitions over its finger angles) that lead from one state to another. The
forward model predicts with the edges leaving a subsystem's active node (§4.4), commits to one as a movement (a path
of edges, several subsystems at once), and learns what no edge predicts as new edges (§4.3). The protocol is checked
when the matcher is attached (:func:`toolkit.components.provides`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Protocol

import numpy as np

from plugins.lib.strokes import StrokeCriteria

__all__ = ["CommandGraphs"]


class CommandGraphs(Protocol):
    """A motor system of motor command graphs, one per subsystem, whose edges are commands (K&G §4.2).

    What the forward model needs of it: ``plugins.motor.motor_command_graph`` provides it.
    """

    subsystems: Mapping[str, np.ndarray]
    """The parts (indices into the body) each subsystem moves."""

    def is_hand(self, subsystem: str) -> bool:
        """Whether a subsystem's states are a hand's finger joint angles (radians) rather than positions."""

    def active_node(self, subsystem: str) -> str:
        """The node a subsystem is in: where the last movement followed or performed ended."""

    def move_to(self, subsystem: str, node: str, *, posture: bool = True) -> None:
        """Put a subsystem in ``node`` (with ``posture``, the body's parts too)."""

    def state(self, subsystem: str, node: str) -> np.ndarray:
        """A node's motor state, (k, 3) for the subsystem's k parts."""

    def edges_from(self, subsystem: str, node: str) -> list[Any]:
        """The edges leaving ``node``: records with ``name``, ``source``, ``target`` and ``commands``."""

    def edge(self, movement: str) -> Any:
        """The edge record of a movement (edge) name."""

    def known_sequence(self, path: tuple[str, ...]) -> tuple[str, ...]:
        """The whole learned sequence of edges ``path`` begins, else ``path``."""

    def add_sequence(self, edges: list[str], *, name: str | None = None, label: str | None = None) -> str:
        """A path of edges named as one movement."""

    def add_together(self, movements: list[str]) -> str:
        """Movements of several subsystems named as one, performed at once."""

    def subsystem_of(self, movement: str) -> str:
        """The subsystem a movement moves."""

    def label(self, movement: str) -> str:
        """The movement a performable name is an example of."""

    def label_of_path(self, path: tuple[str, ...]) -> str | None:
        """The labelled movement a path of edges stands for, if one."""

    def learn_observed(self, subsystem: str, start: str, observed: np.ndarray, fps: float, *,
                       criteria: StrokeCriteria = StrokeCriteria()) -> list[str]:
        """Learn an observed movement as new edges from ``start`` (true imitation); their names."""

    def rest_pose(self) -> np.ndarray:
        """The body's rest pose, local frame (P, 3)."""
