"""Motor system ``keyframe``: movements played from timed key poses.

The demonstrator's motor system in both papers: Moritz "can perform arbitrary
movements by executing predefined keyframe animations" (Kopp & Graeser 2006,
§4), and Max and Morris's movements are interpolated key poses (Buchsbaum &
Blumberg 2005, §4.1). It has no graph and learns nothing; the ``posegraph``
motor system adds the graph.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from plugins.motor.key_poses import REPERTOIRE_PARAMETERS, play, read_repertoire
from toolkit import ConfigError, Motion, MotorSystem, hookimpl


class KeyframeMotor(MotorSystem):
    """Plays movements authored as timed key poses, hub to hub (no learning)."""

    name = "keyframe"
    parameters = REPERTOIRE_PARAMETERS

    def attach(self, owner: Any) -> None:
        super().attach(owner)
        self.key_poses, self.hubs, self.repertoire = read_repertoire(self.params, owner.body)
        self.parts = owner.body.parts

    def movements(self) -> list[str]:
        return list(self.repertoire)

    def rest_pose(self) -> np.ndarray:
        return self.key_poses[self.hubs[0]]

    def perform(self, movement: str, *, speed: float = 1.0, fps: float = 30.0) -> Motion:
        if movement not in self.repertoire:
            raise ConfigError(f"unknown movement {movement!r}", expected="a movement of this character", available=self.movements())
        return play(self.key_poses, self.repertoire[movement], self.parts, fps=fps, speed=speed)

    def describe(self) -> dict[str, Any]:
        return {"movements": len(self.repertoire), "poses": len(self.key_poses.names), "hubs": list(self.hubs)}


@hookimpl
def likeme_register_motor_systems() -> list[type[MotorSystem]]:
    return [KeyframeMotor]
